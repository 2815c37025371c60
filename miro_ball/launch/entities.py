"""A launch file read into entities (an element, its attributes and children), whichever of
ROS 2's two descriptive formats it is written in, XML or YAML; only the subset of the
format that we run is accepted, anything else refused in one line naming it and its file.

The two formats say the same things differently: XML nests elements; YAML writes an
action as a one-key mapping (``- node: {pkg: ..., exec: ...}``), a group's actions as
its list, and a node's params and remaps, or an include's args, as lists under its keys.
"""
from dataclasses import dataclass, field
from pathlib import Path
from xml.etree import ElementTree

import yaml

from miro_ball.common.files import read_regular
from miro_ball.launch import LaunchError
from miro_ball.ros2.convert import check_yaml

MAX_FILE_BYTES = 1 << 20  # ours are 2 kB; a launch file is text a person writes
# Elements inside elements, <launch> counted: ours nest three deep. Also what keeps reading
# and planning (a recursion each) far from Python's recursion limit, includes and all.
MAX_NESTING = 12

ACTIONS = ('arg', 'let', 'node', 'executable', 'group', 'include')
CONDITIONS = ('if', 'unless')
PROCESS = ('name', 'args', 'output', 'respawn', 'respawn_delay', 'on_exit') + CONDITIONS
# element: (attributes, child elements); an include's <arg> passes a value, so it has a
# row of its own. launch_ros spells the namespace action both ways.
SUBSET = {
    'launch': ((), ACTIONS),
    'arg': (('name', 'default', 'description'), ()),
    'let': (('name', 'value'), ()),
    'node': (('pkg', 'exec', 'namespace') + PROCESS, ('param', 'remap')),
    'param': (('name', 'value'), ()),
    'remap': (('from', 'to'), ()),
    'executable': (('cmd',) + PROCESS, ()),
    'group': (CONDITIONS, ACTIONS + ('push_ros_namespace', 'push-ros-namespace')),
    'push_ros_namespace': (('namespace',), ()),
    'push-ros-namespace': (('namespace',), ()),
    'include': (('file',) + CONDITIONS, ('arg',)),
    'include/arg': (('name', 'value'), ()),
}
REQUIRED = {'arg': ('name',), 'let': ('name', 'value'), 'node': ('pkg', 'exec'),
            'param': ('name', 'value'), 'remap': ('from', 'to'), 'executable': ('cmd',),
            'push_ros_namespace': ('namespace',), 'push-ros-namespace': ('namespace',),
            'include': ('file',), 'include/arg': ('name', 'value')}
ACTION_LISTS = ('launch', 'group')  # in YAML, their children are a list of one-key mappings


@dataclass
class Entity:
    kind: str  # 'include/arg' for an include's <arg>
    attrs: dict  # name -> str
    file: Path
    children: list = field(default_factory=list)


def read_file(path):
    """The root entity (<launch>) of the launch file at path; LaunchError if it can not be
    read, is neither XML nor YAML, or steps outside the subset."""
    path = Path(path)
    read = {'.xml': _from_xml, '.yaml': _from_yaml, '.yml': _from_yaml}.get(path.suffix)
    if read is None:
        raise LaunchError(f'{path}: not a launch file in XML or YAML (.launch.xml, '
                          '.launch.yaml; Python launch files need ros2 launch)')
    try:  # links followed (a colcon --symlink-install's share folder is links), then
        # opened without waiting: a FIFO or a device is refused, not waited on
        data = read_regular(path.resolve(), MAX_FILE_BYTES)
        text = data.decode()
    except (OSError, RuntimeError, UnicodeDecodeError) as err:
        raise LaunchError(f'{path}: can not be read ({err})') from None
    if len(data) > MAX_FILE_BYTES:
        raise LaunchError(f'{path}: over {MAX_FILE_BYTES >> 20} MB, too big for a launch file')
    return read(text, path)


