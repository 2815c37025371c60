"""Closed-loop episodes in one process: the simulator and one controller per robot on
one executor.

The world is stepped here, one platform tick (20 ms) at a time, and the executor
runs until every robot has taken this tick's command, so outcomes depend on
simulated time, not on how fast the machine is. Used by the closed-loop tests
and the scenario benchmark.
"""
import math
import random
import time
from dataclasses import dataclass

from miro_ball.run.judge import FELL_BELOW_M, KICK_DISTANCE_M

ARENA_FREE_RADIUS = 1.21 - 0.25  # keep starting poses clear of the wall panels


@dataclass
class Placement:
    robot: tuple  # x, y, yaw of the first robot
    ball: tuple  # x, y


@dataclass
class Outcome:
    kicked: bool
    time_to_kick: float | None  # simulated seconds
    fell: bool  # any robot
    sim_time: float
    wall_time: float
    frames: int  # camera frames the controllers took in

    @property
    def success(self):
        return self.kicked and not self.fell


def random_placement(rng, min_gap=0.4):
    """Robot and ball anywhere in the default arena, apart, the robot facing anywhere."""
    def point():
        r = ARENA_FREE_RADIUS * math.sqrt(rng.random())
        a = rng.uniform(-math.pi, math.pi)
        return r * math.cos(a), r * math.sin(a)
    robot = point()
    ball = point()
    while math.dist(robot, ball) < min_gap:
        ball = point()
    return Placement((*robot, rng.uniform(-math.pi, math.pi)), ball)


def placements(count, seed=0):
    rng = random.Random(seed)
    return [random_placement(rng) for _ in range(count)]


class Episode:
    """The simulator (paused, stepped from here) and a kick_blue_ball per robot."""

    def __init__(self, context, mode='improved', renderer='auto', world='miro', seed=1,
                 controller_params=()):
        from rclpy.executors import SingleThreadedExecutor
        from rclpy.parameter import Parameter

        from miro_ball.controller.node import KickBlueBall
        from miro_sim_bullet.ros.node import SimNode

        self.sim_node = SimNode(context=context, parameter_overrides=[
            Parameter('paused', value=True), Parameter('world', value=world),
            Parameter('renderer', value=renderer)])
        self.sim = self.sim_node.sim
        self.controllers = {
            name: KickBlueBall(context=context, parameter_overrides=[
                Parameter('use_sim_time', value=True), Parameter('robot_name', value=name),
                Parameter('mode', value=mode), Parameter('seed', value=seed + index)]
                + [Parameter(n, value=v) for n, v in controller_params])
            for index, name in enumerate(self.sim.robots)}
        self.executor = SingleThreadedExecutor(context=context)
        for node in (self.sim_node, *self.controllers.values()):
            self.executor.add_node(node)

    def close(self):
        self.executor.shutdown(timeout_sec=1.0)
        for node in (*self.controllers.values(), self.sim_node):
            node.destroy_node()

    def frames_seen(self):
        return sum(c.frames_processed + sum(c.rejected.values())
                   for c in self.controllers.values())

    def wait_for_links(self, timeout_s=10.0):
        """Discovery: until each side's publishers see the other's subscriptions."""
        def linked():
            return all(self.controllers[name].pub_twist.get_subscription_count() > 0
                       and all(pubs[0].get_subscription_count() > 0
                               for pubs in interface.pub_eyes.values())
                       and interface.pub_cliff.get_subscription_count() > 0
                       for name, interface in self.sim_node.robots.items())
        self._spin_until(linked, timeout_s, 'the simulator and the controllers did not '
                                            'discover each other')

    def tick(self, timeout_s=5.0):
        """One platform tick of the world, then callbacks until every robot has this tick's
        command (after its controller took in this tick's frames)."""
        published_before, seen_before = self.sim_node.frames_published, self.frames_seen()
        self.sim_node.advance(self.sim.ticks_per_platform_tick)
        wanted = seen_before + self.sim_node.frames_published - published_before
        now = self.sim.time

        def commanded():
            return self.frames_seen() >= wanted and all(
                robot.last_cmd_time >= now - 1e-9 for robot in self.sim.robots.values())
        self._spin_until(commanded, timeout_s,
                         f'no command for simulated time {now:.2f} s within {timeout_s:g} s')

    def _spin_until(self, predicate, timeout_s, failure):
        deadline = time.monotonic() + timeout_s
        while not predicate():
            if time.monotonic() > deadline:
                raise TimeoutError(failure)
            self.executor.spin_once(timeout_sec=0.01)


def run_episode(context, placement=None, mode='improved', limit_s=60.0, renderer='auto',
                world='miro', seed=1, settle_s=1.0, controller_params=()):
    """One episode from a placement (None: the world's own start); returns an Outcome.

    controller_params: extra (name, value) ROS parameters of every controller.
    """
    episode = Episode(context, mode=mode, renderer=renderer, world=world, seed=seed,
                      controller_params=controller_params)
    sim = episode.sim
    try:
        if placement is not None:
            sim.robot.place(*placement.robot)
            sim.place_ball(*placement.ball)
        episode.wait_for_links()
        episode.sim_node.advance(round(0.2 / sim.dt))  # let the ball settle before measuring
        start = sim.ball_position()
        wall0 = time.monotonic()
        kicked_at, fell = None, False
        while sim.time < limit_s:
            episode.tick()
            fell = fell or any(r.height() < FELL_BELOW_M for r in sim.robots.values())
            if kicked_at is None and math.dist(sim.ball_position()[:2], start[:2]) >= \
                    KICK_DISTANCE_M:
                kicked_at = sim.time
            if fell or (kicked_at is not None and sim.time >= kicked_at + settle_s):
                break
        return Outcome(kicked_at is not None, kicked_at, fell, sim.time,
                       time.monotonic() - wall0,
                       sum(c.frames_processed for c in episode.controllers.values()))
    finally:
        episode.close()
