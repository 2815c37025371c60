"""Closed-loop episodes in one process: simulator and controller nodes on one executor.

The world is stepped here, one platform tick (20 ms) at a time, and the
executor runs until the controller has seen that instant, so outcomes depend
on simulated time, not on how fast the machine is. Used by the closed-loop
tests and the scenario benchmark.
"""
import math
import random
import time
from dataclasses import dataclass

KICK_DISTANCE_M = 0.3
FELL_BELOW_M = 0.02  # axle height: 0.045 on the floor
ARENA_FREE_RADIUS = 1.21 - 0.25  # keep starting poses clear of the wall panels


@dataclass
class Placement:
    robot: tuple  # x, y, yaw
    ball: tuple  # x, y


@dataclass
class Outcome:
    kicked: bool
    time_to_kick: float | None  # simulated seconds
    fell: bool
    sim_time: float
    wall_time: float
    frames: int

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


def run_episode(context, placement=None, mode='improved', limit_s=60.0, renderer='auto',
                world='miro', seed=1, settle_s=1.0, controller_params=()):
    """One episode from a placement (None: the world's own start); returns an Outcome.

    controller_params: extra (name, value) ROS parameters of the controller.
    """
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.parameter import Parameter

    from miro_ball.node import KickBlueBall
    from miro_sim_bullet.node import SimNode

    sim_node = SimNode(context=context, parameter_overrides=[
        Parameter('paused', value=True), Parameter('world', value=world),
        Parameter('renderer', value=renderer)])
    controller = KickBlueBall(context=context, parameter_overrides=[
        Parameter('use_sim_time', value=True), Parameter('mode', value=mode),
        Parameter('seed', value=seed)] + [Parameter(n, value=v) for n, v in controller_params])
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(sim_node)
    executor.add_node(controller)
    sim = sim_node.sim
    try:
        if placement is not None:
            sim.place(robot_pose=placement.robot, ball_xy=placement.ball)
        _wait_for_links(executor, sim_node, controller)
        sim_node.advance(round(0.2 / sim.dt))  # let the ball settle before measuring
        start = sim.ball_position()
        wall0 = time.monotonic()
        kicked_at, fell = None, False
        tick = sim.ticks_per_platform_tick
        while sim.time < limit_s:
            frames_before = sim_node.frames_published
            sim_node.advance(tick)
            _spin_until_controller_at(executor, controller, sim_node, frames_before)
            fell = fell or sim.robot_height() < FELL_BELOW_M
            if kicked_at is None and math.dist(sim.ball_position()[:2], start[:2]) >= \
                    KICK_DISTANCE_M:
                kicked_at = sim.time
            if fell or (kicked_at is not None and sim.time >= kicked_at + settle_s):
                break
        return Outcome(kicked_at is not None, kicked_at, fell, sim.time,
                       time.monotonic() - wall0, controller.frames_processed)
    finally:
        executor.shutdown(timeout_sec=1.0)
        controller.destroy_node()
        sim_node.destroy_node()


def _wait_for_links(executor, sim_node, controller, timeout_s=10.0):
    """Discovery: until each side's publishers see the other's subscriptions."""
    def linked():
        return (controller.pub_twist.get_subscription_count() > 0
                and all(pubs[0].get_subscription_count() > 0
                        for pubs in sim_node.pub_eyes.values())
                and sim_node.pub_cliff.get_subscription_count() > 0)
    deadline = time.monotonic() + timeout_s
    while not linked():
        if time.monotonic() > deadline:
            raise RuntimeError('simulator and controller did not discover each other')
        executor.spin_once(timeout_sec=0.01)


def _spin_until_controller_at(executor, controller, sim_node, frames_before, timeout_s=2.0):
    """Run callbacks until the controller has taken in the camera frames of this tick and
    ticked at the simulator's time, then deliver its output."""
    def seen():
        return controller.frames_processed + sum(controller.rejected.values())
    wanted = seen() + sim_node.frames_published - frames_before

    def caught_up():
        tick = controller.last_tick
        return seen() >= wanted and tick is not None and tick >= sim_node.sim.time - 1e-6
    deadline = time.monotonic() + timeout_s
    while not caught_up() and time.monotonic() < deadline:
        executor.spin_once(timeout_sec=0.005)
    for _ in range(20):
        executor.spin_once(timeout_sec=0)
