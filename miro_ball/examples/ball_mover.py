"""Move the ball back and forth across the arena, like COM3528's ball_mover.py.

Every 20 ms of simulated time the ball is put at x = X, y = A sin(2 pi t / T), at
rest, through the simulator's /miro_sim/set_entity_state (the standard
simulation_interfaces' service: any simulator that serves it takes the same request).
The original took only the nanoseconds of the elapsed time, so its sine jumped back
every second; here t is the whole elapsed time.

    python -m miro_ball.examples.ball_mover [--amplitude 0.65] [--period 1.0] ...
"""
import argparse
import math
import sys
import time

from rclpy.node import Node

from miro_ball.common.clock_guard import guard_clock
from miro_ball.common.messages import has_standard, NO_STANDARD
from miro_ball.common.sim_time import sim_time_overrides
from miro_ball.common.throttle import Throttled
from miro_ball.examples._client import number, run
from miro_ball.miro.interface import BALL_NAME, SimTopics

GIVE_UP_S = 2.0  # wall seconds without an answer: the simulator is gone, ask anew


def ball_y(t, amplitude, period):
    """Where the ball is t seconds after the start."""
    return amplitude * math.sin(2.0 * math.pi * t / period)


class BallMover(Node):
    def __init__(self, options, context=None):
        if not has_standard():
            raise ValueError('the ball is moved through the standard simulator services: '
                             + NO_STANDARD)
        from simulation_interfaces.srv import SetEntityState

        super().__init__('ball_mover', context=context,
                         parameter_overrides=sim_time_overrides())
        self.options = options
        self.warn = Throttled(self.get_logger().warning)
        guard_clock(self, self.warn)
        self.client = self.create_client(SetEntityState, SimTopics().standard(SetEntityState))
        self.start = None
        # (future, wall s) of a request not yet answered: the next waits, so no queue builds
        # up behind a slow simulator; one that vanished is given up after a while.
        self.pending = None
        self.last = None  # (t, y) of the latest command the simulator took
        self.timer = self.create_timer(0.02, self.tick)
        self.get_logger().info(
            f"moving '{options.object}' along x = {options.x:g} m: y = {options.amplitude:g} "
            f"sin(2 pi t / {options.period:g} s), on the simulator's /clock")

    def tick(self):
        from simulation_interfaces.msg import EntityState
        from simulation_interfaces.srv import SetEntityState

        now = self.get_clock().now().nanoseconds * 1e-9
        if now == 0.0:
            return  # no /clock yet
        self.start = now if self.start is None else self.start
        t = now - self.start
        if self.options.duration and t > self.options.duration:
            self.get_logger().info('done: %g s of moving the ball' % self.options.duration)
            raise SystemExit(0)
        if self.pending is not None:
            future, sent = self.pending
            if time.monotonic() - sent < GIVE_UP_S:
                return
            self.client.remove_pending_request(future)
            self.pending = None
        if not self.client.service_is_ready():
            self.warn('service', f'waiting for the simulator\'s {self.client.srv_name}')
            return
        y = ball_y(t, self.options.amplitude, self.options.period)
        state = EntityState()  # header.frame_id '': the world; twist zero: at rest
        position = state.pose.position
        position.x, position.y, position.z = self.options.x, y, self.options.z
        state.pose.orientation.w = 1.0
        future = self.client.call_async(SetEntityState.Request(entity=self.options.object,
                                                               state=state))
        self.pending = (future, time.monotonic())
        future.add_done_callback(lambda done: self._taken(done, (t, y)))

    def _taken(self, future, command):
        from simulation_interfaces.msg import Result

        if self.pending is None or self.pending[0] is not future:
            return  # given up on already
        self.pending = None
        response = future.result()
        if response.result.result != Result.RESULT_OK:
            self.warn('refused', f'the simulator refused: {response.result.error_message}')
            return
        self.last = command

    def stop(self):
        """The ball stays where it is."""


def build_parser():
    parser = argparse.ArgumentParser(prog='ball_mover', description=__doc__.split('\n\n')[0])
    parser.add_argument('--x', type=number(-1000, 1000), default=0.6,
                        help='x of the line (0.6 m)')
    parser.add_argument('--amplitude', type=number(-1000, 1000), default=0.65,
                        help='A, m (0.65)')
    parser.add_argument('--period', type=number(0.001, 1000), default=1.0,
                        help='T, simulated s (1.0)')
    parser.add_argument('--z', type=number(-1000, 1000), default=0.1,
                        help="height of the object's centre (0.1 m: the ball on the floor)")
    parser.add_argument('--duration', type=number(0, 1e6), default=120.0,
                        help='stop after this many simulated seconds; 0 = never (120)')
    parser.add_argument('--object', default=BALL_NAME,
                        help=f'name of the object to move ({BALL_NAME})')
    return parser


def parse_args(argv):
    return build_parser().parse_args(argv)


def main(argv=None):
    return run(BallMover, build_parser(), argv)


if __name__ == '__main__':
    sys.exit(main())
