"""python -m miro_ball.foxglove: a client of Foxglove's WebSocket protocol (what the app does:
serverInfo, advertise, subscribe, binary message data) sees the robot's topics with their
ROS 2 schemas and gets CDR data for what it subscribes to, and only then does ROS read it."""
import json
import struct

import pytest
from nav_msgs.msg import Odometry
from geometry_msgs.msg import TwistStamped
from rclpy.serialization import deserialize_message, serialize_message
from tf2_msgs.msg import TFMessage
from websockets.sync.client import connect

from miro_ball.foxglove.bridge import FoxgloveBridge
from miro_ball.miro.interface import default_robot_name, RobotTopics, TF, TF_STATIC
from rostools import advance_ticks

T = RobotTopics(default_robot_name())
MESSAGE_DATA = 1  # the binary opcode of a message on a subscription


@pytest.fixture(params=[False])
def bridge(request, ros_context, executor):
    node = FoxgloveBridge('127.0.0.1', 0, allow_publish=request.param, context=ros_context)
    executor.add_node(node)
    yield node
    executor.remove_node(node)
    node.close()
    node.destroy_node()


def client(bridge):
    """A connection as the app makes it. After a client has advertised, the SDK's server does
    not answer the closing handshake (0.30.3): a short close timeout, not websockets' 10 s."""
    return connect(f'ws://127.0.0.1:{bridge.port}', subprotocols=['foxglove.sdk.v1'],
                   close_timeout=0.5)


def receive(ws, paused_sim, executor, until, ticks=500):
    """Step the world, collecting what the server sends, until until(texts, frames)."""
    texts, frames = [], []
    for _ in range(ticks):
        advance_ticks(paused_sim, executor)
        while True:
            try:
                message = ws.recv(timeout=0.01)
            except TimeoutError:
                break
            (frames if isinstance(message, bytes) else texts).append(message)
        if until(texts, frames):
            return texts, frames
    raise AssertionError(f'not received after {ticks} ticks: {texts[:3]}')


def channels_of(texts):
    return {c['topic']: c for text in texts for c in json.loads(text).get('channels', [])
            if json.loads(text)['op'] == 'advertise'}


def test_a_client_is_advertised_the_robots_topics_and_gets_what_it_subscribes(
        paused_sim, executor, bridge):
    eye = T.eye_compressed('caml')
    with client(bridge) as ws:
        texts, _ = receive(ws, paused_sim, executor,
                           lambda texts, _: {eye, T.odom, T.package, TF, TF_STATIC}
                           <= set(channels_of(texts)))
        assert json.loads(texts[0])['op'] == 'serverInfo'
        channels = channels_of(texts)
        odom = channels[T.odom]
        assert (odom['encoding'], odom['schemaName'], odom['schemaEncoding']) == \
            ('cdr', 'nav_msgs/msg/Odometry', 'ros2msg')
        assert 'geometry_msgs/PoseWithCovariance pose' in odom['schema']
        assert channels[T.package]['schemaName'] == 'miro2_msg/msg/SensorsPackage'
        # Nobody watches yet: the bridge reads nothing, and no eye is drawn for it.
        eye_pub = paused_sim.robots[T.name].pub_eyes['caml'][0]
        assert eye_pub.get_subscription_count() == 0 and not bridge.watchers
        ws.send(json.dumps({'op': 'subscribe', 'subscriptions': [
            {'id': 1, 'channelId': odom['id']}, {'id': 2, 'channelId': channels[eye]['id']},
            {'id': 3, 'channelId': channels[TF_STATIC]['id']}]}))

        def data(frames, subscription):
            return [f for f in frames if f[0] == MESSAGE_DATA
                    and struct.unpack_from('<I', f, 1)[0] == subscription]

        _, frames = receive(ws, paused_sim, executor,
                            lambda _, frames: len(data(frames, 1)) >= 3 and data(frames, 2)
                            and data(frames, 3))
        assert eye_pub.get_subscription_count() == 1  # drawn now, for the client
        frame = data(frames, 1)[-1]
        log_time = struct.unpack_from('<Q', frame, 5)[0]
        msg = deserialize_message(frame[13:], Odometry)
        assert msg.header.frame_id == f'{T.name}/odom'
        assert log_time == pytest.approx(paused_sim.sim.time * 1e9, abs=0.1e9)  # simulated
        assert data(frames, 2)[-1][13:][4:8] != b''  # a CompressedImage's bytes
        # /tf_static went out at the start: the bridge's subscription still gets it (latched).
        static = deserialize_message(data(frames, 3)[0][13:], TFMessage)
        children = [t.child_frame_id for t in static.transforms]
        assert children[0] == f'{T.name}/odom' and f'{T.name}/caml_optical' in children
        ws.send(json.dumps({'op': 'unsubscribe', 'subscriptionIds': [2]}))
        receive(ws, paused_sim, executor, lambda *_: eye_pub.get_subscription_count() == 0)


