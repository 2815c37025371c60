"""A top-down map of the floor around MiRo, painted from both eyes as it moves.

Like the MDK's client_map. Each eye frame (sensors/cam{l,r}/compressed) is paired
with MiRo's pose (sensors/odom) and head joints (sensors/kinematic_joints) of its
instant, interpolated between the samples either side of its stamp, and painted
onto a grid on the floor through that eye's camera model from camera_info, lens
included (miro_ball/mapping/floor_map.py says how). The map is centred where
MiRo stands at its first odometry, in the odometry frame: x to the right, y up.

It is published on ~/map (sensor_msgs/Image rgb8, frame <robot>/odom) twice a
simulated second and written to --out (PNG) every 2 s and on exit. Unseen cells
are grey; what stands up (the ball, the walls) lies on the floor behind where it
stands, as the eye sees it. --spin turns MiRo on the spot so that it maps all
around (at 0.5 rad/s a full turn takes 13 s).

    python -m miro_ball.examples.client_map [--size 3.0] [--resolution 0.01] [--spin 0.5]
"""
import bisect
import math
import os
import sys
from pathlib import Path

import cv2
import numpy as np
from geometry_msgs.msg import TwistStamped
from nav_msgs.msg import Odometry
from sensor_msgs.msg import Image, JointState

from miro_ball.common.jpeg import decode_jpeg, ImageRejected
from miro_ball.common.stamps import seconds
from miro_ball.examples._client import Client, heading, make_parser, number, run
from miro_ball.mapping.floor_map import FloorMap, MAX_RANGE_M
from miro_ball.miro.interface import EYE_QOS, frame_id
from miro_ball.miro.kc import EYE_FRAMES, KinematicChain
from miro_ball.miro.checks import finite
from miro_ball.miro.kinematics import wrap

TICK = 0.02  # s: MiRo's 50 Hz platform tick, the rate of the spin command
PUBLISH_PERIOD_S = 0.5  # simulated s between maps on ~/map
WRITE_EVERY = 4  # published maps between writes of --out (every 2 s)
HISTORY_S = 1.0  # simulated s of poses and joints kept to pair frames with
MAX_PENDING = 8  # frames waiting for the pose after them (~0.25 s of both eyes)
# Frames in a row that can not be painted before a warning: at the start the first
# frames come before the first pose, joints or camera_info (published after its frame).
PATIENCE = 15
MAX_ODOM_M = 1e5  # odometry beyond this is nonsense (and would put the map out of reach)


class Track:
    """The last ``span_s`` seconds of a stamped vector (pose, joints) and its value at
    any instant between two samples, linearly interpolated (``angles``: the indices that
    are angles, interpolated the short way round)."""

    def __init__(self, span_s, angles=()):
        self.span_s = span_s
        self.angles = angles
        self.times, self.values = [], []

    def add(self, t, values):
        if self.times and t < self.times[-1]:  # time went back: the world was reset
            self.times, self.values = [], []
        self.times.append(t)
        self.values.append(np.asarray(values, float))
        while self.times[0] < t - self.span_s:
            del self.times[0], self.values[0]

    @property
    def newest(self):
        return self.times[-1] if self.times else -math.inf

    def at(self, t):
        """The value at instant t, or None when t is not between the first and the last
        sample."""
        if not self.times or not self.times[0] <= t <= self.times[-1]:
            return None
        after = bisect.bisect_left(self.times, t)
        if self.times[after] == t:
            return self.values[after]
        t0, t1 = self.times[after - 1], self.times[after]
        a, b = self.values[after - 1], self.values[after]
        step = b - a
        for i in self.angles:
            step[i] = wrap(step[i])
        return a + step * (t - t0) / (t1 - t0)


