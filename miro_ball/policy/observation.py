"""The contract's Percepts as the learning environments' observation: a dict of numpy arrays,
one per entry (learn.spaces says each entry's space and units).

Plain numpy, so the controller that runs a trained policy (policy.controller) makes its
input with the very conversion the environment made while the policy learnt, in a node
that loads no Gymnasium.
"""
import math

import numpy as np

from miro_ball.miro.constants import MIC_BLOCK_SAMPLES, MIC_FULL_SCALE, SONAR_RANGE
from miro_ball.miro.touch import TOUCH_PADS

MICS = 4
F32 = np.float32
# The sonar's far end: its reading when nothing is in range (the contract's inf, made finite
# for learners).
SONAR_FAR_M = SONAR_RANGE[1]


def _bits(mask):
    return np.array([(int(mask or 0) >> pad) & 1 for pad in range(TOUCH_PADS)], np.int8)


def _sighting(result):
    """[seen, x, y, r] of one eye's detection (a Ball, or anything with x and y)."""
    if result is None:
        return (0.0, 0.0, 0.0, 0.0)
    return (1.0, float(result.x), float(result.y), float(getattr(result, 'r', 0.0)))


def observation(percepts, entries, mics=None):
    """The observation made from ``percepts`` (contract.Percepts): the state entries, and
    those of ``entries`` (names: an observation space's keys) that are eyes, mics or a
    detector's; ``mics`` the latest microphone block (int16, (4, 500)) or None."""
    entries = tuple(entries)  # a Dict space's keys (`in` would ask whether it holds a sample)
    sonar = percepts.sonar if percepts.sonar is not None else math.inf
    obs = {
        'joints': np.asarray(percepts.joints, F32),
        'sonar': np.array([min(max(sonar, 0.0), SONAR_FAR_M)], F32),
        'cliff': np.clip(np.asarray(percepts.cliff, F32), 0.0, 1.0),
        'light': np.clip(np.asarray(percepts.light, F32), 0.0, 1.0),
        'touch_head': _bits(percepts.touch_head),
        'touch_body': _bits(percepts.touch_body),
    }
    if 'eyes' in entries:
        obs['eyes'] = np.stack([eye.image for eye in percepts.eyes])
    if 'mics' in entries:
        block = np.zeros((MICS, MIC_BLOCK_SAMPLES), F32) if mics is None else \
            np.asarray(mics, F32) / MIC_FULL_SCALE
        obs['mics'] = block
    for name in entries:
        if name not in obs:
            obs[name] = np.clip(np.array([_sighting(found) for found in
                                          percepts.found(name)], F32), -1.0, 1.0)
    return obs
