"""An observer of a run over ROS: simulated time, the ball, the robots, the controllers.

It only subscribes (to /clock, the simulator's ground truth and the controllers'
annotated frames), so it can watch any run: the demo's, a grader's, a user's.
Times are simulated seconds, the kick's from the stamp of the ball reading that
showed it. Image callbacks are optional; they get each frame decoded to BGR.
"""
from miro_ball.common.clock_guard import guard_clock
from miro_ball.common.jpeg import decode_jpeg, ImageRejected
from miro_ball.common.stamps import seconds
from miro_ball.common.throttle import Throttled
from miro_ball.controller.names import debug_topic
from miro_ball.miro.constants import WHEEL_RADIUS_M
from miro_ball.miro.interface import CLOCK, CLOCK_QOS, EYE_QOS, EYES, SimTopics
from miro_ball.run.judge import FELL_BELOW_M, KICK_DISTANCE_M, ball_moved

TRUTH_DEPTH = 10  # the simulator's ground truth topics keep ROS's default depth


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
    """What the monitor knows about one robot."""

    def __init__(self):
        self.frames = 0  # annotated frames its controller published
        self.start_z = None  # floor height when first seen
        self.start = None  # x, y, z when first seen
        self.position = None  # x, y, z of the point under its axle
        self.stamp = None  # simulated s of the latest position
        self.fell = False
        self.distance = 0.0  # m driven over the floor since the start


class Monitor:
    """Subscribes on ``node`` for the given robot names.

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
        self.ball_start = None
        self.ball = None
        self.ball_stamp = None
        self.kick_time = None
        self.kicker = None  # the robot nearest the ball when it was kicked
        self.robots = {name: RobotWatch() for name in robots}
        sim = SimTopics()
        # The node is on sim time: a negative /clock from anyone must not end it.
        guard_clock(node, Throttled(node.get_logger().warning))
        self.truth = [
            node.create_subscription(Clock, CLOCK, self._on_clock, profile(CLOCK_QOS)),
            node.create_subscription(PointStamped, sim.ball, self._on_ball, TRUTH_DEPTH)]
        self.truth += [node.create_subscription(PoseStamped, sim.object_pose(name),
                                                lambda msg, n=name: self._on_robot(n, msg),
                                                TRUTH_DEPTH)
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

    def restart(self):
        """Judge from here on: the ball's and the robots' next positions are the start."""
        self.ball_start = self.ball = self.kick_time = self.kicker = None
        for watch in self.robots.values():
            watch.start_z = watch.start = None
            watch.fell, watch.distance = False, 0.0

    @property
    def kicked(self):
        return self.kick_time is not None

    @property
    def moved(self):
        """How far the ball is from where it was first seen (m)."""
        return 0.0 if self.ball is None else ball_moved(self.ball_start, self.ball)

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

    def _on_ball(self, msg):
        self.ball = (msg.point.x, msg.point.y)
        self.ball_stamp = seconds(msg.header.stamp)
        self.ball_start = self.ball_start or self.ball
        if not self.kicked and self.moved >= KICK_DISTANCE_M:
            self.kick_time = self.ball_stamp
            self.kicker = self._nearest_robot(self.ball)

    def _nearest_robot(self, point):
        placed = [(ball_moved(point, w.position), name)
                  for name, w in self.robots.items() if w.position is not None]
        return min(placed)[1] if placed else None

    def _on_robot(self, name, msg):
        watch = self.robots[name]
        p = msg.pose.position
        if watch.position is not None and watch.start_z is not None:
            watch.distance += ball_moved(watch.position, (p.x, p.y))
        watch.position = (p.x, p.y, p.z)
        watch.stamp = seconds(msg.header.stamp)
        if watch.start_z is None:
            watch.start_z, watch.start = p.z, watch.position
        # The pose is of the point under the axle: the axle is WHEEL_RADIUS_M above it.
        watch.fell = watch.fell or p.z + WHEEL_RADIUS_M - watch.start_z < FELL_BELOW_M

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
