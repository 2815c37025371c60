"""A /clock message that rclpy's time source would raise on is dropped, not fatal.

rclpy's TimeSource turns every /clock message into a Time, and Time refuses a
negative one with a ValueError that comes out of the executor and ends the node.
Anything on the bus may publish /clock, so each node on simulated time puts this
check in front. rclpy has no public hook for it, hence the private _time_source.
The same nodes watch who publishes /clock (clock_watch.py): a second simulator on
the domain is named once.
"""
from miro_ball.common.clock_watch import ClockWatch
from miro_ball.miro.interface import CLOCK


def guard_clock(node, warn):
    """Check /clock before node's time source sees it; warn(key, text) says what was dropped.
    Returns the node's ClockWatch."""
    source = node._time_source
    unchecked = source.clock_callback
    if getattr(unchecked, 'guarded', False):  # a second observer on the same node
        return unchecked.watch

    watch = ClockWatch(node)
    latest = []

    def checked(msg):
        if msg.clock.sec < 0:
            warn('bad clock', f'{CLOCK}: negative time {msg.clock.sec} s ignored')
            return
        now = (msg.clock.sec, msg.clock.nanosec)
        if latest and now < latest[-1]:
            watch.went_back()
        latest[:] = [now]
        unchecked(msg)

    checked.guarded = True
    checked.watch = watch
    # Future subscriptions (use_sim_time switched on later) and the current one.
    source.clock_callback = checked
    for subscription in node.subscriptions:
        if subscription.topic_name == CLOCK and subscription.callback == unchecked:
            subscription.callback = checked
    return checked.watch
