"""Keep MiRo's head on the ball as it moves: look_at, fed by what the eyes see.

In each eye frame (sensors/cam{l,r}/compressed) the ball is found as the controller finds
it (its BallDetector), and its pixel becomes the point where that view meets the plane of
the ball's centre, z = --ball-radius, through the eye's camera model from camera_info
(lens included) and the head as it was when the frame was taken (the first
sensors/kinematic_joints stamped at or after the frame). look_at then gives the head joints
that put that point on an eye's optical axis (whichever eye turns the head less), sent on
control/kinematic_joints. When both eyes see the ball, the one that sees it nearer the
middle of its image is believed: there the detector and the lens err least. The wheels
stay still. A ball out of the head's reach is said once, with why, until it comes back.
Try it with the ball mover:

    python -m miro_ball.examples.ball_mover --period 6 --amplitude 0.15 &
    python -m miro_ball.examples.client_look [--ball-radius 0.1] [--duration 0]
"""
import sys

import numpy as np
from sensor_msgs.msg import JointState

from miro_ball.common.jpeg import decode_jpeg, ImageRejected
from miro_ball.common.stamps import seconds
from miro_ball.controller.detection import BallDetector
from miro_ball.examples._client import Client, make_parser, number, run
from miro_ball.miro.constants import JOINT_NAMES
from miro_ball.miro.gaze import look_at
from miro_ball.miro.kc import EYE_FRAMES, KinematicChain



class Look(Client):
    def __init__(self, options, context=None):
        super().__init__('client_look', options, context)
        self.detector = BallDetector()
        self.pending = {}  # eye -> (stamp s, BGR frame) waiting for the joints of its instant
        self.joints = None  # the latest (tilt, lift, yaw, pitch)
        self.start = None
        self.out_of_reach = None  # the reason last said, while the ball is out of reach
        self.head = self.advertise(JointState, self.topics.kinematic_targets)
        self.watch_eyes(self.on_image)
        self.subscribe(JointState, self.topics.kinematic_joints, self.on_joints)

    def on_image(self, eye, msg):
        try:
            self.pending[eye] = (seconds(msg.header.stamp), decode_jpeg(msg.data))
        except ImageRejected as err:
            self.warn(eye, f'{eye}: frame ignored: {err}')

    def on_joints(self, msg):
        joints = self.reading('kinematic_joints', msg)
        if joints is None:
            return
        self.joints = joints
        now = seconds(msg.header.stamp)
        self.start = now if self.start is None else self.start
        if self.options.duration and now - self.start >= self.options.duration:
            self.say(f'done: {self.options.duration:g} s of looking')
            raise SystemExit(0)
        taken = [eye for eye, (stamp, _) in self.pending.items() if stamp <= now]
        # The head as it was when the frames were taken: these joints.
        sightings = [self.sighting(eye, self.pending.pop(eye)[1]) for eye in taken]
        sightings = [s for s in sightings if s is not None]
        if sightings:
            self.look(max(sightings, key=lambda s: s[0])[1])

    def sighting(self, eye, frame):
        """(the cosine of the ball's angle off the eye's axis, where the ball is in FOOT),
        or None when the eye does not see it."""
        camera = self.cameras.get(eye)
        circle = self.detector.find_circle(frame)
        if camera is None or circle is None:
            return None
        height, width = frame.shape[:2]
        if (camera.width, camera.height) != (width, height):
            camera = camera.scaled_to(width, height)
        kc = KinematicChain(self.joints)
        ball = camera.pixel_to_plane(kc, EYE_FRAMES[eye], circle[0], circle[1],
                                     z=self.options.ball_radius)
        if not np.all(np.isfinite(ball)):
            return None  # seen at or above the horizon: no point on the ball's plane
        return float(camera.pixel_to_ray(circle[0], circle[1])[0]), ball

    def look(self, ball):
        kc = KinematicChain(self.joints)
        gaze = look_at(kc, ball)
        msg = JointState(name=list(JOINT_NAMES), position=list(gaze.joints))
        msg.header.stamp = self.get_clock().now().to_msg()
        self.head.publish(msg)
        if gaze.reachable and self.out_of_reach is not None:
            self.say(f'{self.now():7.2f} s  the ball is back within reach')
            self.out_of_reach = None
        elif not gaze.reachable and self.out_of_reach is None:
            self.say(f'{self.now():7.2f} s  the ball at ({ball[0]:.2f}, {ball[1]:.2f}) m is out '
                     f'of reach: {gaze.reason}')
            self.out_of_reach = gaze.reason


def build_parser():
    parser = make_parser('client_look', __doc__)
    parser.add_argument('--ball-radius', type=number(0.0, 1.0), default=0.1,
                        help="the ball's radius: the height of its centre, m (0.1)")
    parser.add_argument('--duration', type=number(0, 1e6), default=0.0,
                        help='stop after this many simulated seconds; 0 = until Ctrl+C (0)')
    return parser


def main(argv=None):
    return run(Look, build_parser(), argv)


if __name__ == '__main__':
    sys.exit(main())
