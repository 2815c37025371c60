"""The sound of one world: its sources' recent past and what every robot's four
microphones hear, block by block (no ROS; the world ticks it with simulated time).

Sources: the world file's [[sound]]s (and any placed while it runs), every robot's speaker
(in its head) and, when the world asks for it, every robot's wheels. Each platform tick
each source sends one tick of samples into its ring buffer; each time the samples of a
microphone block (500, 25 ms) are all sent, the block is heard by every robot listening
(the tick is told which), with the microphones and sources where they are then
(propagation.render), plus each microphone's own seeded noise floor, and left in the
robot's ``heard`` until the next tick. Block k of every robot covers the same samples,
whoever listens and whenever.
"""
from typing import NamedTuple

import numpy as np

from miro_ball.miro.constants import MIC_BLOCK_SAMPLES, MIC_FULL_SCALE, \
    PLATFORM_TICK_S, WHEEL_MAX_SPEED_M_PER_S
from miro_sim_bullet.acoustics.propagation import HISTORY, OVERSAMPLE, paths, RATE, render, \
    Shadow, WIDTH, write
from miro_sim_bullet.acoustics.sources import Hiss, Noise, rms_scale, WorldSource
from miro_sim_bullet.scene.sounds import Hearing, MAX_SOUNDS

TICK = round(PLATFORM_TICK_S * RATE)  # ring samples a source sends a tick
BLOCK = OVERSAMPLE * MIC_BLOCK_SAMPLES  # ring samples of a microphone block
SELF_NOISE_DB = -60.0  # each microphone's own noise floor, RMS
WHEEL_NOISE_DB = -50.0  # the wheels at full speed, RMS 1 m away
# A block (25 ms) is longer than a tick (20 ms), so a tick ends at most one block: a robot's
# ``heard`` holds every block it hears, each for one tick.
_QUIET_AFTER = HISTORY - 2 * BLOCK  # a source silent this long (ring samples) is heard no more


class MicBlock(NamedTuple):
    """A block of a robot's microphones: the k-th of the world's (25 ms from k * 25 ms)."""

    index: int
    samples: np.ndarray  # int16 (4, 500): the microphones in sensors/mics' order


