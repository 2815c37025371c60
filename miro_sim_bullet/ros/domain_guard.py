"""One simulator per ROS domain: the command line simulator refuses to start beside another.

Twenty students on one network and ROS domain 0 see each other's simulators; two
/clock timelines then take turns in every node that follows /clock. A simulator
that finds another /clock publisher when it starts refuses, and says how to pick a
domain of one's own. Discovery shows the other one within tens of milliseconds; where
some process on the domain has just left, only at its next announcement (Fast DDS:
every 3 s, measured up to 2.9 s), after the look: the running simulators' ClockWatch
then names each other, once.
"""
import time

from miro_ball.common.clock_watch import clock_publishers, UNKNOWN
from miro_ball.miro.interface import CLOCK

POLL_S = 0.05  # wall time between two looks at the graph


class SharedDomain(Exception):
    """Another node publishes /clock on this simulator's ROS domain."""


def other_clock_publishers(node, wait_s):
    """Names of the nodes other than ``node`` (which publishes /clock itself) that publish
    /clock, looked for during up to wait_s of wall time; [] if none turned up."""
    deadline = time.monotonic() + wait_s
    while True:
        others = clock_publishers(node)
        # Its own is in the graph from its creation; another simulator has the same name.
        others.remove(node.get_fully_qualified_name())
        named = not any(UNKNOWN in name for name in others)
        if (others and named) or time.monotonic() >= deadline:
            return others
        time.sleep(POLL_S)


def refuse_shared_domain(node, wait_s):
    """SharedDomain, in one line, if another node publishes /clock on node's domain within
    wait_s of wall time; wait_s 0 skips the look."""
    if wait_s <= 0:
        return
    others = other_clock_publishers(node, wait_s)
    if others:
        raise SharedDomain(
            f'{CLOCK} is already published on ROS domain {node.context.get_domain_id()} by '
            f'{", ".join(others)} (another simulator?): not starting a second one; choose a '
            f'domain of your own, e.g. export ROS_DOMAIN_ID=<1..101> in each of your shells')
