"""ROS time stamps as seconds."""


def seconds(stamp):
    """A builtin_interfaces Time (a header's stamp, /clock's clock) as float seconds."""
    return stamp.sec + stamp.nanosec * 1e-9