@pytest.mark.parametrize('bridge', [True, False], indirect=True)
def test_teleop_from_foxglove_drives_miro_only_when_allowed(paused_sim, executor, bridge):
    robot = paused_sim.sim.robots[T.name]
    twist = TwistStamped()
    twist.twist.linear.x = 0.2
    with client(bridge) as ws:
        receive(ws, paused_sim, executor, lambda texts, _: T.odom in channels_of(texts))
        ws.send(json.dumps({'op': 'advertise', 'channels': [
            {'id': 5, 'topic': T.cmd_vel, 'encoding': 'cdr',
             'schemaName': 'geometry_msgs/msg/TwistStamped'}]}))
        advance_ticks(paused_sim, executor, 5)
        for garbage in (b'', b'\x00\x01', bytes(range(256)) * 40):  # dropped, with a warning
            ws.send(struct.pack('<BI', MESSAGE_DATA, 5) + garbage)
        advance_ticks(paused_sim, executor, 5)
        assert abs(robot.pose()[0]) < 0.01
        for _ in range(50):  # a teleop panel sends at its own rate
            ws.send(struct.pack('<BI', MESSAGE_DATA, 5) + serialize_message(twist))
            advance_ticks(paused_sim, executor)
    moved = robot.pose()[0]
    assert moved > 0.05 if bridge.allow_publish else abs(moved) < 0.01


def test_the_layout_in_docs_shows_topics_that_exist():
    from pathlib import Path

    from miro_ball.miro.interface import SimTopics

    layout = json.loads((Path(__file__).parent.parent / 'docs' / 'foxglove_layout.json')
                        .read_text())
    text = json.dumps(layout['configById'])
    named = {t for t in RobotTopics('miro').all() + [SimTopics().scene] if f'"{t}' in text}
    robot = RobotTopics('miro')
    assert {robot.eye_compressed('caml'), robot.eye_compressed('camr'), robot.wheel_speed_opto,
            robot.wheel_speed_cmd, SimTopics().scene} <= named
    panels = json.dumps(layout['layout'])
    assert all(panel in panels for panel in layout['configById'])


@pytest.mark.parametrize('origin, let_in', [
    (None, True),  # a program, not a page
    ('https://app.foxglove.dev', True),
    ('http://localhost:8080', True), ('http://127.0.0.1:3000', True), ('http://[::1]:5173', True),
    ('https://evil.example.com', False), ('null', False),  # a sandboxed frame of any page
    ('http://localhost.evil.example.com', False), ('https://app.foxglove.dev.evil.com', False),
    ('https://foxglove.example.org', True),  # --allow-origin's pattern below
])
def test_only_the_foxglove_app_pages_of_this_machine_and_origins_allowed_connect(
        ros_context, executor, origin, let_in):
    from websockets.exceptions import InvalidStatus

    node = FoxgloveBridge('127.0.0.1', 0, context=ros_context,
                          origins=['https://*.example.org'])
    executor.add_node(node)
    try:
        def connect_as_page():
            return connect(f'ws://127.0.0.1:{node.port}', subprotocols=['foxglove.sdk.v1'],
                           origin=origin, close_timeout=0.5, open_timeout=5)
        if let_in:
            with connect_as_page() as ws:
                assert json.loads(ws.recv(timeout=5))['op'] == 'serverInfo'
        else:
            with pytest.raises(InvalidStatus, match='403'):
                connect_as_page()
        assert node.gate.refused == (0 if let_in else 1)
    finally:
        executor.remove_node(node)
        node.close()
        node.destroy_node()


