"""A launch file and the arguments given to it, turned into the processes to start: the
launch file's meaning, evaluated as ROS 2's launch evaluates it, without starting anything.

As in ROS 2, arguments are launch configurations that an included file sees too (an arg
given on the command line reaches the file that declares it, however deep), an arg's
default applies only when nobody gave it a value, and a group keeps what is set inside it
(lets, the namespace it pushes) to itself. Here an include is scoped as a group is, so no
file depends on what another leaks.
"""
import shlex
from dataclasses import dataclass, field, replace
from pathlib import Path

from miro_ball.launch import LaunchError
from miro_ball.launch.entities import read_file
from miro_ball.launch.substitutions import substitute, truth

MAX_INCLUDE_DEPTH = 20  # deeper is a file including itself, in all likelihood
# In all, whatever the depth: a 3.5 kB file that includes itself four times, stopping at
# depth 19 by its own arguments, asked for 4^19 includes. Ours take 6 includes and 150
# actions; ROS 2 stacks a few dozen includes and hundreds of actions.
MAX_INCLUDES = 100
MAX_ACTIONS = 5000  # elements evaluated: actions, and a node's params and remaps
MAX_PROCESSES = 100


@dataclass(frozen=True)
class Process:
    """One process to start: a node (pkg and exec) or an executable (cmd)."""
    label: str  # what its output lines are prefixed with
    source: Path  # the file that asked for it
    pkg: str = None
    exec: str = None
    cmd: tuple = ()  # an <executable>'s command
    args: tuple = ()
    name: str = None
    namespace: str = None  # absolute
    params: tuple = ()  # (name, value) pairs
    remaps: tuple = ()  # (from, to) pairs
    respawn: bool = False
    respawn_delay: float = 0.0
    shutdown_on_exit: bool = False  # on_exit="shutdown": its end ends the run


@dataclass(frozen=True)
class Arg:
    name: str
    default: str  # None: required
    description: str
    file: Path


@dataclass
class Plan:
    processes: list
    args: dict  # name -> Arg: the arguments a user may give, includes' too
    missing: list  # required arguments nobody gave


@dataclass
class Scope:
    file: Path
    configs: dict
    namespace: str  # '' or absolute
    share: object  # package -> its share folder
    environ: object
    depth: int = 0

    def inner(self, **changes):
        """A scope of its own (a group, an include) that starts as this one."""
        fields = dict(vars(self), configs=dict(self.configs), **changes)
        return Scope(**fields)


@dataclass
class _Found:
    processes: list = field(default_factory=list)
    args: dict = field(default_factory=dict)
    declared: list = field(default_factory=list)  # every declaration's name, in order
    fixed: dict = field(default_factory=dict)  # name -> the file whose include sets it
    missing: list = field(default_factory=list)
    includes: int = 0
    actions: int = 0

    def count(self, entity):
        """Note that entity is evaluated; LaunchError once the plan is over a bound."""
        # A group's children are actions, counted as each is evaluated; the others' are
        # their params, remaps and args.
        self.actions += 1 if entity.kind == 'group' else 1 + len(entity.children)
        self.includes += entity.kind == 'include'
        for done, most, what in ((self.actions, MAX_ACTIONS, 'actions'),
                                 (self.includes, MAX_INCLUDES, 'includes')):
            if done > most:
                raise LaunchError(f'{entity.file}: <{entity.kind}>: over {most} {what} in all '
                                  '(does a file include itself?)')

    def add(self, process, entity):
        if len(self.processes) >= MAX_PROCESSES:
            raise LaunchError(f'{entity.file}: <{entity.kind}>: over {MAX_PROCESSES} '
                              'processes in all')
        self.processes.append(process)


def make_plan(path, given, share, environ):
    """The Plan of the launch file at path with the arguments given ({name: value}); share:
    package -> share folder (for $(find-pkg-share)); environ: for $(env). LaunchError for a
    file that can not be run, or an argument the files do not declare. Required arguments
    left out are in Plan.missing (--help lists a file's arguments without them)."""
    found = _Found()
    path = Path(path)
    _actions(read_file(path).children, Scope(path, dict(given), '', share, environ), found)
    args = {name: arg for name, arg in found.args.items() if name not in found.fixed}
    for name in given:
        if name in found.fixed:
            raise LaunchError(f'{name} is not for the user to give: {found.fixed[name].name} '
                              'sets it itself')
    if unknown := [name for name in given if name not in args]:
        raise LaunchError(f'{path.name} declares no argument {", ".join(unknown)} (it takes '
                          f'{", ".join(args) or "none"})')
    return Plan(_labelled(found.processes), args, found.missing)


def _actions(entities, scope, found):
    for entity in entities:
        found.count(entity)
        if any(name in entity.attrs for name in ('if', 'unless')) and not _wanted(entity, scope):
            continue
        ACTION[entity.kind](entity, scope, found)


def _wanted(entity, scope):
    where = f'{entity.file}: <{entity.kind}>'
    wanted = True
    if 'if' in entity.attrs:
        wanted = truth(substitute(entity.attrs['if'], scope), where)
    if 'unless' in entity.attrs:
        wanted = wanted and not truth(substitute(entity.attrs['unless'], scope), where)
    return wanted


