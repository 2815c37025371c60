"""/tf and /tf_static: where each robot is, as tf2, RViz and Foxglove read it.

The tree: ``world`` -> ``<robot>/odom`` (static: the simulator's odometry is its ground
truth, so odom coincides with the world) -> ``<robot>/base_link`` (moving, the pose that
sensors/odom gives, published with it each platform tick). The type, tf2_msgs/TFMessage,
is built at set-up (python -m miro_ball.build_interfaces); without it the simulator runs
without /tf and says so once.
"""
from miro_ball.common.messages import message_class
from miro_ball.common.qos import profile
from miro_ball.miro.interface import frame_id, TF, TF_QOS, TF_STATIC, TF_STATIC_QOS, TF_TYPE, \
    WORLD_FRAME
from miro_sim_bullet.ros import convert


class TfInterface:
    """The simulator's /tf and /tf_static for every robot of world (a SimWorld).

    ValueError when tf2_msgs is not installed."""

    def __init__(self, ros, world, when):
        self.world = world
        self.message = message_class(TF_TYPE)
        self.pub = ros.publisher(self.message, TF, profile(TF_QOS))
        self.pub_static = ros.publisher(self.message, TF_STATIC, profile(TF_STATIC_QOS))
        # Published once, kept for late subscribers (transient local).
        self.pub_static.publish(self.message(transforms=[
            convert.transform(WORLD_FRAME, frame_id(name, 'odom'), (0.0, 0.0, 0.0),
                              (0.0, 0.0, 0.0, 1.0), when)
            for name in world.robots]))

    def publish(self, when):
        """Every robot's odom -> base_link now, in one message (only while listened to)."""
        if self.pub.get_subscription_count():
            self.pub.publish(self.message(transforms=[
                convert.odom_transform(robot.sensors, when, name)
                for name, robot in self.world.robots.items()]))
