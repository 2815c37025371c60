"""ROS message classes from the type names of the interface table ('sensor_msgs/msg/Range')."""
import importlib


def message_class(type_name):
    """The Python class of a message type 'package/msg/Name'; ValueError if there is none."""
    try:
        package, kind, name = type_name.split('/')
        return getattr(importlib.import_module(f'{package}.{kind}'), name)
    except (ValueError, ImportError, AttributeError):
        raise ValueError(f'no ROS message type {type_name!r}') from None
