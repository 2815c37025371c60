"""Which MiRos are on a node's ROS graph, and what to tell a user whose robot is not."""
from miro_ball.miro.interface import RobotTopics, robots_in


def robots_running(node):
    """Names of the robots whose odometry someone publishes, sorted (the graph lists topics
    that only have subscribers too, like those of a node waiting for a robot)."""
    return [name for name in robots_in(t for t, _ in node.get_topic_names_and_types())
            if node.count_publishers(RobotTopics(name).odom)]


def missing_robot(node, robot, waited_s):
    """One line: robot ``robot`` is not on node's graph after waited_s, and which are."""
    robots = robots_running(node)
    found = (f'the robots there are {", ".join(robots)} (--robot NAME)' if robots else
             'no robot is there (is the simulator running, with the same ROS_DOMAIN_ID?)')
    return (f'no robot {robot!r} on ROS domain {node.context.get_domain_id()} after '
            f'{waited_s:g} s: {found}')
