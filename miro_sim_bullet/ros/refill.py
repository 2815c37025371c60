"""A message serialised once and refilled: the numbers of a fixed-layout message written
into its bytes in place, for streams too busy to build in Python each time.

/tf carries 13 transforms of every robot each platform tick: building them as rclpy
messages and serialising them took ~0.6 ms a tick for three robots, a fifth of the
simulator's time when it runs fast. Here the message is built and serialised once with a
distinct sentinel in every number that changes (the stamps, the transforms' values), the
sentinels' places found in the bytes, and each tick the new numbers are written there
(rclpy publishes bytes as they are: Publisher.publish of a serialised message).
"""
import struct

import numpy as np
from rclpy.serialization import deserialize_message, serialize_message

_STAMP_SEC = 0x5E7A_11ED  # sentinels no number of ours takes
_STAMP_NANOSEC = 0x3A9C_0DE5
_DOUBLE_BASE = 7.0e300  # sentinel doubles: _DOUBLE_BASE + k * _DOUBLE_STEP
_DOUBLE_STEP = 1.0e290


MAX_TAIL = 8  # bytes of alignment rclpy may add after a message's last field


def _exact(data, msg_type):
    """The serialised message without the tail rclpy adds (it rounds the buffer up: 4 bytes
    of whatever was in memory after a JointState): published as raw bytes the tail would go
    out too, and strict readers (rosbags) refuse it. The shortest prefix that still
    deserialises is the message."""
    for _ in range(MAX_TAIL):
        try:
            deserialize_message(data[:-1], msg_type)
        except Exception:  # rclpy raises its RMWError: too short, so data is exact
            return data
        data = data[:-1]
    return data


class Refill:
    """``build(stamp, doubles)`` makes the message with those sentinels; ``count`` doubles
    are refilled. Raises ValueError when a sentinel's bytes are not found exactly where
    expected (a layout this cannot refill)."""

    def __init__(self, build, count):
        from builtin_interfaces.msg import Time

        sentinels = [_DOUBLE_BASE + k * _DOUBLE_STEP for k in range(count)]
        msg = build(Time(sec=_STAMP_SEC, nanosec=_STAMP_NANOSEC), sentinels)
        data = _exact(serialize_message(msg), type(msg))
        if data[:2] != b'\x00\x01':  # CDR, little endian: the numbers below are so
            raise ValueError('not a little-endian CDR message')
        self.template = bytearray(data)
        self.doubles = np.array([self._place(struct.pack('<d', value), 8)
                                 for value in sentinels], dtype=np.intp)
        self.seconds = self._places(struct.pack('<i', _STAMP_SEC))
        self.nanoseconds = self._places(struct.pack('<I', _STAMP_NANOSEC))

    def _places(self, pattern):
        """Every place of pattern in the template, as indices of 4-byte words."""
        out, start = [], 0
        while (at := self.template.find(pattern, start)) >= 0:
            if at % 4:
                raise ValueError('a stamp is not where CDR aligns it')
            out.append(at // 4)
            start = at + 1
        return np.array(out, dtype=np.intp)

    def _place(self, pattern, size):
        at = self.template.find(pattern)
        if at < 0 or self.template.find(pattern, at + 1) >= 0 or (at - 4) % size:
            raise ValueError('a sentinel is missing, twice or misaligned')
        return (at - 4) // size  # CDR aligns a double after the 4-byte encapsulation header

    def fill(self, stamp, doubles):
        """The message's bytes with this stamp (builtin_interfaces/Time) and doubles."""
        data = bytearray(self.template)
        np.frombuffer(data, dtype='<f8', offset=4, count=(len(data) - 4) // 8)[
            self.doubles] = doubles
        words = np.frombuffer(data, dtype='<u4', count=len(data) // 4)
        words[self.seconds] = stamp.sec & 0xFFFF_FFFF
        words[self.nanoseconds] = stamp.nanosec
        return bytes(data)


def prefix(msg, tail):
    """The bytes of ``msg`` serialised, but for its last field, an array that serialises
    as ``tail`` (bytes): a message whose last array is all that changes is this prefix and
    the array's bytes (the microphones: 40 messages a second a robot)."""
    data = _exact(serialize_message(msg), type(msg))
    if data[:2] != b'\x00\x01' or not data.endswith(tail):
        raise ValueError('not a little-endian CDR message ending in that array')
    return data[:len(data) - len(tail)]
