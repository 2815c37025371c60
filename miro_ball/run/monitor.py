"""An observer of a run over ROS: simulated time, the ball, the robots, the controllers.

It only subscribes (to /clock, the simulator's ground truth, its touches and the
controllers' annotated frames), so it can watch any run: the lab run's, a user's. What
happened is the one judge's to say (run/judge.py): Monitor.judge. Image callbacks are
optional; they get each frame decoded to BGR.
"""
from miro_ball.common.clock_guard import guard_clock
from miro_ball.common.jpeg import decode_jpeg, ImageRejected
from miro_ball.common.stamps import seconds
from miro_ball.common.throttle import Throttled
from miro_ball.controller.names import debug_topic
from miro_ball.miro.interface import CLOCK, CLOCK_QOS, EYE_QOS, EYES, SimTopics, TRUTH_QOS
from miro_ball.run.judge import Judge



def decode(msg):
    """BGR image of a CompressedImage, or None if it is not a sane JPEG."""
    try:
        return decode_jpeg(msg.data)
    except ImageRejected:
        return None


# Every overhead image is a video frame: a second's worth is queued, so an observer busy
# with a run's eyes at its start loses none (with the newest only, the first was lost 1 run
# in 8 on the football pitch).
OVERHEAD_QUEUE = 10


def unmatched(subscriptions):
    """Topics of those subscriptions that no publisher has matched yet."""
    return [sub.topic_name for sub in subscriptions if sub.get_publisher_count() == 0]


class RobotWatch:
    """What the monitor saw of one robot (its judging is the judge's)."""

    def __init__(self):
        self.frames = 0  # annotated frames its controller published
        self.position = None  # x, y, z of the point under its axle, the latest seen
        self.stamp = None  # simulated s of the latest position


class Monitor:
    """Subscribes on ``node`` for the given robot names and feeds what the simulator says to
    ``judge`` (run/judge.py), which judges from the first simulated time it hears of, or from
    restart().

    truth, debug, overhead: its subscriptions to the simulator (/clock and the ground
    truth), to the controllers' annotated frames and to the overhead view, for asking
    whether they are matched (``unmatched``) before a run starts.
    """

    def __init__(self, node, robots, on_eye=None, on_overhead=None, debug_frames=True):
        """debug_frames=False: leave the controllers' annotated frames alone (a controller
        draws them only while someone subscribes). on_overhead(bgr, stamp s)."""
        from geometry_msgs.msg import PointStamped, PoseStamped
        from rosgraph_msgs.msg import Clock
        from sensor_msgs.msg import CompressedImage

        from miro_ball.common.qos import profile

        self.sim_time = 0.0
        self.ball = None  # x, y of the latest seen
        self.ball_stamp = None
        self.judge = Judge()
        self.robots = {name: RobotWatch() for name in robots}
        sim = SimTopics()
        # The node is on sim time: a negative /clock from anyone must not end it.
        guard_clock(node, Throttled(node.get_logger().warning))
        self.truth = [
            node.create_subscription(Clock, CLOCK, self._on_clock, profile(CLOCK_QOS)),
            node.create_subscription(PointStamped, sim.ball, self._on_ball, profile(TRUTH_QOS)),
            node.create_subscription(PointStamped, sim.touches, self._on_touch,
                                     TRUTH_QOS.depth * len(robots))]
        self.truth += [node.create_subscription(PoseStamped, sim.object_pose(name),
                                                lambda msg, n=name: self._on_robot(n, msg),
                                                profile(TRUTH_QOS))
                       for name in robots]
        self.debug = [
            node.create_subscription(
                CompressedImage, debug_topic(name, eye),
                lambda msg, n=name, i=index, s=side: self._on_debug(n, i, s, msg, on_eye),
                profile(EYE_QOS))
            for index, name in enumerate(robots) if debug_frames
            for side, eye in enumerate(EYES)]
        self.overhead = None if on_overhead is None else node.create_subscription(
            CompressedImage, sim.overhead, lambda msg: self._on_overhead(msg, on_overhead),
            OVERHEAD_QUEUE)

    def restart(self, t=None):
        """Judge from simulated time t (s) on; None: from the latest /clock."""
        self.judge.start(self.sim_time if t is None else t)

    @property
    def frames(self):
        """Annotated frames of all controllers so far."""
        return sum(watch.frames for watch in self.robots.values())

    def caught_up(self, now):
        """Whether what the simulator published for simulated time ``now`` (s) is in: /clock,
        the ball and every robot."""
        stamps = [self.sim_time, self.ball_stamp] + [w.stamp for w in self.robots.values()]
        return all(stamp is not None and stamp >= now - 1e-9 for stamp in stamps)

    def _on_clock(self, msg):
        self.sim_time = seconds(msg.clock)
        self.judge.clock(self.sim_time)

    def _on_ball(self, msg):
        self.ball = (msg.point.x, msg.point.y)
        self.ball_stamp = seconds(msg.header.stamp)
        self.judge.ball(self.ball_stamp, self.ball)

    def _on_touch(self, msg):
        if msg.header.frame_id in self.robots:
            self.judge.touch(msg.header.frame_id, seconds(msg.header.stamp),
                             (msg.point.x, msg.point.y))

    def _on_robot(self, name, msg):
        watch = self.robots[name]
        p = msg.pose.position
        watch.position = (p.x, p.y, p.z)
        watch.stamp = seconds(msg.header.stamp)
        self.judge.robot(name, watch.stamp, watch.position)

    def _on_debug(self, name, index, side, msg, on_eye):
        self.robots[name].frames += 1
        if on_eye is not None:
            bgr = decode(msg)
            if bgr is not None:
                on_eye(index, side, bgr)

    @staticmethod
    def _on_overhead(msg, on_overhead):
        bgr = decode(msg)
        if bgr is not None:
            on_overhead(bgr, seconds(msg.header.stamp))
