"""ROS 2 messages to and from plain data and YAML, as the ``ros2`` command line shows and
reads them (plain Python on the message classes' own introspection: their fields, types and
SLOT_TYPES; rosidl_runtime_py, which does this for ``ros2``, is not on PyPI).

- to_data(msg): a dict of the message's fields in order; arrays longer than ``truncate``
  end in '...', as ``ros2 topic echo`` does by default.
- to_yaml(data): the YAML ``ros2 topic echo`` prints (block style, fields in order).
- fill(msg, data): set a message's fields from a dict (``ros2 topic pub``'s YAML); a field
  that does not exist or a value of the wrong kind is a ValueError naming it.
- field(msg, path): the value of 'twist.linear.x' (``--field``).
"""
import math
import re
from array import array

import numpy as np
import yaml

TRUNCATE = 128  # ros2 topic echo's default --truncate-length
MAX_DEPTH = 100  # nesting of a YAML value: a message nests a few levels, never this many


def is_message(value):
    return hasattr(type(value), 'get_fields_and_field_types')


def to_data(msg, truncate=TRUNCATE):
    """A message as plain data (dicts, lists, numbers, strings)."""
    if is_message(msg):
        return {name: to_data(getattr(msg, name), truncate)
                for name in msg.get_fields_and_field_types()}
    if isinstance(msg, (list, tuple, array, np.ndarray, bytes)):
        items = [to_data(v, truncate) for v in (msg[:truncate] if truncate else msg)]
        if truncate and len(msg) > truncate:
            items.append('...')
        return items
    if isinstance(msg, np.generic):
        return msg.item()
    return msg


class _Dumper(yaml.SafeDumper):
    """ros2's YAML: lists as block sequences under their key, with no extra indent."""


_Dumper.add_representer(float, lambda dumper, value: dumper.represent_scalar(
    'tag:yaml.org,2002:float', repr(value) if math.isfinite(value)
    else ('.nan' if math.isnan(value) else ('.inf' if value > 0 else '-.inf'))))


def to_yaml(data):
    """The YAML text of plain data, fields in their order."""
    return yaml.dump(data, Dumper=_Dumper, default_flow_style=False, sort_keys=False,
                     allow_unicode=True, width=10**9)


def has_alias(text):
    """Whether YAML text uses an alias (*name); yaml.YAMLError if it is no YAML."""
    return any(isinstance(event, yaml.AliasEvent) for event in yaml.parse(text))


def check_yaml(text):
    """ValueError for aliases, or for nesting deeper than any message has, seen as the text
    is read: 5000 brackets cost PyYAML 6 s of CPU before it ran out of recursion."""
    depth = 0
    for event in yaml.parse(text):
        if isinstance(event, yaml.AliasEvent):
            raise ValueError('the values use YAML aliases (*name): write the values out')
        if isinstance(event, yaml.CollectionStartEvent):
            depth += 1
            if depth > MAX_DEPTH:
                raise ValueError('the values are nested too deeply')
        elif isinstance(event, yaml.CollectionEndEvent):
            depth -= 1


def parse_yaml(text):
    """A dict from the YAML (or '') of ros2 topic pub / service call; ValueError if not.

    No anchors or aliases (& and *): 270 bytes of aliases nine deep expand to billions of
    values (a MemoryError after 40 s); a message's fields never need them."""
    try:
        check_yaml(text)
        data = yaml.safe_load(text) if text.strip() else {}
    except yaml.YAMLError as err:
        mark = getattr(err, 'problem_mark', None)
        where = f' (line {mark.line + 1}, column {mark.column + 1})' if mark else ''
        raise ValueError(f'the values are not valid YAML{where}: {text[:200]!r}') from None
    except RecursionError:
        raise ValueError('the values are nested too deeply') from None
    if data is None:
        data = {}
    if not isinstance(data, dict):
        raise ValueError(f'the values must be a YAML mapping of field: value, got {text[:200]!r}')
    return data


