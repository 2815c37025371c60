"""Who publishes /clock: one line when a second simulator shares the ROS domain.

Twenty students on one network and one ROS domain see each other's simulators:
/clock then jumps between two timelines. A node that follows /clock cannot tell
that from a simulator restart by the time alone, so it asks the ROS graph who
publishes /clock, once a wall second and whenever time goes back.
"""
from rclpy.clock import Clock, ClockType

from miro_ball.miro.interface import CLOCK

CHECK_EVERY_S = 1.0  # wall time


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
    """Keeps ``contested`` (more publishers on /clock than the node's ``own``, or than the
    one simulator a node with none of its own follows) up to date and says so once, in one
    line, each time it starts."""

    def __init__(self, node, own=0):
        self.node = node
        self.own = own
        self.contested = False
        self.timer = node.create_timer(CHECK_EVERY_S, self.check,
                                       clock=Clock(clock_type=ClockType.STEADY_TIME))

    def check(self):
        """Look again now; True while another simulator shares the domain."""
        publishers = clock_publishers(self.node)
        contested = len(publishers) > max(self.own, 1)
        if contested and not self.contested:
            self.node.get_logger().warning(
                shared_domain_line(publishers, self.node.context.get_domain_id()))
        self.contested = contested
        return contested
