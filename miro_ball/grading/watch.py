"""What a graded command does on the ROS graph beyond MiRo's interface.

A graded command may use its robot's interface (subscribe to the sensors, publish the
controls) and anything of its own. It cheats when it publishes /clock or on a topic
the robot publishes (faking what MiRo senses or when), publishes on another robot's
interface, uses the simulator's own topics or services (ground truth, the standard
simulation_interfaces' services, the older set_pose, reset, pause and step, its
parameters), whether or not the graded simulator offers them.
``breaches`` says so in words for a list of endpoints: plain Python. ``GraphWatch``
lists the endpoints of a node's ROS graph that are not the host's own.
"""
from dataclasses import dataclass

from miro_ball.miro.interface import CLOCK, RobotTopics, SENSOR, SimTopics

PUBLISHER, SUBSCRIPTION, CLIENT = 'publishes on', 'listens to', 'calls'
INFRASTRUCTURE = ('/rosout', '/parameter_events')  # every rclpy node publishes these


@dataclass(frozen=True)
class Endpoint:
    kind: str  # PUBLISHER, SUBSCRIPTION or CLIENT
    name: str  # the topic or service
    node: str  # /namespace/name, as it calls itself (anyone can take any name)


def breaches(endpoints, robot):
    """Sorted reasons, one per forbidden endpoint of a graded command driving ``robot``."""
    own_sensors = set(RobotTopics(robot).all(SENSOR))
    interface_rows = set(RobotTopics().all())
    sim_root = SimTopics().topic('')
    said = set()
    for end in endpoints:
        where = f'{end.name} (node {end.node})'
        if end.name.startswith(sim_root):
            said.add(f"{end.kind} the simulator's own {where}: not MiRo's interface")
        elif end.kind != PUBLISHER or end.name in INFRASTRUCTURE:
            continue
        elif end.name == CLOCK:
            said.add(f'{end.kind} {where}: a clock of its own')
        elif end.name in own_sensors:
            said.add(f"{end.kind} {where}: faking the robot's sensors")
        elif _other_robots(end.name, robot, interface_rows):
            said.add(f"{end.kind} {where}: another robot's interface")
    return sorted(said)


def _other_robots(topic, robot, interface_rows):
    parts = topic.split('/', 2)
    return len(parts) == 3 and parts[1] != robot and parts[2] in interface_rows


class WatchFailed(Exception):
    """The graph could not be looked at: what was not seen can not pass."""


def verdict(watch, robot):
    """breaches() of what ``watch`` (a GraphWatch) sees; a watch that fails fails the episode
    (the reason in the same words as a breach), never lets it pass unseen."""
    try:
        return breaches(watch.endpoints(), robot)
    except WatchFailed as err:
        return [f'the graph watch failed ({err}): the episode is not scored']


class GraphWatch:
    """The endpoints on node's graph that are not the host's: ``mark_own()`` once, before
    the command starts, takes every endpoint there is as the host's (by its GID: node
    names prove nothing); ``endpoints()`` then lists the others."""

    def __init__(self, node):
        self.node = node
        self.own = set()

    def _ends(self):
        node = self.node
        for topic, _ in node.get_topic_names_and_types():
            for kind, infos in ((PUBLISHER, node.get_publishers_info_by_topic(topic)),
                                (SUBSCRIPTION, node.get_subscriptions_info_by_topic(topic))):
                for info in infos:
                    yield (bytes(info.endpoint_gid), Endpoint(
                        kind, topic, _full(info.node_namespace, info.node_name)))

    def mark_own(self):
        self.own = {gid for gid, _ in self._ends()}

    def endpoints(self):
        ends = [end for gid, end in self._ends() if gid not in self.own]
        # Service clients carry no GID in rclpy's graph API: those of every node that is
        # not one of ours (one taking our name is seen too: ours have no clients).
        for name, namespace in self.node.get_node_names_and_namespaces():
            try:
                clients = self.node.get_client_names_and_types_by_node(name, namespace)
            except Exception as err:  # noqa: B902 - rclpy's lookup error has no public class
                if (name, namespace) not in self.node.get_node_names_and_namespaces():
                    continue  # the node left meanwhile: nothing of it to see
                raise WatchFailed(f'could not list the service clients of '
                                  f'{_full(namespace, name)}: {err}') from err
            ends += [Endpoint(CLIENT, service, _full(namespace, name))
                     for service, _ in clients]
        return ends


def _full(namespace, name):
    return f'{namespace.rstrip("/")}/{name}'
