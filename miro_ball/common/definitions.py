"""Message definitions (.msg files) as ROS 2 installs them: share/<package>/msg/<Name>.msg
under each prefix of $AMENT_PREFIX_PATH and, for a pip install with no ROS sourced, this
Python environment's own prefix (where the ROS wheels and build_interfaces put them).

Used where a definition is shown (``ros2 interface show``) or stored (a bag's types, which
rosbags knows for ROS 2's own packages but not for miro2_msg).
"""
import functools
import os
import sys
from pathlib import Path

from miro_ball.common.files import is_dir, is_file

# The packages this project builds itself (python -m miro_ball.build_interfaces).
OWN_PACKAGES = ('miro2_msg',)


def prefixes():
    """Where installed packages are looked for, first wins."""
    listed = [p for p in os.environ.get('AMENT_PREFIX_PATH', '').split(os.pathsep) if p]
    return [Path(p) for p in dict.fromkeys(listed + [sys.prefix])]


def split_type(type_name):
    """('sensor_msgs', 'msg', 'Range') for 'sensor_msgs/msg/Range' (or 'sensor_msgs/Range');
    ValueError in one line if it is not a type name."""
    parts = type_name.split('/') if isinstance(type_name, str) else []
    if len(parts) == 2:
        parts.insert(1, 'msg')
    if len(parts) != 3 or not all(p.isidentifier() for p in parts) \
            or parts[1] not in ('msg', 'srv', 'action'):
        raise ValueError(f'{str(type_name)[:100]!r} is not a type name (package/msg/Name, '
                         'as geometry_msgs/msg/Twist)')
    return tuple(parts)


def definition_file(type_name):
    """The installed .msg/.srv file of a type; ValueError if none is installed."""
    package, kind, name = split_type(type_name)
    for prefix in prefixes():
        path = prefix / 'share' / package / kind / f'{name}.{kind}'
        if is_file(path):
            return path
    raise ValueError(f'no interface {f"{package}/{kind}/{name}"[:200]} is installed')


def package_messages(package):
    """{'pkg/msg/Name': definition text} of every message an installed package holds
    ({} if it is not installed)."""
    for prefix in prefixes():
        folder = prefix / 'share' / package / 'msg'
        if is_dir(folder):
            return {f'{package}/msg/{path.stem}': path.read_text()
                    for path in sorted(folder.glob('*.msg'))}
    return {}


@functools.cache
def typestore():
    """rosbags' typestore of ROS 2 Jazzy's types and ours that are built: what a bag or a
    Foxglove channel says a type is (ros2msg definitions), and how CDR bytes decode."""
    from rosbags.typesys import get_typestore, Stores

    store = get_typestore(Stores.ROS2_JAZZY)
    register_own_types(store)
    return store


def ros2msg(type_name):
    """A type's full definition as bags and Foxglove carry it (dependencies appended);
    KeyError if the type is unknown (or one it uses is: an action's feedback message, which
    no .msg file defines)."""
    from rosbags.typesys.base import TypesysError

    try:
        return typestore().generate_msgdef(type_name, ros_version=2)[0]
    except TypesysError as err:
        raise KeyError(type_name) from err


def register_own_types(typestore):
    """Teach a rosbags typestore the messages of our own packages that are installed, so a
    bag stores their definitions as for any ROS 2 type; returns the type names added."""
    from rosbags.typesys import get_types_from_msg

    added = {}
    for package in OWN_PACKAGES:
        for type_name, text in package_messages(package).items():
            if type_name not in typestore.fielddefs:
                added.update(get_types_from_msg(text, type_name))
    typestore.register(added)
    return sorted(added)