@pytest.mark.parametrize('bridge', [True], indirect=True)
def test_a_client_may_publish_on_a_robots_control_topics_only(paused_sim, executor, bridge,
                                                               capfd):
    from std_msgs.msg import String

    with client(bridge) as ws:
        receive(ws, paused_sim, executor, lambda texts, _: T.odom in channels_of(texts))
        ws.send(json.dumps({'op': 'advertise', 'channels': [
            {'id': 7, 'topic': '/miro_sim/sound', 'encoding': 'cdr',
             'schemaName': 'std_msgs/msg/String'},
            {'id': 8, 'topic': T.cmd_vel, 'encoding': 'cdr',
             'schemaName': 'geometry_msgs/msg/TwistStamped'}]}))
        ws.send(struct.pack('<BI', MESSAGE_DATA, 7)
                + serialize_message(String(data='[[sound]]\ntone = 440\n')))
        advance_ticks(paused_sim, executor, 10)
    assert [topic for _, topic, _ in bridge.client_publishers.values()] == [T.cmd_vel]
    assert not paused_sim.sim.acoustics.sounds
    assert "may not publish on '/miro_sim/sound'" in capfd.readouterr().err


def test_the_control_topics_are_each_robots_and_nothing_else():
    from miro_ball.miro.interface import is_control_topic

    assert is_control_topic(T.cmd_vel) and is_control_topic('/miro02/control/illum')
    for topic in ('/miro_sim/sound', '/miro_sim/set_pose', f'/{T.name}/sensors/odom',
                  f'/{T.name}/control/cmd_vel/x', '/a/b/control/cmd_vel', 'control/cmd_vel',
                  '/1x/control/cmd_vel', None):
        assert not is_control_topic(topic), topic


@pytest.mark.parametrize('bridge', [True], indirect=True)
def test_a_type_name_runs_no_code_and_a_flood_of_channels_is_bounded(paused_sim, executor,
                                                                     bridge, capfd):
    """'venv/__main__/X' as a type imported venv's main, whose SystemExit ended the bridge;
    2000 advertised channels kept 2000 ROS publishers."""
    from miro_ball.foxglove.bridge import MAX_CLIENT_CHANNELS

    with client(bridge) as ws:
        receive(ws, paused_sim, executor, lambda texts, _: T.odom in channels_of(texts))
        ws.send(json.dumps({'op': 'advertise', 'channels': [
            {'id': 1, 'topic': T.cmd_vel, 'encoding': 'cdr', 'schemaName': name}
            for name in ('venv/__main__/X', 'venv/msg/X', 'os/msg/X')]}))
        ws.send(json.dumps({'op': 'advertise', 'channels': [
            {'id': 10 + k, 'topic': T.cmd_vel, 'encoding': 'cdr',
             'schemaName': 'geometry_msgs/msg/TwistStamped'} for k in range(200)]}))
        advance_ticks(paused_sim, executor, 10)
    assert len(bridge.client_publishers) == MAX_CLIENT_CHANNELS
    err = capfd.readouterr().err
    assert "as 'venv/__main__/X', not a ROS 2 type here" in err and 'channels already' in err


def test_a_request_that_is_no_websocket_is_answered_by_the_gate(bridge):
    import socket

    for request in (b'GET / HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n',
                    b'GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nOrigin: https://evil.example.com\r\n'
                    b'\r\n'):
        with socket.create_connection(('127.0.0.1', bridge.port), timeout=5) as sock:
            sock.sendall(request)
            assert sock.recv(100).startswith(b'HTTP/1.1 400 ')
    assert bridge.gate.refused == 0  # not a page's WebSocket: nothing to warn of


@pytest.mark.parametrize('offered', [['foxglove.websocket.v1'], None])
def test_a_client_of_another_subprotocol_is_told_which_one_is_served(bridge, offered, capfd):
    """The SDK's server answered 400 'Missing expected sec-websocket-protocol header' and
    logged 'Dropping client ...: handshake failed', naming neither."""
    from websockets.exceptions import InvalidStatus

    with pytest.raises(InvalidStatus, match='400') as refused:
        connect(f'ws://127.0.0.1:{bridge.port}', subprotocols=offered, close_timeout=0.5,
                open_timeout=5)
    body = bytes(refused.value.response.body).decode()
    err = capfd.readouterr().err
    for said in (body, err):
        assert "serves 'foxglove.sdk.v1' only" in said
        assert ("'foxglove.websocket.v1'" if offered else 'offered no subprotocol') in said
    assert 'handshake failed' not in err
