"""A callback that raises costs its own message, not the node: the traceback is logged once
and the node serves on; what no node can go on from ends the spin with its traceback."""
import time

import pytest
from rclpy.executors import SingleThreadedExecutor
from rclpy.experimental import EventsExecutor

from miro_ball.common.stopping import spin_until_stopped

HANG_GUARD_S = 20.0


class StopWhen:
    """A stop request that comes when predicate() holds (or the hang guard runs out)."""

    def __init__(self, predicate):
        self.predicate = predicate
        self.deadline = time.monotonic() + HANG_GUARD_S

    @property
    def requested(self):
        return self.predicate() or time.monotonic() > self.deadline


def faulty_node(context, fault):
    """A node whose timer raises ``fault`` every other tick; returns (node, ticks)."""
    import rclpy

    node = rclpy.create_node('faulty', context=context)
    ticks = []

    def tick():
        ticks.append(len(ticks))
        if len(ticks) % 2 == 0:
            raise fault
    node.create_timer(0.005, tick)
    return node, ticks


def serve(executor, node, ticks, count):
    """Spin node until its timer ticked ``count`` times, which it must (faults or not)."""
    executor.add_node(node)
    try:
        spin_until_stopped(executor, StopWhen(lambda: len(ticks) >= count))
        assert len(ticks) >= count, 'the node stopped serving after a fault'
    finally:
        executor.shutdown()
        node.destroy_node()


@pytest.mark.parametrize('make_executor', [SingleThreadedExecutor, EventsExecutor])
def test_a_callback_that_raises_is_logged_once_and_the_node_serves_on(
        ros_context, make_executor, capfd):
    node, ticks = faulty_node(ros_context, ValueError('a bad message'))
    serve(make_executor(context=ros_context), node, ticks, 10)
    err = capfd.readouterr().err
    assert err.count('a callback failed') == 1, err  # once, not once a fault
    assert 'Traceback' in err and 'ValueError: a bad message' in err and 'in tick' in err


@pytest.mark.parametrize('fatal, fault', [((), MemoryError()), ((KeyError,), KeyError('x'))])
def test_what_the_node_can_not_go_on_from_ends_the_spin(ros_context, fatal, fault):
    node, ticks = faulty_node(ros_context, fault)
    executor = SingleThreadedExecutor(context=ros_context)
    executor.add_node(node)
    try:
        with pytest.raises(type(fault)):
            spin_until_stopped(executor, StopWhen(lambda: False), fatal=fatal)
        assert len(ticks) == 2  # the first fault ended it
    finally:
        executor.shutdown()
        node.destroy_node()


@pytest.mark.parametrize('warning_first', [True, False])
def test_a_warning_and_a_failing_callback_in_either_order_leave_the_node_serving(
        ros_context, warning_first, capfd):
    """Every node warns through Throttled and logs faults through the spin's fault log, one
    logger at two severities: rclpy refused the second severity from their shared call site
    (the node exited, or every later warning came out as an ERROR traceback)."""
    import rclpy

    from miro_ball.common.throttle import Throttled

    node = rclpy.create_node('warns_and_fails', context=ros_context)
    warn = Throttled(node.get_logger().warning, period_s=0.0)
    ticks = []

    def tick():
        ticks.append(len(ticks))
        if (len(ticks) % 2 == 1) == warning_first:
            warn('bad', f'a bad message number {len(ticks)}: ignored')
        else:
            raise ValueError('a callback that fails')
    node.create_timer(0.005, tick)
    serve(SingleThreadedExecutor(context=ros_context), node, ticks, 8)
    err = capfd.readouterr().err
    warnings = [line for line in err.splitlines() if 'a bad message number' in line]
    assert len(warnings) >= 3 and all(line.startswith('[WARN]') for line in warnings), err
    assert 'Logger severity cannot be changed' not in err
    assert err.count('a callback failed') == 1, err