def fill(msg, data, path=''):
    """Set msg's fields from a dict, recursively; returns msg. ValueError in one line for a
    field that does not exist or a value that does not fit its type."""
    fields = msg.get_fields_and_field_types()
    for name, value in data.items():
        where = f'{path}{name}'
        if name not in fields:
            raise ValueError(f"{type(msg).__name__} has no field '{where}' (it has: "
                             f'{", ".join(fields)})')
        current = getattr(msg, name)
        try:
            if is_message(current):
                if not isinstance(value, dict):
                    raise ValueError(f'{where} is a {fields[name]}: give a mapping')
                fill(current, value, where + '.')
            elif fields[name].startswith(('sequence<', 'array<')) or '[' in fields[name]:
                setattr(msg, name, _sequence(msg, name, value, where))
            else:
                setattr(msg, name, _scalar(value, fields[name], where))
        except (AssertionError, TypeError, OverflowError) as err:
            raise ValueError(f'{where} ({fields[name]}) can not be {value!r}: {err}') from None
    return msg


def _sequence(msg, name, value, where):
    if not isinstance(value, list):
        raise ValueError(f'{where} is a sequence: give a list, as [1, 2]')
    slot = msg.SLOT_TYPES[list(msg.get_fields_and_field_types()).index(name)]
    size, most = getattr(slot, 'size', None), getattr(slot, 'maximum_size', None)
    if size is not None and len(value) != size:
        raise ValueError(f'{where} holds exactly {size} items: give {size}, not {len(value)}')
    if most is not None and len(value) > most:
        raise ValueError(f'{where} holds at most {most} items, not {len(value)}')
    inner = slot.value_type
    if hasattr(inner, 'namespaces'):  # a sequence of messages
        module = __import__('.'.join(inner.namespaces), fromlist=[inner.name])
        items = []
        for k, item in enumerate(value):
            if not isinstance(item, dict):
                raise ValueError(f'{where}[{k}] is a {inner.name}: give a mapping')
            items.append(fill(getattr(module, inner.name)(), item, f'{where}[{k}].'))
        return items
    # a string's slot type has no typename (its bound is its maximum_size)
    kind = getattr(inner, 'typename', 'string')
    return [_scalar(item, kind, f'{where}[{k}]') for k, item in enumerate(value)]


FLOATS = ('float', 'double', 'long double')
# A float as YAML 1.2 writes it. PyYAML reads YAML 1.1, where 1e-3 (no dot) is text, and
# ros2 makes a float field of that text all the same: so do we ('give a number, not 1e-3').
FLOAT_TEXT = re.compile(r'[-+]?(\.[0-9]+|[0-9]+(\.[0-9]*)?)([eE][-+]?[0-9]+)?')
INTEGERS = {'octet': (0, 255), **{f'int{bits}': (-2 ** (bits - 1), 2 ** (bits - 1) - 1)
                                  for bits in (8, 16, 32, 64)},
            **{f'uint{bits}': (0, 2 ** bits - 1) for bits in (8, 16, 32, 64)}}


def _scalar(value, type_name, where):
    """value checked against a field's type ('uint8', 'double', 'string<=8', ...): the
    generated classes check nothing unless ROS_PYTHON_CHECK_FIELDS=1, and an integer out of
    range was sent wrapped (uint8 300 as 44) or failed in the C code with a traceback."""
    if type_name == 'boolean':
        if not isinstance(value, bool):
            raise ValueError(f'{where} is a bool: give true or false')
        return value
    if type_name in FLOATS:
        if isinstance(value, str) and FLOAT_TEXT.fullmatch(value):
            value = float(value)
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ValueError(f'{where} is a {type_name}: give a number, not {value!r}')
        return float(value)
    if type_name in INTEGERS:
        low, high = INTEGERS[type_name]
        if isinstance(value, bool) or not isinstance(value, int):
            raise ValueError(f'{where} is a {type_name}: give an integer, not {value!r}')
        if not low <= value <= high:
            raise ValueError(f'{where} is a {type_name}: give an integer from {low} to {high}, '
                             f'not {value}')
        return bytes([value]) if type_name == 'octet' else value
    if type_name.startswith(('string', 'wstring')):
        text = value if isinstance(value, str) else str(value)
        most = type_name.partition('<=')[2]
        if most and len(text) > int(most):
            raise ValueError(f'{where} is a {type_name}: at most {most} characters')
        return text
    return value


def field(msg, path):
    """The value at a dotted field path ('twist.linear.x'); ValueError naming the part that
    does not exist."""
    value = msg
    for part in path.split('.'):
        if not is_message(value) or part not in value.get_fields_and_field_types():
            raise ValueError(f"no field '{part}' in {type(value).__name__} (--field {path})")
        value = getattr(value, part)
    return value