def _arg(entity, scope, found):
    name, default = entity.attrs['name'], entity.attrs.get('default')
    found.declared.append(name)
    found.args.setdefault(name, Arg(name, default, entity.attrs.get('description', ''),
                                    entity.file))
    if name not in scope.configs:
        if default is None:
            found.missing.append(name)
            scope.configs[name] = f'<{name}>'  # for --help, which lists what is needed
        else:
            scope.configs[name] = substitute(default, scope)


def _let(entity, scope, found):
    scope.configs[entity.attrs['name']] = substitute(entity.attrs['value'], scope)


def _group(entity, scope, found):
    _actions(entity.children, scope.inner(), found)


def _push_namespace(entity, scope, found):
    scope.namespace = absolute(substitute(entity.attrs['namespace'], scope), scope.namespace)


def _include(entity, scope, found):
    target = Path(substitute(entity.attrs['file'], scope))
    target = target if target.is_absolute() else entity.file.parent / target
    if scope.depth >= MAX_INCLUDE_DEPTH:
        raise LaunchError(f'{entity.file}: includes nested over {MAX_INCLUDE_DEPTH} deep '
                          f'(does {target.name} include itself?)')
    inner = scope.inner(file=target, depth=scope.depth + 1)
    for arg in entity.children:
        inner.configs[arg.attrs['name']] = substitute(arg.attrs['value'], scope)
    try:
        root = read_file(target)
    except LaunchError as err:  # say which file's include it is
        raise LaunchError(f'{entity.file}: <include>: {err}') from None
    start = len(found.declared)
    _actions(root.children, inner, found)
    passed = {arg.attrs['name'] for arg in entity.children}
    # What the include sets and no file declared before it, a user can not set.
    for name in passed - set(found.declared[:start]):
        found.fixed.setdefault(name, entity.file)
    if undeclared := sorted(passed - set(found.declared[start:])):
        raise LaunchError(f'{entity.file}: <include> passes {", ".join(undeclared)}, which '
                          f'{target.name} does not declare')


def _process(entity, scope):
    """What a node and an executable share: name, args, respawn, on_exit."""
    values = {name: substitute(value, scope) for name, value in entity.attrs.items()}
    where = f'{entity.file}: <{entity.kind}>'
    # Read as written, as ROS 2's launch reads it (no substitution), which knows no other
    # value in XML or YAML
    on_exit = entity.attrs.get('on_exit')
    if on_exit not in (None, 'shutdown'):
        raise LaunchError(f'{where}: on_exit={on_exit[:60]!r}: the only value is "shutdown" '
                          '(the run ends when this process ends)')
    try:
        args = tuple(shlex.split(values.get('args', '')))
        delay = float(values.get('respawn_delay', 0))
    except ValueError as err:
        raise LaunchError(f'{where}: {err}') from None
    if not 0 <= delay <= 3600:
        raise LaunchError(f'{where}: respawn_delay is in seconds, 0 to 3600')
    return values, dict(args=args, source=entity.file, name=values.get('name'),
                        respawn=truth(values.get('respawn', 'false'), where),
                        respawn_delay=delay, shutdown_on_exit=on_exit == 'shutdown')


def _node(entity, scope, found):
    values, common = _process(entity, scope)
    namespace = absolute(values['namespace'], scope.namespace) if 'namespace' in values \
        else scope.namespace or None
    pairs = {kind: tuple((substitute(c.attrs[a], scope), substitute(c.attrs[b], scope))
                         for c in entity.children if c.kind == kind)
             for kind, a, b in (('param', 'name', 'value'), ('remap', 'from', 'to'))}
    label = '/'.join(filter(None, [(namespace or '').strip('/'),
                                   values.get('name') or values['exec']]))
    found.add(Process(label, pkg=values['pkg'], exec=values['exec'], namespace=namespace,
                      params=pairs['param'], remaps=pairs['remap'], **common), entity)


def _executable(entity, scope, found):
    values, common = _process(entity, scope)
    try:
        cmd = tuple(shlex.split(values['cmd']))
    except ValueError as err:
        raise LaunchError(f'{entity.file}: <executable> cmd: {err}') from None
    if not cmd:
        raise LaunchError(f'{entity.file}: <executable> has an empty cmd')
    found.add(Process(values.get('name') or Path(cmd[0]).name, cmd=cmd, **common), entity)


ACTION = {'arg': _arg, 'let': _let, 'group': _group, 'include': _include, 'node': _node,
          'executable': _executable, 'push_ros_namespace': _push_namespace,
          'push-ros-namespace': _push_namespace}


def absolute(namespace, pushed):
    """namespace made absolute as launch_ros does: a relative one goes under the one pushed
    ('' or absolute); '' is the root namespace."""
    parts = namespace.strip('/')
    if namespace.startswith('/'):
        return '/' + parts if parts else ''
    return f'{pushed}/{parts}' if parts else pushed


def _labelled(processes):
    """processes with labels of their own: a second 'x' becomes 'x-2'."""
    seen, unique = {}, []
    for process in processes:
        seen[process.label] = seen.get(process.label, 0) + 1
        label = process.label if seen[process.label] == 1 \
            else f'{process.label}-{seen[process.label]}'
        unique.append(replace(process, label=label))
    return unique
