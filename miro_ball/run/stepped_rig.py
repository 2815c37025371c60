"""Episodes in one process: the simulator and a kick_blue_ball per robot on one executor,
watched by a referee on the same executor (see episode.py).

The world is stepped here, one platform tick (20 ms) at a time, and the executor
runs until every robot has taken this tick's command and the referee has this
tick's ground truth, so outcomes depend on simulated time, not on how fast the
machine is. Used by the closed-loop tests and the scenario benchmark.

The rig builds its nodes in this process and reads their own counters (the simulator's
robots' last command time, the controllers' frames and publishers): the ROS graph has no
message that says "every controller has taken tick t", and waiting on the wall clock for it
would make outcomes depend on the machine's load.
"""
import time

from miro_ball.controller.names import NODE_NAME as CONTROLLER
from miro_ball.miro.interface import EYES, RobotTopics, SIM_NODE_NAME
from miro_ball.run.referee import Referee, RunError

SETTLE_S = 0.2  # simulated s for robot and ball to come to rest where they were placed
LINK_TIMEOUT_S = 10.0
TICK_TIMEOUT_S = 5.0


class SteppedRig:
    """mode, seed (of the first robot's controller; the next get seed + 1, ...) and
    controller_params ((name, value) ROS parameters) of the controllers; quiet: their and
    the simulator's info lines left out (the benchmark's own lines would drown); lens:
    the simulator's eye lens (pinhole or miro)."""

    def __init__(self, context, world='miro', mode='improved', renderer='auto', seed=1,
                 controller_params=(), quiet=False, lens='pinhole'):
        self.context = context
        self.world, self.mode, self.renderer, self.seed = world, mode, renderer, seed
        self.lens = lens
        self.controller_params = controller_params
        self.quiet = quiet
        self.sim_node = self.referee = None
        self.controllers = {}

    def open(self):
        from rclpy.executors import SingleThreadedExecutor
        from rclpy.parameter import Parameter

        from miro_ball.controller.host import ControllerHost
        from miro_ball.controller.kick_blue_ball import KICK_BLUE_BALL
        from miro_sim_bullet.ros.node import SimNode

        self._quieten(SIM_NODE_NAME)
        self.sim_node = SimNode(context=self.context, parameter_overrides=[
            Parameter('paused', value=True), Parameter('world', value=self.world),
            Parameter('renderer', value=self.renderer), Parameter('lens', value=self.lens)])
        self.sim = self.sim_node.sim
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.sim_node)
        for index, name in enumerate(self.sim.robots):
            self._quieten(f'{name}.{CONTROLLER}')  # the logger of node /<name>/<CONTROLLER>
            self.controllers[name] = ControllerHost(
                KICK_BLUE_BALL, context=self.context, robot=name, parameter_overrides=[
                    Parameter('use_sim_time', value=True), Parameter('mode', value=self.mode),
                    Parameter('seed', value=self.seed + index)]
                + [Parameter(n, value=v) for n, v in self.controller_params])
            self.executor.add_node(self.controllers[name])
        self.referee = Referee(self.context, list(self.sim.robots), 'miro_episode_referee',
                               executor=self.executor)

    def _quieten(self, logger):
        if self.quiet:
            from rclpy.logging import LoggingSeverity, set_logger_level

            set_logger_level(logger, LoggingSeverity.WARN)

    def place(self, placement):
        self.sim.robot.place(*placement.robot)
        self.sim.place_ball(*placement.ball)
        self.sim.run(SETTLE_S)

    def wait_for_controllers(self):
        """Discovery: until each controller's publisher sees the simulator's subscription and
        its eye and cliff subscriptions see the simulator's publishers, so that no frame of
        the episode is lost."""
        def linked(name, controller):
            topics = RobotTopics(name)
            wanted = {topics.eye_compressed(eye) for eye in EYES} | {topics.cliff}
            listening = [sub for sub in controller.subscriptions if sub.topic_name in wanted]
            return (controller.pub_twist.get_subscription_count() > 0
                    and len(listening) == len(wanted)
                    and all(sub.get_publisher_count() > 0 for sub in listening))
        self._spin_until(lambda: all(linked(*c) for c in self.controllers.items()),
                         LINK_TIMEOUT_S, 'the simulator and the controllers did not discover '
                                         'each other')

    def start(self):
        self.referee.monitor.restart(self.sim.time)
        self.referee.start_time = self.sim.time

    def frames_seen(self):
        return sum(c.frames_processed + sum(c.rejected.values())
                   for c in self.controllers.values())

    def advance(self):
        """One platform tick of the world, then callbacks until every robot has this tick's
        command (after its controller took in this tick's frames) and the referee this
        tick's ground truth."""
        published_before, seen_before = self.sim_node.frames_published, self.frames_seen()
        self.sim_node.advance(self.sim.ticks_per_platform_tick)
        wanted = seen_before + self.sim_node.frames_published - published_before
        now = self.sim.time

        def done():
            return (self.frames_seen() >= wanted
                    and all(robot.last_cmd_time >= now - 1e-9
                            for robot in self.sim.robots.values())
                    and self.referee.monitor.caught_up(now))
        self._spin_until(done, TICK_TIMEOUT_S,
                         f'no command for simulated time {now:.2f} s within '
                         f'{TICK_TIMEOUT_S:g} s')

    def ended_early(self):
        return None

    def _spin_until(self, predicate, timeout_s, failure):
        deadline = time.monotonic() + timeout_s
        while not predicate():
            if time.monotonic() > deadline:
                raise RunError(failure)
            self.executor.spin_once(timeout_sec=0.01)

    def close(self, result):
        result.frames = sum(c.frames_processed for c in self.controllers.values())
        if self.referee is not None:
            self.referee.close()
        if self.sim_node is not None:
            self.executor.shutdown(timeout_sec=1.0)
        for node in (*self.controllers.values(), self.sim_node):
            if node is not None:
                node.destroy_node()
