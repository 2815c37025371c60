"""ROS parameters declared from dataclasses: one field, one parameter.

A field's default is the parameter's default, its metadata['help'] the
description and its metadata['range'] (lowest, highest) the values it may take,
so a node's declarations, its --help and the README cannot drift apart. The
dataclass's __post_init__ calls check_ranges and validates the whole set.
Every number is bounded: a value that is legal but absurd (a 1e9 s tick, a
99999 px blur) would otherwise be accepted at start and hang or fail later.
"""
import math
from dataclasses import fields, MISSING, replace


def default_of(f):
    return f.default_factory() if f.default is MISSING else f.default


def coerce(name, value, default):
    """A parameter value in the type of its default, or ValueError saying what was wrong.

    Numbers are accepted loosely (-p fast:=1 is 1.0), since ROS types 1 as an integer.
    """
    def fail(kind):
        return ValueError("parameter '%s' must be %s, not %r" % (name, kind, value))

    if isinstance(default, tuple):
        if isinstance(value, (str, bytes)) or not hasattr(value, '__len__'):
            raise fail('a list of %d integers' % len(default))
        if len(value) != len(default):
            raise fail('a list of %d integers' % len(default))
        return tuple(coerce(name, v, default[0]) for v in value)
    if isinstance(default, str):
        if not isinstance(value, str):
            raise fail('a string')
        return value
    if isinstance(default, bool):
        if not isinstance(value, bool):
            raise fail('true or false')
        return value
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise fail('a number')
    if not math.isfinite(value):
        raise fail('finite')
    if isinstance(default, int):
        if value != int(value):
            raise fail('an integer')
        return int(value)
    return float(value)


def check_ranges(values):
    """ValueError naming the first field of a params dataclass outside its range."""
    for f in fields(values):
        bounds = f.metadata.get('range')
        value = getattr(values, f.name)
        if bounds is None:
            continue
        lowest, highest = bounds
        if not all(lowest <= v <= highest for v in (value if isinstance(value, tuple)
                                                    else (value,))):
            raise ValueError('parameter %s must be in [%s, %s], not %s'
                             % (f.name, _show(lowest), _show(highest), _show(value)))


def declare(node, cls, overrides=None):
    """Declare every field of cls on the node and return the filled-in dataclass.

    overrides: {name: value} that win over the node's own (e.g. from the command line).
    """
    from rcl_interfaces.msg import ParameterDescriptor

    values = {}
    for f in fields(cls):
        default = default_of(f)
        descriptor = ParameterDescriptor(description=f.metadata['help'], dynamic_typing=True)
        declared = list(default) if isinstance(default, tuple) else default
        value = node.declare_parameter(f.name, declared, descriptor).value
        if overrides and f.name in overrides:
            value = overrides[f.name]
        values[f.name] = coerce(f.name, value, default)
    return cls(**values)


def _show(value):
    if isinstance(value, tuple):
        return '[%s]' % ','.join(_show(v) for v in value)
    return '%g' % value if isinstance(value, float) else str(value)


def _help(f):
    bounds = f.metadata.get('range')
    if bounds is None:
        return f.metadata['help']
    return '%s [%s..%s]' % (f.metadata['help'], _show(bounds[0]), _show(bounds[1]))


def table(*groups):
    """(name, default as text, help with the range) for every parameter of the groups."""
    return [(f.name, _show(default_of(f)), _help(f)) for cls in groups for f in fields(cls)]


def help_lines(*groups):
    """The parameter table as --help epilog lines."""
    rows = table(*groups)
    width = max(len(name) for name, _, _ in rows)
    return ['parameters (--ros-args -p name:=value):'] + [
        '  %-*s  %-14s %s' % (width, name, default, text) for name, default, text in rows]


class LiveParams:
    """Run-time set_parameters for a node whose parameters are dataclass fields.

    A change is checked exactly as at start (coerce, the ranges, the dataclass's own
    checks) and handed to apply(updated dataclass); a change to a name in ``fixed``, or one
    that fails a check, is refused with the reason. Never accepted and then ignored.
    Parameters that are not fields (use_sim_time) are left to rclpy.
    """

    def __init__(self, node, values, apply, fixed=()):
        self.values = {type(v): v for v in values}
        self.apply = apply
        self.log = node.get_logger().info
        self.fixed = set(fixed)
        self._owner = {f.name: (cls, f) for cls in self.values for f in fields(cls)}
        node.add_on_set_parameters_callback(self._on_set)

    def _on_set(self, parameters):
        from rcl_interfaces.msg import SetParametersResult

        updated, said = dict(self.values), []
        for parameter in parameters:
            if parameter.name not in self._owner:
                continue
            if parameter.name in self.fixed:
                return SetParametersResult(successful=False, reason=(
                    f'{parameter.name} is read at start only: restart the node to change it'))
            cls, f = self._owner[parameter.name]
            try:
                value = coerce(f.name, parameter.value, default_of(f))
                updated[cls] = replace(updated[cls], **{f.name: value})
            except (ValueError, TypeError) as err:
                return SetParametersResult(successful=False, reason=str(err))
            said.append(f'{f.name} := {_show(value)}')
        changed = [v for cls, v in updated.items() if v != self.values[cls]]
        self.values = updated
        for values in changed:
            self.apply(values)
        if said:
            self.log('set at run time: ' + ', '.join(said))
        return SetParametersResult(successful=True)
