"""ROS parameters declared from dataclasses: one field, one parameter.

A field's default is the parameter's default, its metadata['help'] the
description and its metadata['range'] (lowest, highest) the values it may take,
so a node's declarations, its --help and the README cannot drift apart. The
dataclass's __post_init__ calls check_ranges and validates the whole set.
Every number is bounded: a value that is legal but absurd (a 1e9 s tick, a
99999 px blur) would otherwise be accepted at start and hang or fail later.

A node with many groups names them the ROS 2 way, with dotted names: ``Group('affect',
AffectParams)`` declares ``affect.gain``, ... (a YAML params file nests them under
``affect:``). A plain dataclass is a group without a prefix.
"""
import functools
import math
from dataclasses import fields, MISSING, replace
from pathlib import Path
from typing import NamedTuple

from miro_ball.common.throttle import Throttled

# Parameters every rclpy node has; a user may set them on any of ours.
ROS_OWN_PARAMS = {'use_sim_time': False, 'start_type_description_service': True}
ROS_OWN_PREFIXES = ('qos_overrides.',)
# A --params-file is read only if it is a regular file of at most this size (a FIFO held
# the program for ever, here and in rcl's own read; /dev/urandom was read as YAML).
PARAMS_FILE_MAX_BYTES = 1 << 20


class Group(NamedTuple):
    """A params dataclass whose parameters are named '<prefix>.<field>'."""

    prefix: str
    cls: type


def group_of(group):
    """A Group for a Group or a plain dataclass (no prefix)."""
    return group if isinstance(group, Group) else Group('', group)


def full_name(prefix, name):
    return f'{prefix}.{name}' if prefix else name


def parameters(*groups):
    """[(parameter name, dataclass, field)] of every field of the groups, in order."""
    return [(full_name(prefix, f.name), cls, f)
            for prefix, cls in map(group_of, groups) for f in fields(cls)]


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


def declare(node, group):
    """Declare every field of a group (a dataclass, or a Group) on the node and return the
    filled-in dataclass (the command line's values checked: coerce, then the dataclass's
    ranges)."""
    from rcl_interfaces.msg import ParameterDescriptor
    from rclpy.parameter import Parameter

    given = {}
    for name, _, f in parameters(group):
        default = default_of(f)
        descriptor = ParameterDescriptor(description=f.metadata['help'], dynamic_typing=True)
        declared = list(default) if isinstance(default, tuple) else default
        value = given[name] = node.declare_parameter(name, declared, descriptor).value
        stored = as_declared(value, default)
        if stored is not value:  # -p x:=0 for a float: stored as the double it is
            node.set_parameters([Parameter(name, value=stored)])
    return values_of(group, given)


def as_declared(value, default):
    """value as the parameter of that default holds it: a float's integer as a float (ROS
    types the 0 of -p real_time_factor:=0 as an integer, and the parameter then said
    "Integer value is: 0" to ros2 param get); any other value itself (coerce checks it)."""
    if isinstance(default, float) and isinstance(value, int) and not isinstance(value, bool):
        return float(value)
    return value


def values_of(group, given):
    """A group's filled-in dataclass from {parameter name: value} (a name not given: its
    default), checked as a node's declared values are: coerce, then the dataclass's ranges
    and its own checks. ValueError in one line."""
    prefix, cls = group_of(group)
    values = {f.name: coerce(name, given.get(name, default_of(f)), default_of(f))
              for name, _, f in parameters(group)}
    try:
        return cls(**values)
    except ValueError as err:
        raise ValueError(_in_group(prefix, err)) from None


def _in_group(prefix, err):
    """A dataclass's own complaint ('parameter gain must be ...') with the group's prefix."""
    text = str(err)
    return f'{prefix}: {text}' if prefix else text


