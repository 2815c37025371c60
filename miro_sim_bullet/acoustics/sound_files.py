"""Sound files as the world plays them: decoded once, held compactly, bounded in all.

A file (checked first by scene.sounds: allowed folder, regular file, a sane header) is
decoded to one channel of float32 at the microphones' rate (20 kHz) with RMS 1; the ring
buffers' rate (twice that) is made as it plays (sources.WorldSource). Ten minutes are 48 MB
(float64 at 40 kHz held 192 MB). Every source playing one file shares one copy, and the
copies alive in this process hold at most MAX_BYTES in all: a file that would pass that is
refused in one line (SoundFileError), as a file whose samples are not all finite numbers
(NaN made every microphone read 0).
"""
import math
import threading
import weakref
from fractions import Fraction
from pathlib import Path

import numpy as np

from miro_ball.miro.constants import MIC_SAMPLE_RATE_HZ
from miro_ball.common.files import open_regular

MAX_BYTES = 200_000_000  # every sound file's samples alive at once: 35 minutes of sound
BLOCK_FRAMES = 1 << 16  # read and mixed down this many frames at a time
# A file's rate is brought to 20 kHz by a ratio of integers no larger than this: 44.1 kHz is
# exactly 200/441, and a rate such as 191,999 Hz is off by less than 1e-6 instead of asking
# for a filter of four million taps.
MAX_RATIO_TERM = 1000


class SoundFileError(ValueError):
    """A sound file that can not be played, said in one line."""


def decode(path):
    """The file's samples as float32 mono at MIC_SAMPLE_RATE_HZ with RMS 1 (its level is
    the world file's); SoundFileError for what can not be played."""
    import soundfile  # here, as scipy.signal: only a world with a sound file pays their import
    from scipy.signal import resample_poly

    name = Path(path).name
    try:
        with open_regular(path) as raw, soundfile.SoundFile(raw) as file:
            rate = file.samplerate
            mono = np.concatenate([block.mean(axis=1) for block in file.blocks(
                BLOCK_FRAMES, dtype='float32', always_2d=True)] or [np.zeros(0, np.float32)])
    except (OSError, RuntimeError, soundfile.LibsndfileError) as err:
        raise SoundFileError(f'cannot read {name!r} as sound: {str(err)[:100]}') from None
    if not np.isfinite(mono).all():
        raise SoundFileError(f'{name!r} holds samples that are not numbers (NaN or infinite)')
    if rate != MIC_SAMPLE_RATE_HZ:
        ratio = Fraction(MIC_SAMPLE_RATE_HZ, rate).limit_denominator(MAX_RATIO_TERM)
        mono = resample_poly(mono, ratio.numerator, ratio.denominator).astype(np.float32)
    rms = math.sqrt(float(np.mean(np.square(mono, dtype=np.float64)))) if mono.size else 0.0
    return mono / np.float32(rms) if rms > 0 else mono


def decoded_bytes(frames, rate):
    """What a file of ``frames`` at ``rate`` holds once decoded."""
    return math.ceil(frames * MIC_SAMPLE_RATE_HZ / rate) * np.dtype(np.float32).itemsize


class SoundBank:
    """The decoded files of this process: one copy per file (its path, size and time of
    change), alive while a source plays it; their sum is bounded. Thread-safe: the
    simulator decodes files asked for at run time off its own thread."""

    def __init__(self, limit_bytes=MAX_BYTES):
        self.limit_bytes = limit_bytes
        self._copies = {}  # (path, size, mtime) -> weak reference to its samples
        self._lock = threading.Lock()

    def samples(self, path):
        """The decoded samples of ``path`` (shared); SoundFileError when they can not be
        had, or would pass the bound."""
        import soundfile

        try:
            key = _key(path)
            with self._lock:
                found, held = self._live().get(key), self._held()
            if found is not None:
                return found
            with open_regular(path) as raw:
                info = soundfile.info(raw)
        except (OSError, RuntimeError, soundfile.LibsndfileError) as err:
            raise SoundFileError(f'cannot read {Path(path).name!r} as sound: '
                                 f'{str(err)[:100]}') from None
        self._check_room(path, decoded_bytes(info.frames, info.samplerate), held)
        samples = decode(path)  # outside the lock: seconds for a long file
        with self._lock:
            self._check_room(path, samples.nbytes, self._held())
            self._copies[key] = weakref.ref(samples)
        return samples

    def held_bytes(self):
        """What the decoded files alive now hold."""
        with self._lock:
            return self._held()

    def _held(self):
        return sum(samples.nbytes for samples in self._live().values())

    def _live(self):
        """{key: samples} of the copies still played (the lock held); forgets the rest."""
        live = {key: ref() for key, ref in self._copies.items()}
        live = {key: samples for key, samples in live.items() if samples is not None}
        self._copies = {key: self._copies[key] for key in live}
        return live

    def _check_room(self, path, size, held):
        if held + size > self.limit_bytes:
            raise SoundFileError(
                f'{Path(path).name!r} would need {size / 1e6:.0f} MB; the sound files playing '
                f'hold {held / 1e6:.0f} MB of at most {self.limit_bytes / 1e6:.0f} MB: stop '
                'one (/miro_sim/sound_off) or use a shorter file')


def _key(path):
    found = Path(path).stat()
    return str(path), found.st_size, found.st_mtime_ns


BANK = SoundBank()  # the process's own: every world of it shares the copies
