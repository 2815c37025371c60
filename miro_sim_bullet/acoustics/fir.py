"""Low-pass FIR filters in numpy, streamed block by block.

scipy.signal would do this, but importing it takes half a second (it brings scipy.stats
along), and every process that builds a world would pay that at start: the simulator,
each grader's episode, every test that starts one. A windowed sinc and np.convolve are all
the simulator's sound needs.
"""
import numpy as np


def lowpass(cutoff_hz, rate_hz, taps):
    """A linear-phase low-pass: ``taps`` (odd) coefficients of a Hamming-windowed sinc,
    unit gain at 0 Hz; its delay is (taps - 1) / 2 samples."""
    middle = (taps - 1) / 2
    h = np.sinc(2 * cutoff_hz / rate_hz * (np.arange(taps) - middle)) * np.hamming(taps)
    return h / h.sum()


class Stream:
    """A FIR filter over the last axis of blocks of shape ``shape + (n,)``, carrying its
    last inputs from block to block (as if the blocks were one signal)."""

    def __init__(self, taps, shape=()):
        self.taps = np.asarray(taps, float)
        self.memory = np.zeros(shape + (len(self.taps) - 1,))

    def __call__(self, block):
        block = np.asarray(block, float)
        joined = np.concatenate([self.memory, block], axis=-1)
        self.memory = joined[..., block.shape[-1]:]
        rows = joined.reshape(-1, joined.shape[-1])
        out = np.stack([np.convolve(row, self.taps, mode='valid') for row in rows])
        return out.reshape(block.shape)

    @property
    def quiet(self):
        """Whether its memory holds nothing but silence."""
        return not np.any(self.memory)

    def reset(self):
        self.memory[...] = 0.0