class Mapper(Client):
    def __init__(self, options, context=None):
        super().__init__('client_map', options, context)
        self.out = Path(options.out)
        if self.out.suffix.lower() != '.png':
            raise ValueError(f'--out {options.out}: the map is written as PNG, name a .png')
        if not self.out.parent.is_dir():
            raise ValueError(f'--out {options.out}: no folder {self.out.parent}')
        FloorMap(options.size, options.resolution, max_range_m=options.range)  # checks them
        self.map = None  # a FloorMap, centred where the first odometry puts MiRo
        self.kc = KinematicChain()
        self.poses = Track(HISTORY_S, angles=(2,))  # x, y, heading
        self.joints = Track(HISTORY_S)  # tilt, lift, yaw, pitch
        self.pending = []  # (stamp s, eye, RGB image) waiting for the pose after them
        self.skipped = 0  # frames in a row that could not be painted
        self.published = 0
        self.watch_eyes(self.on_image)
        self.subscribe(Odometry, self.topics.odom, self.on_odom)
        self.subscribe(JointState, self.topics.kinematic_joints, self.on_joints)
        # The map is an image, so the eyes' profile: a late subscriber wants the newest.
        self.pub_map = self.advertise(Image, '~/map', EYE_QOS)
        self.create_timer(PUBLISH_PERIOD_S, self.publish)
        self.cmd_vel = None
        if options.spin:
            self.cmd_vel = self.advertise(TwistStamped, self.topics.cmd_vel)
            self.create_timer(TICK, lambda: self.cmd_vel.publish(self.twist(0.0, options.spin)))

    # -- what comes in ------------------------------------------------------------------------
    def on_image(self, eye, msg):
        try:
            bgr = decode_jpeg(msg.data)
        except ImageRejected as err:
            self.warn(eye, f'{eye}: frame ignored: {err}')
            return
        self.pending.append((seconds(msg.header.stamp), eye, cv2.cvtColor(bgr,
                                                                          cv2.COLOR_BGR2RGB)))
        if len(self.pending) > MAX_PENDING:
            self.skip(self.pending.pop(0)[1], 'no pose and joints after it')
        self.paint_ready()

    def on_odom(self, msg):
        p = msg.pose.pose.position
        pose = (p.x, p.y, heading(msg.pose.pose.orientation))
        if not (finite(*pose) and max(map(abs, pose)) < MAX_ODOM_M):
            self.warn('odom', f'{self.topics.odom} ignored: pose {pose} is not a place')
            return
        if self.map is None:
            self.map = FloorMap(self.options.size, self.options.resolution, pose[:2],
                                self.options.range)
            self.say(f'mapping {self.map.size:g} m x {self.map.size:g} m at '
                     f'{self.map.resolution:g} m a cell ({self.map.cells} x {self.map.cells}) '
                     f'around ({pose[0]:.2f}, {pose[1]:.2f}) of {frame_id(self.robot, "odom")}'
                     f', x right, y up; eyes seen up to {self.map.max_range:g} m')
        self.poses.add(seconds(msg.header.stamp), pose)
        self.paint_ready()

    def on_joints(self, msg):
        joints = self.reading('kinematic_joints', msg)
        if joints is None:
            return
        self.joints.add(seconds(msg.header.stamp), joints)
        self.paint_ready()

    # -- painting -----------------------------------------------------------------------------
    def paint_ready(self):
        """Paint the frames whose instant both the pose and the joints have passed."""
        known = min(self.poses.newest, self.joints.newest)
        waiting = []
        for frame in self.pending:
            if frame[0] <= known:
                self.paint(*frame)
            elif frame[0] <= known + HISTORY_S:
                waiting.append(frame)
            else:  # no pose or joints yet, or a frame from before a reset of the world
                self.skip(frame[1], 'no pose and joints of its instant')
        self.pending = waiting

    def skip(self, eye, why):
        """A frame that can not be painted: said when it goes on for a while."""
        self.skipped += 1
        if self.skipped > PATIENCE:
            self.warn(why, f'{eye}: frames ignored: {why} ({self.topics.odom}, '
                           f'{self.topics.kinematic_joints}, {self.topics.camera_info(eye)})')

    def paint(self, t, eye, rgb):
        camera, pose, joints = self.cameras.get(eye), self.poses.at(t), self.joints.at(t)
        if camera is None:
            self.skip(eye, 'no camera_info yet')
            return
        if pose is None or joints is None:
            self.skip(eye, 'no pose and joints of its instant')
            return
        self.skipped = 0
        self.kc.set_joints(*joints)
        self.kc.set_pose(*pose)
        try:
            self.map.add_view(rgb, camera, self.kc, EYE_FRAMES[eye])
        except ValueError as err:  # a frame of another size than camera_info's
            self.warn(f'{eye}_size', f'{eye}: frame ignored: {err}')

    # -- what goes out ------------------------------------------------------------------------
    def publish(self):
        if self.map is None:
            return
        image = self.map.image()
        msg = Image(height=image.shape[0], width=image.shape[1], encoding='rgb8',
                    step=image.shape[1] * 3, data=image.tobytes())
        msg.header.stamp = self.get_clock().now().to_msg()
        msg.header.frame_id = frame_id(self.robot, 'odom')
        self.pub_map.publish(msg)
        self.published += 1
        if self.published % WRITE_EVERY == 0:
            self.write(image)

    def write(self, image):
        # Written aside, then renamed: a viewer never reads a half-written file.
        aside = self.out.with_name('.' + self.out.name)
        cv2.imwrite(str(aside), cv2.cvtColor(image, cv2.COLOR_RGB2BGR))
        os.replace(aside, self.out)
        seen = self.map.seen().mean()
        self.say(f'{self.now():7.2f} s  {self.map.views} views, {seen:.0%} of the map seen, '
                 f'written to {self.out}')

    def stop(self):
        if self.cmd_vel is not None:
            self.cmd_vel.publish(self.twist(0.0, 0.0))
        if self.map is not None:
            self.write(self.map.image())


def build_parser():
    parser = make_parser('client_map', __doc__)
    parser.add_argument('--size', type=number(0.1, 100.0), default=3.0,
                        help='side of the square map, m (3.0)')
    parser.add_argument('--resolution', type=number(0.001, 1.0), default=0.01,
                        help='side of a map cell, m (0.01); at most 4000 cells a side')
    parser.add_argument('--range', type=number(0.1, 10.0), default=MAX_RANGE_M,
                        help=f'paint floor up to this far from each eye, m ({MAX_RANGE_M:g})')
    parser.add_argument('--out', default='map.png', metavar='FILE.png',
                        help='where to write the map, PNG (map.png)')
    parser.add_argument('--spin', type=number(-2.0, 2.0), default=0.0, metavar='RATE',
                        help='turn on the spot at this rate, rad/s, + = left; 0 = do not '
                             'drive (0)')
    return parser


def main(argv=None):
    return run(Mapper, build_parser(), argv)


if __name__ == '__main__':
    sys.exit(main())
