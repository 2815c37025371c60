"""A bag's sound as WAV files: every robot's microphones (sensors/mics: 4 channels, 20 kHz)
and what it was told to say (control/stream: 1 channel, 8 kHz), one file each.

    python -m miro_ball.record --wav DIR BAG

Read with rosbags (no ROS needed), written with soundfile, 16 bit. A block of the wrong
length is skipped and counted, not fatal: a bag may hold what a broken node sent.
"""
import fnmatch
from collections import defaultdict
from pathlib import Path

import numpy as np
import soundfile
from rosbags.rosbag2 import Reader

from miro_ball.miro.body import MICS
from miro_ball.miro.constants import MIC_BLOCK_SAMPLES, MIC_SAMPLE_RATE_HZ, \
    SPEAKER_SAMPLE_RATE_HZ
from miro_ball.miro.interface import TOPIC
from miro_ball.recording.bag import TYPESTORE

# topic pattern -> (file name suffix, sample rate, channels)
SOUNDS = {'/*/' + TOPIC['mics'].name: ('mics', MIC_SAMPLE_RATE_HZ, len(MICS)),
          '/*/' + TOPIC['stream'].name: ('stream', SPEAKER_SAMPLE_RATE_HZ, 1)}


class WavError(ValueError):
    """The bag can not be read or the files not written; one line."""


def export_wav(bag, folder):
    """Write the bag's sound into ``folder`` (made if need be); [(file, seconds, skipped)]."""
    parts = defaultdict(list)  # (robot, kind) -> [int16 (channels, n)]
    skipped = defaultdict(int)
    try:
        with Reader(bag) as reader:
            wanted = {c.id: (c, spec) for c in reader.connections for pattern, spec in
                      SOUNDS.items() if fnmatch.fnmatchcase(c.topic, pattern)}
            chosen = [c for c, _ in wanted.values()]
            for connection, _, data in reader.messages(connections=chosen):
                _, spec = wanted[connection.id]
                robot = connection.topic.split('/')[1]
                samples = np.asarray(TYPESTORE.deserialize_cdr(data, connection.msgtype).data,
                                     np.int16)
                name, _, channels = spec
                if channels > 1 and samples.size != channels * MIC_BLOCK_SAMPLES:
                    skipped[robot, name] += 1
                    continue
                parts[robot, name].append(samples.reshape(channels, -1))
    except Exception as err:  # rosbags raises its own kinds for a missing or broken bag
        raise WavError(f'{bag}: cannot read the bag: {str(err)[:120]}') from None
    if not parts:
        raise WavError(f'{bag}: no sensors/mics or control/stream in it')
    out = Path(folder)
    try:
        out.mkdir(parents=True, exist_ok=True)
        written = []
        for (robot, name), blocks in sorted(parts.items()):
            rate = next(spec[1] for spec in SOUNDS.values() if spec[0] == name)
            samples = np.concatenate(blocks, axis=1).T
            path = out / f'{robot}_{name}.wav'
            soundfile.write(str(path), samples, rate, subtype='PCM_16')
            written.append((path, len(samples) / rate, skipped[robot, name]))
    except OSError as err:
        raise WavError(f'{folder}: cannot write: {err.strerror or err}') from None
    return written