def _checked(kind, attrs, path, parent, depth):
    """The entity's row of SUBSET; LaunchError for an element, attribute or missing
    attribute outside it, or for one nested deeper than MAX_NESTING."""
    key = f'{parent}/{kind}' if f'{parent}/{kind}' in SUBSET else kind
    where = f'{path}: <{kind}>'
    if depth > MAX_NESTING:
        raise LaunchError(f'{where} is nested over {MAX_NESTING} elements deep')
    if key not in SUBSET or (parent and kind not in SUBSET[parent][1]):
        inside = f' inside <{parent}>' if parent not in ('', 'launch') else ''
        raise LaunchError(f'{where}{inside} is not supported by python -m miro_ball.launch '
                          '(docs/launch.md lists the subset)')
    allowed, _ = SUBSET[key]
    for name in attrs:
        if name not in allowed:
            raise LaunchError(f'{where}: attribute {name!r} is not supported by python -m '
                              f'miro_ball.launch (it takes {", ".join(allowed) or "none"})')
    for name in REQUIRED.get(key, ()):
        if name not in attrs:
            raise LaunchError(f'{where} needs the attribute {name!r}')
    return key


def _from_xml(text, path):
    try:
        root = ElementTree.fromstring(text)
    except ElementTree.ParseError as err:
        raise LaunchError(f'{path}: not well-formed XML ({err})') from None
    if root.tag != 'launch':
        raise LaunchError(f'{path}: the root element is <{root.tag}>, not <launch>')
    return _xml_entity(root, path, '', 1)


def _xml_entity(element, path, parent, depth):
    key = _checked(element.tag, element.attrib, path, parent, depth)
    return Entity(key, dict(element.attrib), path,
                  [_xml_entity(child, path, key, depth + 1) for child in element])


def _from_yaml(text, path):
    try:  # aliases expand 300 bytes into millions of values: refused before they are built
        check_yaml(text)
        document = yaml.safe_load(text)
    except yaml.YAMLError as err:
        raise LaunchError(f'{path}: not valid YAML ({" ".join(str(err).split())})') from None
    except ValueError as err:
        raise LaunchError(f'{path}: {err}') from None
    if not isinstance(document, dict) or list(document) != ['launch']:
        raise LaunchError(f'{path}: a YAML launch file is one mapping, launch: [actions]')
    return _yaml_entity('launch', document['launch'], path, '', 1)


def _yaml_entity(kind, body, path, parent, depth):
    where = f'{path}: <{kind}>'
    if kind in ACTION_LISTS:  # a list of actions, or (a group) a mapping with its children
        attrs = {str(k): v for k, v in body.items()} if isinstance(body, dict) else {}
        listed = attrs.pop('children', []) if isinstance(body, dict) else body
        if not isinstance(listed, list):
            raise LaunchError(f'{where} holds a list of actions')
        key = _checked(kind, attrs, path, parent, depth)
        attrs = _scalars(attrs, where)
        return Entity(key, attrs, path, [_yaml_entity(*_one_key(item, where), path, key,
                                                      depth + 1) for item in listed])
    if not isinstance(body, dict):
        raise LaunchError(f'{where} is a mapping of its attributes')
    children = SUBSET.get(kind, ((), ()))[1]
    attrs = {str(name): value for name, value in body.items() if name not in children}
    key = _checked(kind, attrs, path, parent, depth)
    entity = Entity(key, _scalars(attrs, where), path)
    for child in (name for name in body if name in children):
        if not isinstance(body[child], list):
            raise LaunchError(f'{where}: {child} holds a list of mappings')
        entity.children += [_yaml_entity(child, item, path, key, depth + 1)
                            for item in body[child]]
    return entity


def _one_key(item, where):
    if not isinstance(item, dict) or len(item) != 1:
        raise LaunchError(f'{where}: each action is a mapping of one key (its kind), got '
                          f'{str(item)[:60]!r}')
    return next(iter(item.items()))


def _scalars(attrs, where):
    """Attribute values as the XML format has them: text (YAML's true is 'true')."""
    text = {}
    for name, value in attrs.items():
        if isinstance(value, bool):
            text[name] = 'true' if value else 'false'
        elif isinstance(value, (str, int, float)):
            text[name] = str(value)
        elif value is None:
            text[name] = ''
        else:
            raise LaunchError(f'{where}: attribute {name!r} must be a single value')
    return text
