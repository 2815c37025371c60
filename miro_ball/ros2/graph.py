"""The command line's view of the ROS graph: one short-lived node that waits for discovery,
finds a topic's type and its publishers' QoS, and calls a service.

``ros2`` asks a daemon that has been listening all along; without one, a fresh node must
listen a moment before the graph is complete (DISCOVERY_S of wall time, or until what is
asked for shows up).
"""
import os
import time

import rclpy
from rclpy.node import Node

from miro_ball.common.qos import matching

DISCOVERY_S = 1.5  # wall seconds a listing listens before it answers
STABLE_S = 0.5  # wall seconds a listing must stay the same to be the answer
WAIT_S = 5.0  # wall seconds to wait for a topic, node or service that is asked for by name


class CliError(Exception):
    """A one-line answer to bad input (exit status 1)."""


class Graph:
    """A node of the command line, on the default context; closed with close()."""

    def __init__(self, name='miro_ball_ros2'):
        rclpy.init(args=[])
        self.node = Node(f'{name}_{os.getpid()}', start_parameter_services=False)
        self.domain = self.node.context.get_domain_id()

    def close(self):
        self.node.destroy_node()
        rclpy.try_shutdown()

    def spin(self, seconds):
        deadline = time.monotonic() + seconds
        while time.monotonic() < deadline:
            rclpy.spin_once(self.node, timeout_sec=min(0.05, max(0.0, deadline - time.monotonic())))

    def wait(self, predicate, seconds=WAIT_S):
        """Spin until predicate() is true (its value) or seconds pass (None)."""
        deadline = time.monotonic() + seconds
        while time.monotonic() < deadline:
            value = predicate()
            if value:
                return value
            rclpy.spin_once(self.node, timeout_sec=0.05)
        return None

    def settle(self, listing):
        """listing() once the graph has been listened to for DISCOVERY_S and it has not
        changed for STABLE_S (endpoints are announced one by one), or at WAIT_S."""
        start = time.monotonic()
        seen, since = listing(), start
        while time.monotonic() - start < WAIT_S:
            rclpy.spin_once(self.node, timeout_sec=0.05)
            now, current = time.monotonic(), listing()
            if current != seen:
                seen, since = current, now
            elif seen and now - start >= DISCOVERY_S and now - since >= STABLE_S:
                break
        return seen

    def topics(self):
        """{topic: [types]} of everyone but this node."""
        return {name: types for name, types in self.node.get_topic_names_and_types()
                if self._others(name)}

    def _others(self, topic):
        ours = {t for t, _ in self.node.get_publisher_names_and_types_by_node(
            self.node.get_name(), self.node.get_namespace())}
        return topic not in ours or self.node.count_publishers(topic) > 1 \
            or self.node.count_subscribers(topic) > 0

    def topic_type(self, topic):
        """The type of a topic someone publishes or subscribes to; CliError if none does."""
        types = self.wait(lambda: self.topics().get(topic))
        if not types:
            raise CliError(f'no topic {topic} on ROS domain {self.domain} (the topics: '
                           'python -m miro_ball.ros2 topic list)')
        return types[0]

    def qos_for(self, topic):
        """A subscription QoS every publisher of topic matches (common.qos.matching)."""
        return matching(self.node.get_publishers_info_by_topic(topic))

    def nodes(self):
        """['/namespace/name'] of every node but this one, sorted."""
        me = self.node.get_fully_qualified_name()
        return sorted({_join(ns, name) for name, ns in self.node.get_node_names_and_namespaces()
                       if _join(ns, name) != me})

    def find_node(self, full_name):
        """(name, namespace) of a running node; CliError if there is none."""
        full_name = full_name if full_name.startswith('/') else '/' + full_name
        if not self.wait(lambda: full_name in self.nodes()):
            raise CliError(f'no node {full_name} on ROS domain {self.domain} (the nodes: '
                           'python -m miro_ball.ros2 node list)')
        namespace, _, name = full_name.rpartition('/')
        return name, namespace or '/'

    def services(self):
        return {name: types for name, types in self.node.get_service_names_and_types()
                if not name.startswith(self.node.get_fully_qualified_name() + '/')}

    def call(self, service, srv_class, request, seconds=WAIT_S):
        """The response of one call; CliError if there is no such service or no answer."""
        client = self.node.create_client(srv_class, service)
        try:
            if not client.wait_for_service(timeout_sec=seconds):
                raise CliError(f'no service {service} on ROS domain {self.domain} (the '
                               'services: python -m miro_ball.ros2 service list)')
            future = client.call_async(request)
            rclpy.spin_until_future_complete(self.node, future, timeout_sec=seconds)
            if not future.done():
                raise CliError(f'{service} did not answer within {seconds:g} s')
            return future.result()
        finally:
            self.node.destroy_client(client)


def _join(namespace, name):
    return f'{namespace.rstrip("/")}/{name}'
