"""The referee of a run: a node on the run's ROS domain that watches it (Monitor), puts
robot and ball where an episode wants them, and starts the simulator's clock only once
everyone who must see the run from its first instant is there.

The simulator of a run starts paused. Free-running, it was seconds into the run
before a slow controller or the observer had matched its topics: the observer
reported 0.0 s simulated while the robots were already at the ball.
"""
import time
from contextlib import contextmanager

from miro_ball.controller.names import NODE_NAME as CONTROLLER
from miro_ball.miro.interface import BALL_NAME, EYES, RobotTopics, SimTopics
from miro_ball.miro.rotations import yaw_quaternion
from miro_ball.run.monitor import Monitor, unmatched

SERVICE_TIMEOUT_S = 10.0
PLACED_WITHIN_M = 0.02  # ground truth this close to the placement: it took
PLACE_TRIES = 20


class RunError(RuntimeError):
    """A run that can not go on (the simulator did not answer or took no placement, a node
    exited before the start); the message says why, in one line."""


@contextmanager
def ros_domain(domain):
    """An initialised rclpy Context on ROS domain ``domain``, shut down at the end."""
    import rclpy
    from rclpy.context import Context

    context = Context()
    rclpy.init(context=context, domain_id=domain)
    try:
        yield context
    finally:
        rclpy.try_shutdown(context=context)


def set_pose_request(name, position, yaw=0.0):
    """A set_pose message: move object or robot ``name`` to position (x, y, z), turned by
    yaw (rad) about the vertical."""
    from geometry_msgs.msg import PoseStamped

    msg = PoseStamped()
    msg.header.frame_id = name
    p, o = msg.pose.position, msg.pose.orientation
    p.x, p.y, p.z = (float(v) for v in position)
    o.x, o.y, o.z, o.w = yaw_quaternion(yaw)
    return msg


class Referee:
    """A node ``name`` on ``context`` (its own executor unless one is given) watching the
    robots named. video: a Video to write (overhead view and the controllers' eyes);
    video_note: what its caption says until the ball is kicked."""

    def __init__(self, context, robots, name, executor=None, video=None, video_note='',
                 debug_frames=False):
        import rclpy
        from geometry_msgs.msg import PoseStamped
        from rclpy.executors import SingleThreadedExecutor
        from rclpy.parameter import Parameter
        from std_srvs.srv import SetBool, Trigger

        self.node = rclpy.create_node(name, context=context, parameter_overrides=[
            Parameter('use_sim_time', value=True)])
        self.own_executor = executor is None
        self.executor = executor or SingleThreadedExecutor(context=context)
        self.executor.add_node(self.node)
        self.video, self.video_note = video, video_note
        self.monitor = Monitor(self.node, robots, on_eye=video.eye if video else None,
                               on_overhead=self._on_overhead if video else None,
                               debug_frames=debug_frames or video is not None)
        sim = SimTopics()
        self.set_pose = self.node.create_publisher(PoseStamped, sim.set_pose, 10)
        self.pause = self.node.create_client(SetBool, sim.pause)
        self.step = self.node.create_client(Trigger, sim.step)
        self.start_time = None  # simulated s when the clock was started

    @property
    def judge(self):
        """The run's judge (run/judge.py), judging from the clock's start."""
        return self.monitor.judge

    @property
    def elapsed(self):
        """Simulated seconds since the clock was started."""
        return self.judge.elapsed

    def _on_overhead(self, bgr, stamp):
        note = 'KICKED' if self.judge.kicked else self.video_note
        self.video.overhead(bgr, stamp - (self.start_time or 0.0), note)

    def spin_once(self, timeout_s):
        self.executor.spin_once(timeout_sec=timeout_s)

    def spin_until(self, predicate, timeout_s):
        """Spin until predicate() holds (True) or timeout_s of wall time pass (False)."""
        deadline = time.monotonic() + timeout_s
        while not predicate():
            if time.monotonic() > deadline:
                return False
            self.executor.spin_once(timeout_sec=0.02)
        return True

    def call(self, client, request):
        future = client.call_async(request)
        if not self.spin_until(future.done, SERVICE_TIMEOUT_S):
            raise RunError(f'the simulator did not answer {client.srv_name}')
        return future.result()

    # -- before the run --------------------------------------------------------------------------
    def simulator_ready(self):
        """Its services answer, it takes set_pose and its ground truth reaches us."""
        return (self.pause.service_is_ready() and self.step.service_is_ready()
                and self.set_pose.get_subscription_count() > 0
                and not unmatched(self.monitor.truth))

    def waiting_for(self, controllers=(), recorder=None):
        """What the run still waits for before its clock may start, in words ([]: nothing):
        the simulator; this node's own subscriptions (the controllers' annotated frames and
        the overhead view among them); each robot's controller, /<robot>/kick_blue_ball,
        commanding and watching its eyes; the node ``recorder`` subscribed to the robots'
        commands."""
        missing = [] if self.simulator_ready() else ['the simulator']
        missing += unmatched(self.monitor.debug + [s for s in [self.monitor.overhead] if s])
        for robot in controllers:
            topics = RobotTopics(robot)
            for topic, publishes in [(topics.cmd_vel, True)] + [
                    (topics.eye_compressed(eye), False) for eye in EYES]:
                if not self._serves(CONTROLLER, f'/{robot}', topic, publishes):
                    missing.append(f'/{robot}/{CONTROLLER} on {topic}')
            if recorder and not self._serves(recorder, '/', topics.cmd_vel, False):
                missing.append(f'/{recorder} on {topics.cmd_vel}')
        return missing

    def _serves(self, name, namespace, topic, publishes):
        """Whether node namespace/name publishes (or subscribes to) topic, in our graph."""
        ends = (self.node.get_publishers_info_by_topic(topic) if publishes
                else self.node.get_subscriptions_info_by_topic(topic))
        return any(end.node_name == name and end.node_namespace == namespace for end in ends)

    def place(self, world, robot, ball):
        """The world's first robot at robot (x, y, yaw) and its ball at ball (x, y), checked
        on the ground truth (the set_pose topic and the step service are not ordered, so it
        is tried until it took). The simulator must be paused."""
        from std_srvs.srv import Trigger

        name = next(iter(self.monitor.robots))
        requests = [set_pose_request(name, (*robot[:2], world.robots[0].floor), robot[2]),
                    set_pose_request(BALL_NAME,
                                     (*ball, world.ball.floor + world.ball.radius))]

        def took():
            at, seen = self.monitor.robots[name].position, self.monitor.ball
            return (seen is not None and at is not None
                    and max(abs(at[0] - robot[0]), abs(at[1] - robot[1]),
                            abs(seen[0] - ball[0]), abs(seen[1] - ball[1])) < PLACED_WITHIN_M)
        for _ in range(PLACE_TRIES):
            for request in requests:
                self.set_pose.publish(request)
            self.call(self.step, Trigger.Request())
            if self.spin_until(took, 0.2):
                return
        raise RunError('the simulator did not take the placement')

    def start_clock(self):
        """The run starts now: judged from here (Monitor.restart), the simulator resumed."""
        from std_srvs.srv import SetBool

        self.monitor.restart()
        self.start_time = self.monitor.sim_time
        self.call(self.pause, SetBool.Request(data=False))

    def close(self):
        if self.own_executor:
            self.executor.shutdown(timeout_sec=1.0)
        else:
            self.executor.remove_node(self.node)
        self.node.destroy_node()
