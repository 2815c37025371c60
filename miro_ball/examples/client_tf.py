"""Where is the ball, as MiRo's head sees it? The frames of /tf, the ROS 2 way.

The simulator puts every part of every MiRo on /tf and /tf_static (world -> <robot>/odom
-> <robot>/base_link -> body -> neck -> gimbal -> head -> caml, camr, ...) and gives the
ball's ground truth in frame world (/miro_sim/ball). This client keeps the newest of
every frame (miro_ball.miro.tf_tree, what tf2's buffer does) and, every --every simulated
seconds, takes the ball's centre into MiRo's head frame (x forward, y left, z up) and
prints it with its distance and bearing: the MDK's kinematic-chain examples, done with
the frames any ROS tool reads. Move the head (client_look) or the ball (the GUI) and
watch the numbers change.

    python -m miro_ball.examples.client_tf [--frame head] [--count 3] [--every 1.0]

It needs tf2_msgs, which ./dev.sh setup builds (or python -m miro_ball.build_interfaces).
"""
import math
import sys

from geometry_msgs.msg import PointStamped

from miro_ball.common.messages import message_class
from miro_ball.common.qos import profile
from miro_ball.examples._client import Client, make_parser, Periodic, periodic_options, \
    require_type, run
from miro_ball.miro.body import LINK, ROOT
from miro_ball.miro.interface import frame_id, SimTopics, TF, TF_QOS, TF_STATIC, \
    TF_STATIC_QOS, TF_TYPE
from miro_ball.miro.tf_tree import TfError, TfTree

# Simulated seconds (of the ball's stamps) the frames have to arrive before a frame missing
# is said: the ball comes first, /tf and /tf_static only once their subscriptions match.
FRAMES_WAIT_S = 2.0


class WhereIsTheBall(Client):
    def __init__(self, options, context=None):
        super().__init__('client_tf', options, context)
        self.tree = TfTree()
        self.frame = frame_id(self.robot, options.frame)
        self.heard = set()  # of TF and TF_STATIC
        self.first_ball = None  # the first ball message's stamp, s
        tf_type = message_class(TF_TYPE)
        self.create_subscription(tf_type, TF, lambda msg: self.on_tf(msg, TF), profile(TF_QOS))
        self.create_subscription(tf_type, TF_STATIC, lambda msg: self.on_tf(msg, TF_STATIC),
                                 profile(TF_STATIC_QOS))
        self.subscribe(PointStamped, SimTopics().ball, self.on_ball)
        self.periodic = Periodic(options)

    def on_tf(self, msg, topic=TF):
        self.heard.add(topic)
        for reason in self.tree.set_message(msg.transforms):
            self.warn('tf', f'a transform ignored: {reason}')

    def on_ball(self, msg):
        stamp = msg.header.stamp
        if not self.periodic.due(stamp):
            return
        p = msg.point
        try:
            x, y, z = self.tree.transform_point(self.frame, msg.header.frame_id,
                                                (p.x, p.y, p.z))
        except (TfError, ValueError) as err:
            self._missing(stamp.sec + stamp.nanosec * 1e-9, err)
            return
        distance = math.sqrt(x * x + y * y + z * z)
        self.say(f't = {stamp.sec + stamp.nanosec * 1e-9:.2f} s: ball in {self.frame}: x {x:+.3f} y {y:+.3f} z {z:+.3f} m, '
                 f'{distance:.3f} m away, azimuth {math.degrees(math.atan2(y, x)):+.1f} deg, '
                 f'elevation {math.degrees(math.atan2(z, math.hypot(x, y))):+.1f} deg')
        self.periodic.done(stamp)

    def _missing(self, now, err):
        """Say a failed lookup, unless /tf or /tf_static may still be on its way."""
        if self.first_ball is None:
            self.first_ball = now
        unheard = [topic for topic in (TF, TF_STATIC) if topic not in self.heard]
        if unheard and now - self.first_ball < FRAMES_WAIT_S:
            return
        self.warn('lookup', f'the ball not taken into {self.frame} yet: {err}' + (
            f' (nothing on {" or ".join(unheard)} after {FRAMES_WAIT_S:g} s)' if unheard else ''))


def build_parser():
    parser = make_parser('client_tf', __doc__)
    frames = sorted({ROOT, *LINK})
    parser.add_argument('--frame', default='head', choices=frames, metavar='FRAME',
                        help='the robot\'s frame to see the ball from (head); one of '
                             + ', '.join(frames))
    periodic_options(parser, 'lines')
    return parser


def main(argv=None):
    parser = build_parser()
    require_type(parser, TF_TYPE)
    return run(WhereIsTheBall, parser, argv)


if __name__ == '__main__':
    sys.exit(main())
