"""Demo mode in one process with the simulator, stepped a platform tick at a time.

The world advances 20 ms, then the executor runs until demo mode has ticked at this
instant with this tick's frames taken in, so what happens depends on simulated time only
(as run/stepped_rig.py does for the ball controllers). Tests read the world's ground truth
and what demo mode sent (its last Action, its Animal's state) directly.
"""
import time

from rclpy.executors import SingleThreadedExecutor
from rclpy.parameter import Parameter

from miro_ball.animal.demo_mode import DEMO_MODE
from miro_ball.controller.host import ControllerHost
from miro_sim_bullet.ros.node import SimNode

TICK_TIMEOUT_S = 10.0


class AnimalRig:
    def __init__(self, context, world='den', camera_rate=15.0, **params):
        """params: demo mode's ROS parameters; camera_rate: the eyes' frames a second (a
        test about touch, sound or sleep needs fewer)."""
        self.sim_node = SimNode(context=context, parameter_overrides=[
            Parameter('paused', value=True), Parameter('world', value=world),
            Parameter('camera_rate', value=camera_rate)])
        self.sim = self.sim_node.sim
        self.robot = self.sim.robot
        self.node = ControllerHost(
            DEMO_MODE, context=context, robot=self.robot.name,
            parameter_overrides=[Parameter('use_sim_time', value=True)]
            + [Parameter(name, value=value) for name, value in params.items()])
        self.animal = self.node.controller
        self.executor = SingleThreadedExecutor(context=context)
        for node in (self.sim_node, self.node):
            self.executor.add_node(node)
        self.actions = []  # (simulated s, Action) of every tick

    def frames_seen(self):
        return self.node.frames_processed + sum(self.node.rejected.values())

    def advance(self):
        """One platform tick; then callbacks until demo mode has ticked at this instant with
        every frame and microphone block of it taken in."""
        published, seen = self.sim_node.frames_published, self.frames_seen()
        self.sim_node.advance(self.sim.ticks_per_platform_tick)
        wanted = seen + self.sim_node.frames_published - published
        mics = self.sim_node.robots[self.robot.name]
        now = self.sim.time
        deadline = time.monotonic() + TICK_TIMEOUT_S
        while not (self.frames_seen() >= wanted and self.node.mic_blocks >= mics.sent['mics']
                   and self.node.last_tick is not None and self.node.last_tick >= now - 1e-9):
            if time.monotonic() > deadline:
                raise TimeoutError(f'demo mode did not tick at {now:.2f} s')
            self.executor.spin_once(timeout_sec=0.01)
        self.animal = self.node.controller
        self.actions.append((now, self.node.last_action))

    def run(self, seconds, until=None):
        """Advance seconds of simulated time (or until until() holds); the time it took."""
        start = self.sim.time
        while self.sim.time - start < seconds - 1e-9:
            self.advance()
            if until is not None and until():
                break
        return self.sim.time - start

    def close(self):
        self.executor.shutdown(timeout_sec=1.0)
        self.node.destroy_node()
        self.sim_node.destroy_node()