def ros_overrides(argv, node_name):
    """{name: value} of every parameter the ``--ros-args`` parts of argv set for a node called
    node_name: ``-p name:=value`` and the node's (or ``/**``'s) part of ``--params-file``.
    A node_name with a leading '/' is the node's fully qualified name, and a part of the file
    applies as rcl applies it (node_matches); a bare name: any part naming it, in any
    namespace (what a command line's check may look at).

    rclpy keeps the overrides it parsed to itself (a private attribute of Node), and a node
    that never declares a name never sees it: so the command line is read here, as rcl reads
    it (a value is YAML). ValueError in one line for what can not be read.
    """
    import yaml

    found = {}
    for flag, rule in _ros_rules(argv):
        if flag in ('-p', '--param'):
            name, sep, text = rule.partition(':=')
            if not sep or not name:
                raise ValueError(f'{flag} {rule!r}: expected name:=value')
            try:
                found[name] = yaml.safe_load(text)
            except yaml.YAMLError:
                found[name] = text
        elif flag == '--params-file':
            found.update(_params_file(rule, node_name))
    return found


def _ros_rules(argv):
    """(flag, the argument after it) of each -p, -r and --params-file in the ``--ros-args``
    parts of argv, in order."""
    inside, tokens = False, iter(argv)
    for token in tokens:
        if token == '--ros-args':
            inside = True
        elif token == '--':
            inside = False
        elif inside and token in ('-p', '--param', '-r', '--remap', '--params-file'):
            yield token, next(tokens, '')


def _params_file(path, node_name):
    import yaml

    from miro_ball.common.files import read_regular

    shown = f'--params-file {path[:200]!r}'
    try:
        text = read_regular(Path(path).resolve(), PARAMS_FILE_MAX_BYTES)
        if len(text) > PARAMS_FILE_MAX_BYTES:
            raise ValueError(f'{shown}: more than {PARAMS_FILE_MAX_BYTES >> 20} MB')
        content = yaml.safe_load(text) or {}
    except (OSError, RuntimeError, yaml.YAMLError) as err:  # RuntimeError: a link loop
        raise ValueError(f'{shown}: ' + ' '.join(str(err).split())[:300]) from None
    found = {}
    for node, section in (content.items() if isinstance(content, dict) else ()):
        key = str(node)
        if node_matches(key, node_name) if node_name.startswith('/') else (
                key in ('/**', node_name, '/' + node_name) or key.endswith('/' + node_name)):
            _flatten((section or {}).get('ros__parameters') or {}, '', found)
    return found


def node_matches(key, fqn):
    """Whether the part ``key`` of a --params-file applies to the node of fully qualified
    name ``fqn``, as rcl decides: a key is taken from the root ('kick_blue_ball' is
    '/kick_blue_ball', not '/<robot>/kick_blue_ball'), '*' stands for one part of the name
    and '**' for any number of parts."""
    name = fqn.strip('/').split('/')
    parts = key.strip('/').split('/')
    pattern = [part for k, part in enumerate(parts)
               if part != '**' or k == 0 or parts[k - 1] != '**']  # '**/**' is '**'
    if sum(part != '**' for part in pattern) > len(name):
        return False  # (and the recursion below stays as deep as the node's name is long)

    # Each (pattern part, name part) pair decided once: a key of many '**' (a params file
    # can be anything) took time exponential in their number.
    @functools.cache
    def match(p, n):
        if p == len(pattern):
            return n == len(name)
        if pattern[p] == '**':
            return any(match(p + 1, i) for i in range(n, len(name) + 1))
        return n < len(name) and pattern[p] in ('*', name[n]) and match(p + 1, n + 1)

    return match(0, 0)


def remapped_namespace(argv):
    """The namespace the ``--ros-args`` parts of argv give a node (``-r __ns:=/ns``), or None."""
    found = None
    for flag, rule in _ros_rules(argv):
        name, sep, value = rule.partition(':=')
        if flag in ('-r', '--remap') and sep and name == '__ns':
            found = value
    return found


