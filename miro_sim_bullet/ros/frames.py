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
from miro_sim_bullet.physics import model as rb
from miro_sim_bullet.render.visuals import BodyVisuals

# The optical convention (REP 103): z along the optical axis, x right, y down; the
# camera's own frame has x along the axis, y left, z up.
_OPTICAL_IN_CAMERA = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])
_EYES_IN_HEAD = [(position, rotation @ _OPTICAL_IN_CAMERA)
                 for position, rotation in (camera_in_head(EYE_SIDE[eye]) for eye in EYES)]


def quaternion(rotation):
    """(x, y, z, w) of a 3x3 rotation matrix, w >= 0."""
    m = np.asarray(rotation, float)
    w = np.sqrt(max(0.0, 1.0 + m[0, 0] + m[1, 1] + m[2, 2])) / 2
    x = np.sqrt(max(0.0, 1.0 + m[0, 0] - m[1, 1] - m[2, 2])) / 2
    y = np.sqrt(max(0.0, 1.0 - m[0, 0] + m[1, 1] - m[2, 2])) / 2
    z = np.sqrt(max(0.0, 1.0 - m[0, 0] - m[1, 1] + m[2, 2])) / 2
    x = np.copysign(x, m[2, 1] - m[1, 2])
    y = np.copysign(y, m[0, 2] - m[2, 0])
    z = np.copysign(z, m[1, 0] - m[0, 1])
    norm = np.sqrt(w * w + x * x + y * y + z * z)
    return tuple(float(v / norm) for v in (x, y, z, w))


def pose(rotation, position):
    msg = Pose()
    msg.position.x, msg.position.y, msg.position.z = (float(v) for v in position)
    o = msg.orientation
    o.x, o.y, o.z, o.w = quaternion(rotation)
    return msg


class RobotLinks:
    """The link frames of one robot of a built SimWorld (make anew after a reset)."""

    def __init__(self, world, name):
        self.visuals = BodyVisuals(world.client, world.robots[name].body_id)

    def frames(self):
        """[(rotation, position)] in the world of every frame of LINK_FRAMES, now."""
        positions, rotations = self.visuals.link_frames()
        head_pos, head_rot = positions[rb.HEAD + 1], rotations[rb.HEAD + 1]
        eyes = [(head_rot @ rotation, head_pos + head_rot @ position)
                for position, rotation in _EYES_IN_HEAD]
        return list(zip(rotations, positions)) + eyes

    def message(self, when):
        msg = PoseArray(poses=[pose(r, p) for r, p in self.frames()])
        msg.header.stamp, msg.header.frame_id = when, WORLD_FRAME
        return msg
