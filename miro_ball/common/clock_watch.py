"""Who publishes /clock: one line when a second simulator shares the ROS domain.

Twenty students on one network and one ROS domain see each other's simulators:
/clock then jumps between two timelines. A node that follows /clock cannot tell
that from a simulator restart by the time alone, so it asks the ROS graph who
publishes /clock, once a wall second and whenever time goes back. The graph alone
is not enough either: a simulator killed with SIGKILL stays in the graphs of the
nodes that knew it for about 20 s (Fast DDS's lease), so a follower calls /clock
shared only when it also went back twice within JUMPS_WINDOW_S: two timelines
taking turns, not one restart.
"""
import collections
import time

from rclpy.clock import Clock, ClockType

from miro_ball.miro.interface import CLOCK

CHECK_EVERY_S = 1.0  # wall time
JUMPS_WINDOW_S = 3.0  # wall time
UNKNOWN = '_NODE_NAME_UNKNOWN_'  # what the graph says before it knows a node's name


def clock_publishers(node):
    """Fully qualified names of the nodes publishing /clock, as the graph shows them."""
    return sorted(f"{info.node_namespace.rstrip('/')}/{info.node_name}"
                  for info in node.get_publishers_info_by_topic(CLOCK))


def shared_domain_line(publishers, domain):
    """What a user reads when /clock has more than one publisher."""
    return (f'{len(publishers)} publishers on {CLOCK} ({", ".join(publishers)}) on ROS domain '
            f'{domain}: another simulator shares this domain; give each class member a domain '
            f'of their own, e.g. export ROS_DOMAIN_ID=<1..101> in every shell')


class ClockWatch:
    """Keeps ``contested`` (more publishers on /clock than the node's ``own``, or, for a
    node with none of its own, than the one simulator it follows, its clock having gone
    back twice lately) up to date and says so once, in one line, each time it starts."""

    def __init__(self, node, own=0):
        self.node = node
        self.own = own
        self.contested = False
        self._said = False
        self._backs = collections.deque()  # wall times /clock went back
        self.timer = node.create_timer(CHECK_EVERY_S, self.check,
                                       clock=Clock(clock_type=ClockType.STEADY_TIME))

    def went_back(self):
        """The followed /clock just went back (a restart, or two timelines)."""
        self._backs.append(time.monotonic())

    def check(self):
        """Look again now; True while another simulator shares the domain."""
        while self._backs and time.monotonic() - self._backs[0] > JUMPS_WINDOW_S:
            self._backs.popleft()
        publishers = clock_publishers(self.node)
        taking_turns = self.own > 0 or len(self._backs) >= 2
        contested = len(publishers) > max(self.own, 1) and taking_turns
        # A publisher's node name reaches the graph after the publisher: name them once known.
        if contested and not self._said and not any(UNKNOWN in name for name in publishers):
            self.node.get_logger().warning(
                shared_domain_line(publishers, self.node.context.get_domain_id()))
            self._said = True
        self._said = self._said and contested
        self.contested = contested
        return contested