def _flatten(tree, prefix, into):
    for key, value in tree.items():
        if isinstance(value, dict):
            _flatten(value, f'{prefix}{key}.', into)
        else:
            into[prefix + str(key)] = value


def check_overrides(overrides, *groups):
    """ValueError in one line for the first override that names no parameter of the groups
    (nor one of ROS's own), with the nearest known names, or whose value has the wrong type.
    A typo must not run the defaults as if nothing had been said."""
    import difflib

    known = {name: f for name, _, f in parameters(*groups)}
    for name, value in overrides.items():
        if name.startswith(ROS_OWN_PREFIXES):
            continue
        if name in ROS_OWN_PARAMS:
            coerce(name, value, ROS_OWN_PARAMS[name])
            continue
        if name not in known:
            near = difflib.get_close_matches(name, list(known) + list(ROS_OWN_PARAMS), n=3)
            hint = (' (did you mean %s?)' % ', '.join(near)) if near else (
                ' (--help lists the parameters)' if known else
                ' (this node has none of its own; ROS\'s: %s)' % ', '.join(ROS_OWN_PARAMS))
            raise ValueError(f'unknown parameter {name!r}{hint}')
        coerce(name, value, default_of(known[name]))


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
    return [(name, _show(default_of(f)), _help(f)) for name, _, f in parameters(*groups)]


def help_lines(*groups):
    """The parameter table as --help epilog lines."""
    rows = table(*groups)
    width = max(len(name) for name, _, _ in rows)
    return ['parameters (--ros-args -p name:=value):'] + [
        '  %-*s  %-14s %s' % (width, name, default, text) for name, default, text in rows]


class LiveParams:
    """Run-time set_parameters for a node whose parameters are dataclass fields.

    A change is checked exactly as at start (coerce, the ranges, the dataclass's own
    checks) and handed to apply(updated dataclass), which may refuse it with ValueError; a
    change to a name in ``fixed``, or one that fails a check, is refused with the reason.
    Never accepted and then ignored.
    Parameters that are not fields (use_sim_time) are left to rclpy.
    """

    def __init__(self, node, values, apply, fixed=(), groups=None):
        """values: the declared dataclasses; groups: how each was declared (the dataclasses
        or Groups, in the same order; default: no prefixes)."""
        self.values = {type(v): v for v in values}
        self.apply = apply
        # A client may toggle a switch a thousand times a second: a few lines, not a flood.
        self.log = Throttled(node.get_logger().info)
        self.fixed = set(fixed)
        self._owner = {name: (cls, f) for name, cls, f
                       in parameters(*(groups or list(self.values)))}
        node.add_pre_set_parameters_callback(self._as_declared)
        node.add_on_set_parameters_callback(self._on_set)

    def _as_declared(self, changes):
        """The parameters to set, a float's integer made a float (as_declared)."""
        from rclpy.parameter import Parameter

        typed = []
        for parameter in changes:
            owner = self._owner.get(parameter.name)
            value = parameter.value if owner is None else as_declared(parameter.value,
                                                                      default_of(owner[1]))
            typed.append(parameter if value is parameter.value
                         else Parameter(parameter.name, value=value))
        return typed

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
                value = coerce(parameter.name, parameter.value, default_of(f))
                updated[cls] = replace(updated[cls], **{f.name: value})
            except (ValueError, TypeError) as err:
                return SetParametersResult(successful=False, reason=str(err))
            said.append(f'{parameter.name} := {_show(value)}')
        changed = [v for cls, v in updated.items() if v != self.values[cls]]
        for values in changed:
            try:
                self.apply(values)  # ValueError: the node can not take it (a mode that
            except ValueError as err:  # needs other parameters): refused, nothing changed
                return SetParametersResult(successful=False, reason=str(err))
            self.values[type(values)] = values
        if said:
            self.log('set', 'set at run time: ' + ', '.join(said))
        return SetParametersResult(successful=True)
