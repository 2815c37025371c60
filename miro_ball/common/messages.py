"""ROS message classes from the type names of the interface table ('sensor_msgs/msg/Range')."""
import importlib
import importlib.util
import re
from pathlib import Path

from miro_ball.miro.interface import frame_id

# A type name as rosidl makes them: a package, msg, a CamelCase name.
_TYPE_NAME = re.compile(r'([a-z][a-z0-9_]*)/msg/([A-Z][A-Za-z0-9]*)\Z')
# Our tools drive the simulator through the standard simulator interfaces; an install built
# without a compiler has none (the simulator then serves only the older aliases).
NO_STANDARD = ('no simulation_interfaces in this install (python -m miro_ball.build_interfaces '
               'builds it)')


def message_class(type_name):
    """The Python class of a message type 'package/msg/Name'; ValueError if there is none.

    A type name may come from outside (a Foxglove client's advertisement): only a package
    with rosidl's generated msg/ folder is imported, so 'venv/msg/X' runs nothing of venv's
    (importing venv.__main__ ran its main() and ended the bridge)."""
    match = _TYPE_NAME.match(type_name) if isinstance(type_name, str) else None
    if match is None or not _interface_package(match[1]):
        raise ValueError(f'no ROS message type {str(type_name)[:100]!r}')
    try:
        return getattr(importlib.import_module(f'{match[1]}.msg'), match[2])
    except Exception:  # noqa: BLE001 -- whatever a broken package raises, it is no type here
        raise ValueError(f'no ROS message type {type_name!r}') from None


def has_standard():
    """Whether simulation_interfaces is installed (found, not imported)."""
    return _interface_package('simulation_interfaces')


def _interface_package(package):
    """Whether ``package`` is found and has a generated msg/ folder (found, not imported)."""
    try:
        spec = importlib.util.find_spec(package)
    except (ImportError, ValueError):
        return False
    return spec is not None and any((Path(place) / 'msg' / '__init__.py').is_file()
                                    for place in spec.submodule_search_locations or ())


def drive_command(node, robot, linear, angular):
    """control/cmd_vel's TwistStamped: ``linear`` m/s and ``angular`` rad/s in the robot's
    body frame, stamped with node's clock now (simulated time on /clock)."""
    from geometry_msgs.msg import TwistStamped

    msg = TwistStamped()
    msg.header.stamp = node.get_clock().now().to_msg()
    msg.header.frame_id = frame_id(robot, 'base_link')
    msg.twist.linear.x, msg.twist.angular.z = float(linear), float(angular)
    return msg
