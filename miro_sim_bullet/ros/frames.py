"""Where each robot's link frames are: /miro_sim/links/<robot>, a PoseArray in frame world.

A robot's scene markers hang in its link frames (``<robot>/body``, ``<robot>/head``, ...;
constants.LINK_FRAMES); this stream moves them. It is what /tf would carry (tf2_msgs is
not among the ROS packages this project installs from the package index), in one message
per robot and instant: about 1 KB, 30 KB/s at the scene's 30 Hz, where the same motion as
world-frame markers would cost six times as much.
"""
import numpy as np
from geometry_msgs.msg import Pose, PoseArray

from miro_ball.miro.interface import EYE_SIDE, EYES, WORLD_FRAME
from miro_ball.miro.kc import camera_in_head
from miro_ball.miro.rotations import matrix_quaternions
from miro_sim_bullet.physics import model as rb
from miro_sim_bullet.bullet import pybullet as pb

# The optical convention (REP 103): z along the optical axis, x right, y down; the
# camera's own frame has x along the axis, y left, z up.
_OPTICAL_IN_CAMERA = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])


def quaternion(rotation):
    """(x, y, z, w) of one 3x3 rotation matrix, w >= 0."""
    return tuple(matrix_quaternions(rotation)[0].tolist())


_EYES_IN_HEAD = [(tuple(position), quaternion(rotation @ _OPTICAL_IN_CAMERA))
                 for position, rotation in (camera_in_head(EYE_SIDE[eye]) for eye in EYES)]


class RobotLinks:
    """The link frames of one robot of a built SimWorld (make anew after a reset)."""

    def __init__(self, world, name):
        self.client, self.body = world.client, world.robots[name].body_id
        kw = {'physicsClientId': self.client}
        self.links = pb.getNumJoints(self.body, **kw)
        # PyBullet reports the base by its centre of mass: this takes it to the link frame.
        info = pb.getDynamicsInfo(self.body, -1, **kw)
        self.com_to_link = pb.invertTransform(info[3], info[4])
        # One message, filled in anew each time: making 20 poses costs more than the rest.
        self.msg = PoseArray(poses=[Pose() for _ in range(self.links + 1 + len(EYES))])
        self.msg.header.frame_id = WORLD_FRAME

    def frames(self):
        """[(position, quaternion xyzw)] in the world of the frames of LINK_FRAMES, now
        (PyBullet's own quaternions, composed in C: this runs 30 times a simulated second)."""
        kw = {'physicsClientId': self.client}
        com = pb.getBasePositionAndOrientation(self.body, **kw)
        frames = [pb.multiplyTransforms(*com, *self.com_to_link)]
        states = pb.getLinkStates(self.body, range(self.links), computeForwardKinematics=1,
                                  **kw)
        frames += [(s[4], s[5]) for s in states]
        head = frames[rb.HEAD + 1]
        frames += [pb.multiplyTransforms(*head, *eye) for eye in _EYES_IN_HEAD]
        return frames

    def message(self, when):
        """The PoseArray of this instant, stamped when (the same object each call)."""
        for pose, ((x, y, z), (qx, qy, qz, qw)) in zip(self.msg.poses, self.frames()):
            p, o = pose.position, pose.orientation
            p.x, p.y, p.z, o.x, o.y, o.z, o.w = x, y, z, qx, qy, qz, qw
        self.msg.header.stamp = when
        return self.msg
