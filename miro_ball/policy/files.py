"""A policy's two files read as files from outside: ``MIRO_POLICY`` and evaluate's DIR may
name any folder, and what lies in it may be anything.

Each file is read only when it is a regular file, opened without waiting (a FIFO named
policy.json held the controller node at start, deaf to Ctrl+C), and only as far as the
policy needs: a file's size is bounded before it is read, a weights array's header
(its shape and type) and its unpacked size are checked before a number of it is unpacked
(a 2.9 MB policy.npz of 3 GB of zeros took 2.5 GB; a 200-byte one whose header claimed
2**40 numbers ended in a MemoryError), and the settings' nesting is bounded by Python's
recursion limit. Every refusal is a ValueError of one line.
"""
import json
import math
import os
import zipfile
import zlib

import numpy as np

from miro_ball.common.files import open_regular, read_regular
from miro_ball.common.lifecycle import first_line

# policy.json: train writes about 500 bytes.
MAX_SETTINGS_BYTES = 65536
# policy.npz, and any array in it unpacked: twelve weights are 364 bytes packed.
MAX_WEIGHTS_BYTES = 65536
MAX_HEADER_BYTES = 1024  # of an array (numpy writes 118)
NUMBER_KINDS = 'fiu'  # arrays of floats or integers are weights; no complex, object or record
# What a damaged or hostile zip may raise on the way to an array's numbers.
UNREADABLE = (OSError, ValueError, KeyError, EOFError, RuntimeError, NotImplementedError,
              zipfile.BadZipFile, zlib.error)
HEADER_READERS = {(1, 0): np.lib.format.read_array_header_1_0,
                  (2, 0): np.lib.format.read_array_header_2_0}


def read_settings(path):
    """The JSON object in the file ``path``; ValueError (one line) when it is not one."""
    try:
        # Through a link (the regular file it names), as any program opens a file.
        text = read_regular(os.path.realpath(path), MAX_SETTINGS_BYTES)
    except (OSError, ValueError) as err:
        raise ValueError(f'cannot read {path}: {first_line(err)}') from None
    if len(text) > MAX_SETTINGS_BYTES:
        raise ValueError(f'{path}: more than {MAX_SETTINGS_BYTES} bytes; a policy\'s settings '
                         'are a few hundred')
    try:
        settings = json.loads(text)
    except ValueError as err:  # not JSON, not UTF-8, an integer of too many digits
        raise ValueError(f'cannot read {path}: {first_line(err)}') from None
    except RecursionError:
        raise ValueError(f'cannot read {path}: nested too deeply') from None
    if not isinstance(settings, dict):
        raise ValueError(f'{path} is not a JSON object of settings')
    return settings


class _Refused(Exception):
    """What a policy's weights file holds that the policy cannot use."""


def read_numbers(path, name, count):
    """The array ``name`` of the .npz file ``path`` as ``count`` float64 numbers (of any
    shape); ValueError (one line) when it is not, said before its numbers are unpacked."""
    try:
        with open_regular(os.path.realpath(path)) as file:
            size = os.fstat(file.fileno()).st_size
            if size > MAX_WEIGHTS_BYTES:
                raise _Refused(f'{size} bytes; a policy\'s weights are at most '
                               f'{MAX_WEIGHTS_BYTES}')
            with zipfile.ZipFile(file) as archive:
                try:
                    member = archive.getinfo(f'{name}.npy')
                except KeyError:
                    raise _Refused(f'no array {name!r}') from None
                if member.file_size > MAX_WEIGHTS_BYTES:
                    raise _Refused(f'{name} unpacks to {member.file_size} bytes; at most '
                                   f'{MAX_WEIGHTS_BYTES}')
                with archive.open(member) as stream:
                    return _numbers(stream, name, count)
    except _Refused as err:
        raise ValueError(f'{path}: {err}') from None
    except UNREADABLE as err:
        raise ValueError(f'cannot read {path}: {first_line(err)}') from None


def _numbers(stream, name, count):
    """``count`` numbers of the .npy array at ``stream``, its header checked first."""
    version = np.lib.format.read_magic(stream)
    read_header = HEADER_READERS.get(version)
    if read_header is None:
        raise _Refused(f'{name} is an array of .npy version {version}; 1.0 or 2.0 are read')
    shape, _, dtype = read_header(stream, max_header_size=MAX_HEADER_BYTES)
    if dtype.kind not in NUMBER_KINDS or math.prod(shape) != count:
        raise _Refused(f'{name} holds {shape} of {dtype}; the policy needs {count} numbers')
    data = stream.read(count * dtype.itemsize)
    if len(data) != count * dtype.itemsize:
        raise _Refused(f'{name} ends before its {count} numbers')
    return np.frombuffer(data, dtype).astype(np.float64)
