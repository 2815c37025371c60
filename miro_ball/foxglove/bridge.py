"""The ROS graph as Foxglove sees it: every topic a channel of the Foxglove SDK's WebSocket
server (ros2msg schema, CDR data, so the app decodes them as it decodes a ROS 2 bag).

A topic is subscribed to in ROS only while some Foxglove client subscribes to its channel:
with nobody watching, the bridge reads nothing, and the simulator draws no eye for it. The
server calls the listener from its own threads; those calls only queue work, which the
node's timer does in the ROS thread (rclpy's entities are made and destroyed there).

Messages are stamped with simulated time (the latest /clock) when a simulator runs, and the
server tells clients that time, so Foxglove's timeline is the world's.

Who may connect is the gate's rule (gate.py: the Foxglove app and pages of this machine);
with allow_publish a client may publish on each robot's control topics only (a teleop's),
never on the simulator's own (/miro_sim/sound, set_pose) nor anything else.
"""
import fnmatch
import queue

import foxglove
from foxglove.websocket import Capability, ServerListener
from rclpy.node import Node
from rclpy.serialization import deserialize_message
from rosgraph_msgs.msg import Clock

from miro_ball.common.definitions import ros2msg
from miro_ball.common.messages import message_class
from miro_ball.common.qos import matching, profile
from miro_ball.common.throttle import Throttled
from miro_ball.foxglove.gate import hidden_address, OriginGate
from miro_ball.miro.interface import CLOCK, CLOCK_QOS, is_control_topic

NODE_NAME = 'miro_foxglove'
DISCOVERY_PERIOD_S = 1.0  # wall seconds between looks for new topics
WORK_PERIOD_S = 0.02  # how soon a client's subscribe reaches ROS
MAX_QUEUED = 1000  # client requests waiting for the ROS thread (a flood is dropped)
# ROS publishers made for clients' channels, all clients together: a teleop needs a few, and
# a client that advertised thousands and left (its unadvertisements lost in a flood) kept
# every one of them.
MAX_CLIENT_CHANNELS = 32


class Listener(ServerListener):
    """The server's callbacks: each queues (verb, argument) for the ROS thread."""

    def __init__(self, work, warn):
        self.work = work
        self.warn = warn

    def _put(self, item):
        try:
            self.work.put_nowait(item)
        except queue.Full:
            self.warn('flood', 'Foxglove clients send more than can be handled: dropped')

    def on_subscribe(self, client, channel):
        self._put(('subscribe', channel.topic))

    def on_unsubscribe(self, client, channel):
        self._put(('unsubscribe', channel.topic))

    def on_client_advertise(self, client, channel):
        self._put(('advertise', (client.id, channel.id, channel.topic, channel.schema_name,
                                 channel.encoding)))

    def on_client_unadvertise(self, client, client_channel_id):
        self._put(('unadvertise', (client.id, client_channel_id)))

    def on_message_data(self, client, client_channel_id, data):
        self._put(('publish', (client.id, client_channel_id, bytes(data))))


