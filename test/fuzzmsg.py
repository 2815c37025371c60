"""Hostile messages of any ROS message type, for the fuzz tests.

Every leaf field of the type (found through rosidl's introspection, so new topics
are covered without writing anything) gets each of its hostile values in turn,
the others left at their defaults: NaN, infinities and the largest numbers; the
limits of every integer type; stamps far in the past, the future and negative;
empty, huge and NaN-filled arrays; empty and huge strings; undecodable bytes and
a JPEG decompression bomb.
"""
import importlib
import math

from rosidl_parser.definition import AbstractNestedType, Array, BasicType, NamespacedType

from hostile import decompression_bomb

FLOATS = [math.nan, math.inf, -math.inf, 1e308, -1e308, 3.4e38, -0.0, 5e-324]
INTS = {'int8': (-2**7, 2**7 - 1), 'int16': (-2**15, 2**15 - 1), 'int32': (-2**31, 2**31 - 1),
        'int64': (-2**63, 2**63 - 1), 'uint8': (0, 2**8 - 1), 'uint16': (0, 2**16 - 1),
        'uint32': (0, 2**32 - 1), 'uint64': (0, 2**64 - 1), 'octet': (0, 255),
        'char': (0, 255)}
LONG = 10000
BYTES = [b'', bytes(range(256)) * 4, b'\xff\xd8' + b'\xff' * 3000, decompression_bomb(),
         b'\x00' * 2_000_000]


def _message_class(namespaced):
    module = importlib.import_module('.'.join(namespaced.namespaces))
    return getattr(module, namespaced.name)


def _basic_values(typename):
    if typename in ('float', 'double'):
        return FLOATS
    if typename == 'boolean':
        return [True, False]
    low, high = INTS.get(typename, (0, 1))
    return [low, high, 0]


def _values(slot):
    """Hostile values of one field, as its setter takes them."""
    if isinstance(slot, AbstractNestedType):
        item = slot.value_type
        if isinstance(item, BasicType) and item.typename in ('uint8', 'octet'):
            return BYTES
        if isinstance(item, NamespacedType):
            return [[], [_message_class(item)()] * 1000]
        one = _basic_values(item.typename) if isinstance(item, BasicType) else ['']
        if isinstance(slot, Array):  # fixed size: every element the same hostile value
            return [[value] * slot.size for value in one]
        return [[], one[:1] * LONG, one * 3, one[-1:]]
    if isinstance(slot, BasicType):
        return _basic_values(slot.typename)
    return ['', 'x' * LONG, '\u00e9\u4e2d\U0001f600', '\x00']  # strings


def _leaves(msg_class, path=()):
    """(path of attribute names, slot type) of every leaf field."""
    for name, slot in zip(msg_class.get_fields_and_field_types(), msg_class.SLOT_TYPES):
        if isinstance(slot, NamespacedType):
            yield from _leaves(_message_class(slot), path + (name,))
        else:
            yield path + (name,), slot


def hostile(msg_class):
    """Messages of msg_class, each with one leaf field set to one hostile value."""
    yield msg_class()
    for path, slot in _leaves(msg_class):
        for value in _values(slot):
            msg = msg_class()
            holder = msg
            for name in path[:-1]:
                holder = getattr(holder, name)
            try:
                setattr(holder, path[-1], value)
            except (AssertionError, TypeError, ValueError, OverflowError):
                continue  # the message class itself refuses it: nobody can send it
            yield msg