class Acoustics:
    """Sound for ``robots`` ({name: MiroRobot}) and the world's ``sounds`` (scene.sounds)
    with ``hearing`` (scene.sounds.Hearing); ``seed`` makes every noise."""

    def __init__(self, robots, sounds=(), hearing=Hearing(), seed=0, ground=0.0):
        self.robots = robots
        self.hearing = hearing
        self.seed = seed
        self.sent = 0  # ring samples every source has sent
        self.next_block = 0
        capacity = MAX_SOUNDS + 2 * len(robots)
        self.history = np.zeros((capacity, WIDTH), np.float32)
        # Each row's source: None while the row is free, else one past the last ring sample
        # it sent that was not silence.
        self._loud_until = [None] * capacity
        self.sounds = {}  # name -> (row, WorldSource)
        for sound in sounds:
            self.add_sound(sound)
        self._speaker_rows = {name: self._take_row() for name in robots}
        self._wheel_rows = {name: self._take_row() for name in robots} \
            if hearing.wheel_noise else {}
        self._noise = {name: Noise((seed, 1, index)) for index, name in enumerate(robots)}
        self._wheel_noise = {name: Hiss((seed, 2, index)) for index, name in enumerate(robots)}
        self._before = None  # the geometry at the last block's end
        # robot -> [its last block heard, its Shadow (the filters that carry on from it)]
        self._shadow = {name: [None, Shadow()] for name in robots}
        self._kept_paths = (None, None)  # (key, the paths at the last block's end)
        # The surfaces that echo (axis, coordinate): the ground, and the room's walls and
        # ceiling; an echo keeps sqrt(1 - absorption) of the pressure.
        self._planes = [(2, ground)]
        if hearing.room:
            x0, y0, x1, y1, height = hearing.room
            self._planes += [(0, x0), (0, x1), (1, y0), (1, y1), (2, ground + height)]
        self._reflected = (1.0 - hearing.absorption) ** 0.5

    # -- sources ------------------------------------------------------------------------------
    def _take_row(self):
        row = self._loud_until.index(None)  # ValueError: full (the limit keeps it not)
        self._loud_until[row] = -HISTORY  # never sounded
        self.history[row] = 0.0
        return row

    def add_sound(self, sound):
        """A world sound (scene.sounds.Sound) starts to play, its start and stop counted
        from now; its name replaces one of the same name. ValueError when MAX_SOUNDS
        already play, or its file can not be played (sound_files.SoundFileError): then
        nothing changes."""
        others = len(self.sounds) - (sound.name in self.sounds)
        if others >= MAX_SOUNDS:
            raise ValueError(f'at most {MAX_SOUNDS} sounds play at once')
        # The source first: a file that fails to play must not keep a row.
        source = WorldSource(sound, (self.seed, 0, others), self.sent)
        self.remove_sound(sound.name)
        self.sounds[sound.name] = (self._take_row(), source)

    def remove_sound(self, name):
        """Silence a world sound at once (what it sent is still on its way: not heard)."""
        if name in self.sounds:
            row, _ = self.sounds.pop(name)
            self._loud_until[row] = None

    def source_positions(self):
        """{name: world position} of every world sound and every robot's speaker (the
        ground truth a test or a lab compares with what the ears make of it)."""
        out = {name: source.position for name, (_, source) in self.sounds.items()}
        out.update({name: robot.hearing_frame().speaker for name, robot in self.robots.items()})
        return out

    # -- time ---------------------------------------------------------------------------------
    def tick(self, listening):
        """One platform tick: every source sends its samples; a block whose samples are now
        all sent is heard by the robots named in ``listening`` (the others' microphones are
        not worked out) and left in each one's ``heard``."""
        for robot in self.robots.values():
            robot.heard = None
        n0 = self.sent
        chunks = [(row, source.emit(n0, TICK)) for row, source in self.sounds.values()]
        chunks += [(self._speaker_rows[name], robot.sound) for name, robot in self.robots.items()]
        for name, row in self._wheel_rows.items():
            speed = sum(abs(v) for v in self.robots[name].wheel_out) / 2
            chunks.append((row, None if speed == 0 else self._wheel_noise[name](n0, TICK)
                           * rms_scale(WHEEL_NOISE_DB) * speed / WHEEL_MAX_SPEED_M_PER_S))
        for row, samples in chunks:
            if samples is None:
                if self._loud_until[row] <= n0 - HISTORY:
                    continue  # silent a whole ring's length: it holds nothing but zeros
                # (Zeros until then: a block read up to _QUIET_AFTER after the last sound
                # reaches past it, and a sound that starts again reads a little before its
                # start; what the ring held from a ring's length ago would be heard again.)
                samples = np.zeros(TICK)
            else:
                self._loud_until[row] = n0 + TICK
            write(self.history, row, n0, samples)
        self.sent = n0 + TICK
        while (self.next_block + 1) * BLOCK <= self.sent:
            self._hear_block(listening)

    def _geometry(self):
        """({robot: its hearing_frame()}, {row: position of its source}) now."""
        frames = {name: robot.hearing_frame() for name, robot in self.robots.items()}
        sources = {row: source.position for row, source in self.sounds.values()}
        sources.update({self._speaker_rows[name]: frame.speaker
                        for name, frame in frames.items()})
        sources.update({self._wheel_rows[name]: frame.wheels for name, frame in frames.items()
                        if name in self._wheel_rows})
        return frames, sources

    def _hear_block(self, listening):
        block = self.next_block
        self.next_block += 1
        heard = [name for name in self.robots if name in listening]
        if not heard:  # nothing worked out; the next heard block starts from where it is
            self._before = None
            return
        n0 = block * MIC_BLOCK_SAMPLES
        rows = [row for row, loud_until in enumerate(self._loud_until)
                if loud_until is not None and loud_until > OVERSAMPLE * n0 - _QUIET_AFTER]
        if rows:
            sound = self._hear_sources(block, rows, heard)
        else:  # silence but for the microphones' own noise (the usual block: cheap)
            self._before = None
            for name in heard:
                self._shadow[name][0] = None  # the filters' memory is of before: dropped
            sound = np.zeros((len(heard) * 4, MIC_BLOCK_SAMPLES))
        size = 4 * MIC_BLOCK_SAMPLES
        noise = np.concatenate([self._noise[name](block * size, size) for name in heard])
        mics = sound + rms_scale(SELF_NOISE_DB) * noise.reshape(-1, MIC_BLOCK_SAMPLES)
        samples = np.clip(np.rint(mics * MIC_FULL_SCALE), -MIC_FULL_SCALE,
                          MIC_FULL_SCALE - 1).astype(np.int16)
        for index, name in enumerate(heard):
            self.robots[name].heard = MicBlock(block, samples[4 * index:4 * index + 4])

    def _hear_sources(self, block, rows, heard):
        """(4 x robots heard, 500): what the listened robots' microphones hear of the
        sources of ``rows`` over the block."""
        now = self._geometry()
        before = self._before if self._before is not None else now
        self._before = now
        echoes = len(self._planes) if self.hearing.reflections else 0
        high, rest = render(self.history, rows * (1 + echoes), block * MIC_BLOCK_SAMPLES,
                            MIC_BLOCK_SAMPLES, self._paths(rows, before, now, heard),
                            self._paths(rows, now, now, heard))
        # Each robot's shadow filters carry on from its last block if that was the one before
        # (else they start from rest).
        out = np.empty_like(high)
        for index, name in enumerate(heard):
            kept = self._shadow[name]
            if kept[0] != block - 1:
                kept[1].reset()
            kept[0] = block
            part = slice(4 * index, 4 * index + 4)
            out[part] = kept[1](high[part], rest[part])
        return out

    def _paths(self, rows, geometry, now, heard):
        """propagation.paths of the block's sources and listened microphones at
        ``geometry``; those at a block's end are its next block's start (kept)."""
        key = (geometry, tuple(rows), tuple(heard))
        kept_key, kept = self._kept_paths
        if kept_key is not None and kept_key[0] is geometry and kept_key[1:] == key[1:]:
            return kept
        gains, where = self._images(rows, geometry, now, heard)
        found = paths(*where, gains, MIC_BLOCK_SAMPLES)
        self._kept_paths = (key, found)
        return found

    def _images(self, rows, geometry, now, heard):
        """(gains, (source positions, mic positions, outward normals)) of the sources of
        ``rows`` followed by their echoes off each wall, and of the listened robots'
        microphones, from ``geometry`` (a source new since then: from ``now``)."""
        (frames, sources), latest = geometry, now[1]
        count = len(rows)
        positions = np.array([sources.get(row, latest[row]) for row in rows],
                             float).reshape(-1, 3)
        images, gains = [positions], [np.ones(count)]
        for axis, value in self._planes if self.hearing.reflections else ():
            mirrored = positions.copy()
            mirrored[:, axis] = 2 * value - mirrored[:, axis]
            images.append(mirrored)
            gains.append(np.full(count, self._reflected))
        mics = np.concatenate([frames[name].mics for name in heard])
        outward = np.concatenate([frames[name].outward for name in heard])
        return np.concatenate(gains), (np.concatenate(images), mics, outward)
