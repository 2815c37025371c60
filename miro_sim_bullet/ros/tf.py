"""/tf and /tf_static: every frame of every robot, as tf2, RViz and Foxglove read them.

The tree, each robot's frames prefixed with its name (REP 105):

    world -> <robot>/odom -> <robot>/base_link -> <robot>/body -> ... every URDF link

- ``world -> <robot>/odom`` (static): the simulator's odometry is its ground truth, so
  odom coincides with the world;
- ``<robot>/odom -> <robot>/base_link``: the pose of sensors/odom, the same numbers;
- ``<robot>/base_link -> <robot>/body``: the body's exact pose (its tilt, as measured);
- every other movable joint of the URDF from its position in joint_states (the same tick);
- every fixed joint (the LEDs, the eyes and their optical frames, the sonar, the IMUs,
  the microphones, the cliff sensors) on /tf_static, once.

The moving transforms go out each platform tick, only while someone listens. The type,
tf2_msgs/TFMessage, is built at set-up (python -m miro_ball.build_interfaces); without it
the simulator runs without /tf and says so once.
"""
import numpy as np

from miro_ball.common.messages import message_class
from miro_ball.common.qos import profile
from miro_ball.miro.body import LINK_OF_JOINT, MOVABLE
from miro_ball.miro.interface import frame_id, TF, TF_QOS, TF_STATIC, TF_STATIC_QOS, TF_TYPE, \
    WORLD_FRAME
from miro_ball.miro.link_poses import fixed_transforms, JOINTED, jointed_poses
from miro_ball.miro.rotations import axis_angle_quaternion
from miro_sim_bullet.ros import convert
from miro_sim_bullet.ros.refill import Refill

_BODY = LINK_OF_JOINT['tilt']  # its exact pose, not the tilt alone (a slope rolls it too)
# Where each JOINTED link's joint is in Sensors.joint_positions.
_JOINT_INDEX = np.array([MOVABLE.index(link.joint) for link in JOINTED])


def static_transforms(robots, when):
    """The TransformStampeds of /tf_static for the robots named."""
    out = []
    for name in robots:
        out.append(convert.transform(WORLD_FRAME, frame_id(name, 'odom'), (0.0, 0.0, 0.0),
                                     (0.0, 0.0, 0.0, 1.0), when))
        out += [convert.transform(frame_id(name, parent), frame_id(name, child), xyz, turn,
                                  when) for parent, child, xyz, turn in fixed_transforms()]
    return out


def robot_pairs(name):
    """[(parent, child)] of one robot's moving frames, in robot_poses' order."""
    return [(frame_id(name, 'odom'), frame_id(name, 'base_link')),
            (frame_id(name, _BODY.parent), frame_id(name, _BODY.name))] + [
        (frame_id(name, link.parent), frame_id(name, link.name)) for link in JOINTED]


def robot_poses(sensors):
    """(robots, frames, 7): xyz and quaternion of the moving frames of every robot (each
    robot's Sensors of its tick, in robot_pairs' order)."""
    poses = np.empty((len(sensors), 2 + len(JOINTED), 7))
    poses[:, 2:] = jointed_poses(np.array([s.joint_positions for s in sensors])[:, _JOINT_INDEX])
    for pose, s in zip(poses, sensors):
        x, y, yaw = s.pose
        pose[0] = (x, y, 0.0, *axis_angle_quaternion((0.0, 0.0, 1.0), yaw))
        pose[1, :3], pose[1, 3:] = s.body_in_base
    return poses


class TfInterface:
    """The simulator's /tf and /tf_static for every robot of world (a SimWorld).

    ValueError when tf2_msgs is not installed."""

    def __init__(self, ros, world, when):
        self.world = world
        self.message = message_class(TF_TYPE)
        self.pub = ros.publisher(self.message, TF, profile(TF_QOS))
        self.pub_static = ros.publisher(self.message, TF_STATIC, profile(TF_STATIC_QOS))
        # Published once, kept for late subscribers (transient local).
        self.pub_static.publish(self.message(transforms=static_transforms(world.robots, when)))
        pairs = [pair for name in world.robots for pair in robot_pairs(name)]
        self._refill = Refill(lambda stamp, values: self.message(transforms=[
            convert.transform(parent, child, values[7 * k:7 * k + 3],
                              values[7 * k + 3:7 * k + 7], stamp)
            for k, (parent, child) in enumerate(pairs)]), 7 * len(pairs))

    def publish(self, when):
        """Every robot's moving frames now, in one message (only while listened to)."""
        if self.pub.get_subscription_count():
            self.pub.publish(self._refill.fill(when, robot_poses(
                [robot.sensors for robot in self.world.robots.values()]).ravel()))
