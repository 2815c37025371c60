"""ROS message classes from the type names of the interface table ('sensor_msgs/msg/Range')."""
import importlib

from miro_ball.miro.interface import frame_id


def message_class(type_name):
    """The Python class of a message type 'package/msg/Name'; ValueError if there is none."""
    try:
        package, kind, name = type_name.split('/')
        return getattr(importlib.import_module(f'{package}.{kind}'), name)
    except (ValueError, ImportError, AttributeError):
        raise ValueError(f'no ROS message type {type_name!r}') from None


def drive_command(node, robot, linear, angular):
    """control/cmd_vel's TwistStamped: ``linear`` m/s and ``angular`` rad/s in the robot's
    body frame, stamped with node's clock now (simulated time on /clock)."""
    from geometry_msgs.msg import TwistStamped

    msg = TwistStamped()
    msg.header.stamp = node.get_clock().now().to_msg()
    msg.header.frame_id = frame_id(robot, 'base_link')
    msg.twist.linear.x, msg.twist.angular.z = float(linear), float(angular)
    return msg
