"""The command line's view of the ROS graph: one short-lived node that waits for discovery,
finds a topic's type and its publishers' QoS, and calls a service.

``ros2`` asks a daemon that has been listening all along; without one, a fresh node must
listen until the graph is complete (settling.py says when), or until what is asked for
by name shows up.
"""
import os
import signal
import sys
import time

import rclpy
from rclpy.node import Node, NodeNameNonExistentError

from miro_ball.common.clock_watch import UNKNOWN
from miro_ball.common.qos import matching
from miro_ball.ros2.settling import incomplete_line, LIMIT_S, Settling

DISCOVERY_INFO = 'ros_discovery_info'  # each process's own topic, of no node: not checked
WAIT_S = 5.0  # wall seconds to wait for a topic, node or service that is asked for by name
WAITING_LINE = 'waiting for service to become available...'  # ros2 service call's


class CliError(Exception):
    """A one-line answer to bad input (exit status 1)."""


class Graph:
    """A node of the command line, on the default context; closed with close()."""

    def __init__(self, name='miro_ball_ros2', own_ctrl_c=False):
        """own_ctrl_c: Ctrl+C raises KeyboardInterrupt and the node stays up, for a verb
        that still has something to say to the graph (a goal to cancel); else rclpy's
        handler shuts the node down and wakes whatever waits on it."""
        from rclpy.signals import SignalHandlerOptions

        rclpy.init(args=[], signal_handler_options=SignalHandlerOptions.NO if own_ctrl_c
                   else SignalHandlerOptions.ALL)
        if own_ctrl_c:  # also where SIGINT came ignored (a shell's job started with &), as
            # rclpy's handler takes it there too
            signal.signal(signal.SIGINT, signal.default_int_handler)
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
        """listing() once the graph is complete (settling.Settling), or at its time limit,
        then with a line on stderr that it may be incomplete."""
        settling = Settling(time.monotonic())
        while not settling.see(time.monotonic(), listing(), self.consistent()):
            self.spin(0.1)
        if not settling.whole:
            print(incomplete_line(LIMIT_S), file=sys.stderr)
        return settling.listing

    def consistent(self):
        """Whether every endpoint heard of has its node and every node heard of has
        endpoints: a process's endpoints and its node names arrive apart."""
        node = self.node
        for topic, _ in node.get_topic_names_and_types(no_demangle=True):
            if topic == DISCOVERY_INFO:
                continue
            endpoints = node.get_publishers_info_by_topic(topic, no_mangle=True) \
                + node.get_subscriptions_info_by_topic(topic, no_mangle=True)
            if any(info.node_name == UNKNOWN for info in endpoints):
                return False
        for name, namespace in node.get_node_names_and_namespaces():
            try:
                if not (node.get_publisher_names_and_types_by_node(name, namespace)
                        or node.get_subscriber_names_and_types_by_node(name, namespace)):
                    return False
            except NodeNameNonExistentError:  # it has just gone
                return False
        return True

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

    def endpoints(self, topic):
        """([publishers], [subscriptions]) of topic (TopicEndpointInfo) but this node's."""
        me = self.node.get_name()
        return tuple([info for info in endpoints if info.node_name != me]
                     for endpoints in (self.node.get_publishers_info_by_topic(topic),
                                       self.node.get_subscriptions_info_by_topic(topic)))

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

    def call(self, service, srv_class, request, seconds=WAIT_S, say=None):
        """The response of one call; CliError if there is no such service or no answer.
        say: print ros2 service call's lines (WAITING_LINE if the service is not there at
        once, then say(), once it is, before the request goes)."""
        client = self.node.create_client(srv_class, service)
        try:
            if say is not None and not client.service_is_ready():
                print(WAITING_LINE, flush=True)
            if not client.wait_for_service(timeout_sec=seconds):
                # A client of another type never finds it: that is not "no service". (The
                # graph lists this client's own type under the name too.)
                wanted = _type_name(srv_class)
                served = [kind for kind in self.services().get(service, ()) if kind != wanted]
                if served:
                    raise CliError(f'{service} is a {", ".join(served)} service, not '
                                   f'{wanted}')
                raise CliError(f'no service {service} on ROS domain {self.domain} (the '
                               'services: python -m miro_ball.ros2 service list)')
            if say is not None:
                say()
            future = client.call_async(request)
            rclpy.spin_until_future_complete(self.node, future, timeout_sec=seconds)
            if not future.done():
                raise CliError(f'{service} did not answer within {seconds:g} s')
            return future.result()
        finally:
            self.node.destroy_client(client)


def _type_name(srv_class):
    """'package/srv/Name' of a service class."""
    return f'{srv_class.__module__.split(".")[0]}/srv/{srv_class.__name__}'


def _join(namespace, name):
    return f'{namespace.rstrip("/")}/{name}'