class FoxgloveBridge(Node):
    """See the module docstring. allow_publish: clients may publish on the robots' control
    topics (their advertised channels become ROS publishers); topics: fnmatch patterns of
    what to offer (all); origins: fnmatch patterns of the web pages let in besides the
    Foxglove app and this machine's (gate.py). OSError when the port is taken."""

    def __init__(self, host, port, allow_publish=False, topics=('*',), context=None,
                 origins=()):
        super().__init__(NODE_NAME, context=context)
        self.patterns = tuple(topics)
        self.allow_publish = allow_publish
        self.channels = {}  # topic -> foxglove.Channel
        self.watchers = {}  # topic -> (subscription, how many client subscriptions)
        self.client_publishers = {}  # (client id, client channel id) -> (ROS publisher, topic)
        self.sim_ns = None  # the latest /clock
        self.work = queue.Queue(MAX_QUEUED)
        self._warn = Throttled(self.get_logger().warning)
        capabilities = [Capability.Time] + ([Capability.ClientPublish] if allow_publish else [])
        hidden = hidden_address()
        self.server = foxglove.start_server(
            name='miro_ball', host=hidden, port=0, capabilities=capabilities,
            server_listener=Listener(self.work, self._warn),
            supported_encodings=['cdr'] if allow_publish else None)
        try:
            self.gate = OriginGate(host, port, (hidden, self.server.port), origins, self._warn)
        except OSError:
            self.server.stop()
            raise
        self.port = self.gate.port
        self.create_subscription(Clock, CLOCK, self._on_clock, profile(CLOCK_QOS))
        self.create_timer(DISCOVERY_PERIOD_S, self.discover)
        self.create_timer(WORK_PERIOD_S, self.do_work)
        self.discover()

    def close(self):
        self.gate.close()
        self.server.stop()
        for channel in self.channels.values():
            channel.close()

    def _on_clock(self, msg):
        self.sim_ns = msg.clock.sec * 10**9 + msg.clock.nanosec
        self.server.broadcast_time(self.sim_ns)

    def offered(self, topic):
        return any(fnmatch.fnmatchcase(topic, p) for p in self.patterns)

    def discover(self):
        """A channel for every topic of the graph that has a publisher and a known type."""
        for topic, types in self.get_topic_names_and_types():
            if topic in self.channels or not self.offered(topic) \
                    or not self.count_publishers(topic):
                continue
            try:
                schema = ros2msg(types[0])
            except KeyError:
                self._warn(f'type:{types[0]}', f'{topic}: type {types[0]} unknown to the '
                           'bridge: not offered')
                continue
            self.channels[topic] = foxglove.Channel(
                topic, message_encoding='cdr',
                schema=foxglove.Schema(name=types[0], encoding='ros2msg',
                                       data=schema.encode()))

    def do_work(self):
        while True:
            try:
                verb, argument = self.work.get_nowait()
            except queue.Empty:
                return
            getattr(self, f'_{verb}')(argument)

    def _subscribe(self, topic):
        if topic in self.watchers:
            sub, count = self.watchers[topic]
            self.watchers[topic] = (sub, count + 1)
            return
        infos = self.get_publishers_info_by_topic(topic)
        if not infos:
            return
        channel = self.channels[topic]
        sub = self.create_subscription(
            message_class(infos[0].topic_type), topic,
            lambda data: channel.log(data, log_time=self.sim_ns), matching(infos), raw=True)
        self.watchers[topic] = (sub, 1)
        self.get_logger().info(f'a Foxglove client watches {topic}')

    def _unsubscribe(self, topic):
        if topic not in self.watchers:
            return
        sub, count = self.watchers[topic]
        if count > 1:
            self.watchers[topic] = (sub, count - 1)
            return
        self.destroy_subscription(sub)
        del self.watchers[topic]

    def _advertise(self, argument):
        client, channel_id, topic, type_name, encoding = argument
        if not self.allow_publish:
            return
        if not is_control_topic(topic):
            self._warn('advertise_topic', f'a Foxglove client may not publish on {topic[:100]!r}: '
                       "only a robot's control topics (/<robot>/control/...) are open to it")
            return
        try:
            msg_class = message_class(type_name)
        except ValueError:
            self._warn('advertise', f'a Foxglove client offers {topic} as {type_name!r}, '
                       'not a ROS 2 type here: ignored')
            return
        if encoding != 'cdr':
            self._warn('advertise', f'a Foxglove client offers {topic} in {encoding!r}, '
                       'not cdr: ignored')
            return
        self._unadvertise((client, channel_id))  # advertised again: the old one goes
        if len(self.client_publishers) >= MAX_CLIENT_CHANNELS:
            self._warn('advertise_many', f'Foxglove clients publish on {MAX_CLIENT_CHANNELS} '
                       f'channels already: {topic} refused')
            return
        self.client_publishers[client, channel_id] = (
            self.create_publisher(msg_class, topic, 10), topic, msg_class)

    def _unadvertise(self, argument):
        publisher = self.client_publishers.pop(argument, None)
        if publisher is not None:
            self.destroy_publisher(publisher[0])

    def _publish(self, argument):
        client, channel_id, data = argument
        advertised = self.client_publishers.get((client, channel_id))
        if advertised is None:
            return
        publisher, topic, msg_class = advertised
        # Decoded here, so that bytes that are no such message never reach a subscriber.
        try:
            msg = deserialize_message(data, msg_class)
        except Exception as err:  # rclpy's error for undecodable bytes has no public class
            self._warn('publish', f'a Foxglove message on {topic} is not a CDR '
                       f'{msg_class.__name__}: dropped ({type(err).__name__})')
            return
        publisher.publish(msg)
