"""Spatial attention: a priority map around MiRo whose peak is what it attends to.

The map covers every azimuth (-180..180 deg) and elevations -45..75 deg of MiRo's body
frame in BIN_DEG cells. Each tick every stimulus paints a blob there, as tall as its
salience (gain of its kind x novelty, for motion and sound x their strength) and as wide
as it looks; the map keeps the larger of what it held, faded (time constant map_tau_s),
and what is painted now. Taking the larger, not the sum, means a frame seen again on the
next tick holds its blob steady rather than piling up. The kind that painted a cell is
kept with it, so the peak says what it is.

Getting used to a kind (habituation, over habituation_s of seeing it) takes up to
habituation_depth of its salience away: a new thing draws more than an old one.
"""
import math
from typing import NamedTuple, Optional

import numpy as np

from miro_ball.animal.senses import KINDS

BIN_DEG = 4.0
ELEVATIONS_DEG = (-45.0, 75.0)
AZIMUTHS = np.radians(np.arange(-180.0, 180.0, BIN_DEG) + BIN_DEG / 2)
ELEVATIONS = np.radians(np.arange(*ELEVATIONS_DEG, BIN_DEG) + BIN_DEG / 2)
NO_KIND = -1


class Peak(NamedTuple):
    """The map's highest point: the attention target when high enough."""
    kind: str
    azimuth: float  # rad, body frame, + left
    elevation: float
    height: float  # the map's value there (salience)
    range: Optional[float]  # m, of the stimulus that painted it, if known
    span: float  # rad


def _wrap(angles):
    """Angles (an array) into [-pi, pi)."""
    return (angles + math.pi) % (2 * math.pi) - math.pi


def cell_of(azimuth, elevation):
    """(row, column) of the map's cell holding a direction, rad (scalars or arrays)."""
    step = math.radians(BIN_DEG)
    column = np.round((np.asarray(azimuth) - AZIMUTHS[0]) / step).astype(int) % len(AZIMUTHS)
    row = np.clip(np.round((np.asarray(elevation) - ELEVATIONS[0]) / step).astype(int), 0,
                  len(ELEVATIONS) - 1)
    return row, column


class PriorityMap:
    def __init__(self, params):
        self.params = params
        shape = (len(ELEVATIONS), len(AZIMUTHS))
        self.values = np.zeros(shape)
        self.kinds = np.full(shape, NO_KIND, dtype=np.int8)
        self.habituation = dict.fromkeys(KINDS, 0.0)
        self._painted = {}  # cell -> the stimulus whose blob peaks there (for the range)

    def gain(self, kind, self_noisy=False):
        p = self.params
        if kind == 'sound':
            return p.gain_sound_self if self_noisy else p.gain_sound
        return {'ball': p.gain_ball, 'face': p.gain_face, 'tag': p.gain_tag,
                'motion': p.gain_motion}[kind]

    def salience(self, stimulus, self_noisy=False):
        novelty = 1.0 - self.params.habituation_depth * self.habituation[stimulus.kind]
        strength = 1.0
        if stimulus.kind == 'sound':
            strength = stimulus.strength
        elif stimulus.kind == 'motion':
            strength = min(1.0, stimulus.strength / 0.02)  # 2 % of the frame counts fully
        return self.gain(stimulus.kind, self_noisy) * novelty * strength

    def update(self, dt, stimuli, self_noisy=False):
        """Fade, paint this tick's stimuli, and get used to what is in view; the Peak."""
        p = self.params
        self.values *= math.exp(-dt / p.map_tau_s)
        seen = {s.kind for s in stimuli}
        for kind in KINDS:
            target = 1.0 if kind in seen else 0.0
            self.habituation[kind] += (target - self.habituation[kind]) * min(
                1.0, dt / p.habituation_s)
        # The painted cells the map has faded from are forgotten (bounded bookkeeping).
        self._painted = {cell: s for cell, s in self._painted.items()
                         if self.values[cell] > 1e-3}
        for stimulus in stimuli:
            height = self.salience(stimulus, self_noisy)
            if height <= 0:
                continue
            width = max(stimulus.span / 2, math.radians(BIN_DEG))
            d_az = _wrap(AZIMUTHS - stimulus.azimuth)[None, :]
            d_el = (ELEVATIONS - stimulus.elevation)[:, None]
            blob = height * np.exp(-(d_az ** 2 + d_el ** 2) / (2 * width ** 2))
            higher = blob > self.values
            self.values = np.where(higher, blob, self.values)
            self.kinds = np.where(higher, KINDS.index(stimulus.kind), self.kinds)
            row, column = cell_of(stimulus.azimuth, stimulus.elevation)
            self._painted[(int(row), int(column))] = stimulus
        return self.peak()

    def peak(self):
        row, column = np.unravel_index(int(np.argmax(self.values)), self.values.shape)
        kind = int(self.kinds[row, column])
        if kind == NO_KIND or self.values[row, column] <= 0:
            return None
        source = self._nearest_painted(row, column, KINDS[kind])
        return Peak(KINDS[kind], float(AZIMUTHS[column]), float(ELEVATIONS[row]),
                    float(self.values[row, column]), source.range if source else None,
                    source.span if source else 0.0)

    def _nearest_painted(self, row, column, kind):
        """The latest stimulus of that kind painted nearest the cell (for range and span)."""
        best, best_distance = None, math.inf
        for (r, c), stimulus in self._painted.items():
            if stimulus.kind != kind:
                continue
            distance = abs(r - row) + min(abs(c - column), len(AZIMUTHS) - abs(c - column))
            if distance < best_distance:
                best, best_distance = stimulus, distance
        return best

    def target(self, peak):
        """The peak if it is high enough to attend to."""
        if peak is not None and peak.height >= self.params.peak_threshold:
            return peak
        return None
