"""The GUI's message checks, readout units and web server, without ROS or a browser."""
import asyncio
import contextlib
import json
import math
import random
import time
import types

import aiohttp
import pytest

from miro_ball.gui import protocol as p
from miro_ball.gui import readouts as r
from miro_ball.gui import server as web_server
from miro_ball.gui.scene import SceneState
from miro_ball.gui.server import GuiServer, is_loopback, listen, origin_allowed, serve, url
from miro_ball.miro.camera_model import CameraModel
from miro_ball.miro.constants import (DOWNSTREAM_FLAG_DISABLE_CLIFF_REFLEX, JOINT_LIMITS_RAD,
                                      TILT_RAD, WHEEL_MAX_SPEED_M_PER_S)
from miro_ball.miro.interface import BALL_NAME, RobotTopics, SimTopics, robots_in
from miro_ball.miro.kinematics import cmd_vel2wheel_speed


def parse(message):
    return p.parse(json.dumps(message))


def test_a_drive_within_range_is_passed_on_unchanged():
    command, clamped = parse({'t': 'drive', 'linear': 0.2, 'angular': -1.0})
    assert command == p.Drive(0.2, -1.0) and clamped == []


@pytest.mark.parametrize('linear, angular', [(9.0, 0.0), (-1e300, 0.0), (0.4, 5.0), (0.0, -99.0),
                                             (0.3, 2.0)])
def test_a_drive_out_of_range_is_clamped_to_what_the_wheels_can_do(linear, angular):
    command, clamped = parse({'t': 'drive', 'linear': linear, 'angular': angular})
    assert clamped
    left, right = cmd_vel2wheel_speed(command.linear, command.angular)
    assert max(abs(left), abs(right)) <= WHEEL_MAX_SPEED_M_PER_S + 1e-9
    assert abs(command.angular) <= p.MAX_TURN_RAD_S
    assert math.copysign(1, command.linear) == math.copysign(1, linear) or command.linear == 0


def test_head_degrees_become_radians_clamped_to_the_joint_limits_with_tilt_fixed():
    command, clamped = parse({'t': 'head', 'lift': 500, 'yaw': -10, 'pitch': -1e9})
    tilt, lift, yaw, pitch = command.positions
    assert tilt == TILT_RAD
    assert lift == JOINT_LIMITS_RAD[1][1] and pitch == JOINT_LIMITS_RAD[3][0]
    assert yaw == pytest.approx(math.radians(-10))
    assert sorted(clamped) == ['lift', 'pitch']


def test_the_other_controls():
    assert parse({'t': 'cosmetic', 'values': [0, 1, 0.5, 2, -1, 0.3]})[0].values == \
        (0, 1, 0.5, 1.0, 0.0, 0.3)
    assert parse({'t': 'illum', 'leds': [0xFF0000FF, 0, 1, 2, 3, 2 ** 40]})[0].leds[5] == \
        p.ARGB_MAX
    assert parse({'t': 'tone', 'values': [50, 100, 300]})[0].values == (200, 100, 255)
    assert parse({'t': 'flags', 'cliff_reflex': False})[0].data == \
        DOWNSTREAM_FLAG_DISABLE_CLIFF_REFLEX
    assert parse({'t': 'flags', 'cliff_reflex': True})[0].data == 0
    assert parse({'t': 'sim', 'action': 'reset'})[0] == p.SimAction('reset')
    assert parse({'t': 'robot', 'name': 'miro02'})[0] == p.SelectRobot('miro02')
    assert parse({'t': 'ack', 'ch': 1})[0] == p.Ack(1)
    assert parse({'t': 'stop'})[0] == p.Stop()


def test_the_world_views_messages():
    assert parse({'t': 'view', 'channels': ['caml', 'overhead'], 'world': True})[0] == \
        p.View(frozenset({'caml', 'overhead'}), True)
    assert parse({'t': 'view', 'channels': [], 'world': False})[0] == p.View(frozenset(), False)
    assert parse({'t': 'place', 'name': BALL_NAME, 'x': 1, 'y': -0.5})[0] == \
        p.Place(BALL_NAME, 1.0, -0.5)
    assert parse({'t': 'place', 'name': BALL_NAME, 'x': 1e9, 'y': 0})[0].x == p.MAX_PLACE_M
    assert parse({'t': 'touch', 'part': 'head', 'u': 0.25, 'v': 1.5}) == \
        (p.Touch('head', 0.25, 1.0), ['v'])
    assert parse({'t': 'rtf', 'value': 0})[0] == p.SetRtf(0.0)
    assert parse({'t': 'rtf', 'value': 5000})[0] == p.SetRtf(p.MAX_RTF)
    assert parse({'t': 'hear', 'mic': 3, 'listen': True, 'shown': True})[0] == \
        p.Hear(3, True, True)
    assert parse({'t': 'sound', 'x': 1, 'y': 2, 'kind': 'tone'})[0] == p.PlaceSound(1.0, 2.0, 'tone')
    assert parse({'t': 'unsound', 'name': 'gui_sound1'})[0] == p.StopSound('gui_sound1')
    assert parse({'t': 'demo', 'shown': True})[0] == p.Demo(True)
    assert parse({'t': 'demo_run', 'run': False})[0] == p.DemoRun(False)


@pytest.mark.parametrize('text', [
    'not json', '[]', '"drive"', 'null', '{}', '{"t": "launch_missiles"}',
    '{"t": "drive", "linear": "fast", "angular": 0}',
    '{"t": "drive", "linear": true, "angular": 0}',
    '{"t": "drive", "linear": NaN, "angular": 0}',
    '{"t": "drive", "linear": Infinity, "angular": 0}',
    '{"t": "drive", "linear": 1e999, "angular": 0}',
    '{"t": "drive", "linear": 0.1}',
    '{"t": "drive", "linear": 0.1, "angular": 0, "extra": 1}',
    '{"t": "head", "lift": 30, "yaw": 0, "pitch": null}',
    '{"t": "cosmetic", "values": [0, 0, 0]}',
    '{"t": "illum", "leds": [0.5, 0, 0, 0, 0, 0]}',
    '{"t": "tone", "values": "loud"}',
    '{"t": "flags", "cliff_reflex": 0}',
    '{"t": "sim", "action": "explode"}',
    '{"t": "robot", "name": "../etc"}',
    '{"t": "ack", "ch": 99}',
    '[' * 100000,
    'x' * (p.MAX_TEXT_BYTES + 1),
    # Found by a held-out attack: each dropped the page's connection with a traceback.
    '{"t": []}', '{"t": {}}', '{"t": 5}', '{"t": null}',
    '{"t": "drive", "linear": ' + '9' * 400 + ', "angular": 0}',
    '{"t": "illum", "leds": [' + '1' * 400 + ', 0, 0, 0, 0, 0]}',
    '{"t": "ack", "ch": -' + '9' * 400 + '}',
    '{"t": "drive", "linear": ' + '9' * 5000 + ', "angular": 0}',  # beyond int()'s digits
    '{"t": "robot", "name": "' + '\u00e9' * 3000 + '"}',  # 3,000 characters, 6 KB
    '{"t": "view", "channels": ["caml", "eyes"], "world": true}',
    '{"t": "view", "channels": "caml", "world": true}',
    '{"t": "view", "channels": [["caml"]], "world": true}',
    '{"t": "view", "channels": [], "world": 1}',
    '{"t": "place", "name": "ball", "x": 0}',
    '{"t": "place", "name": "../ball", "x": 0, "y": 0}',
    '{"t": "touch", "part": "tail", "u": 0, "v": 0}',
    '{"t": "touch", "part": ["head"], "u": 0, "v": 0}',
    '{"t": "rtf", "value": NaN}',
    '{"t": "hear", "mic": 4, "listen": true, "shown": true}',
    '{"t": "hear", "mic": 0, "listen": 1, "shown": true}',
    '{"t": "hear", "mic": 0.5, "listen": false, "shown": true}',
    '{"t": "hear", "mic": 0, "listen": false}',
    '{"t": "sound", "x": 0, "y": 0, "kind": "bang"}', '{"t": "sound", "x": 0, "y": NaN, "kind": "tone"}',
    '{"t": "unsound", "name": "\\n[[sound]]"}',
    '{"t": "demo", "shown": 1}', '{"t": "demo_run", "run": "yes"}', '{"t": "demo_run"}',
    '{"t": "demo", "shown": true, "robot": "miro"}',
])
def test_malformed_messages_are_rejected_with_a_one_line_reason(text):
    with pytest.raises(p.Rejected) as err:
        p.parse(text)
    assert '\n' not in str(err.value) and len(str(err.value)) < 200


def test_any_garbage_is_rejected_or_gives_values_within_miros_ranges():
    rng = random.Random(8)
    atoms = [0, 1, -1, 0.5, 1e308, -1e308, 1e-320, 'x', None, True, [], {}, [1] * 6,
             2 ** 64, -(2 ** 64), 10 ** 400, -(10 ** 400), 'head', 'caml', ['caml'], BALL_NAME]
    for _ in range(5000):
        kind = rng.choice(list(p.KINDS) + ['bogus', [], {}, 3, None])
        keys = list(p.KINDS.get(kind, ((), None))[0]) if isinstance(kind, str) else []
        keys += ['t', 'junk']
        message = {key: rng.choice(atoms) for key in rng.sample(keys, rng.randint(0, len(keys)))}
        message['t'] = kind
        try:
            command, _ = p.parse(json.dumps(message))
        except p.Rejected:
            continue
        if isinstance(command, p.Drive):
            wheels = cmd_vel2wheel_speed(command.linear, command.angular)
            assert max(map(abs, wheels)) <= WHEEL_MAX_SPEED_M_PER_S + 1e-9
        if isinstance(command, p.Head):
            assert all(lo <= v <= hi for v, (lo, hi) in zip(command.positions, JOINT_LIMITS_RAD))
        if isinstance(command, p.Cosmetic):
            assert all(0 <= v <= 1 for v in command.values)


def test_a_frame_message_is_its_header_then_the_jpeg_unchanged():
    jpeg = b'\xff\xd8 some jpeg \xff\xd9'
    message = p.frame_message(1, 12.34, jpeg)
    assert p.FRAME_HEADER.unpack_from(message) == (1, 12.34)
    assert message[p.FRAME_HEADER.size:] == jpeg


def test_the_page_gets_miros_ranges_from_the_constants():
    config = p.page_config()
    assert config['head']['lift'] == [8.0, 60.0] and config['max_linear'] == 0.4
    assert json.loads(json.dumps(config))['channels'][0] == 'caml'
    assert config['touch'] == {'rows': 2, 'columns': 7}
    assert config['battery_marks'] == [4.6, 4.8]  # the MDK GUI's low and high


def test_a_tone_goes_to_the_page_as_the_mdk_says_it():
    assert json.loads(p.tone_message([440, 100, 50])) == \
        {'t': 'tone', 'hz': 440, 'volume': 100, 'ticks': 50}


@pytest.mark.parametrize('lens, expected', [('pinhole', (120.0, 88.5)), ('miro', (121.2, 63.6))])
def test_the_eyes_field_of_view_is_read_from_camera_info(lens, expected):
    camera = CameraModel(640, 360, lens=lens)
    info = types.SimpleNamespace(**camera.camera_info_fields())
    assert r.eye_fov_deg(CameraModel.from_camera_info(info)) == \
        pytest.approx(expected, abs=0.1)


def test_readouts_in_the_mdk_guis_units():
    assert r.sonar_text(0.0) == 'short' and r.sonar_text(math.inf) == 'inf'
    assert r.sonar_text(0.456) == '0.46m' and r.sonar_text(math.nan) == '-'
    x, y, z, magnitude = r.accel([0.0, 0.0, 9.81])
    assert (x, y, z) == (0.0, 0.0, pytest.approx(50.0)) and magnitude == pytest.approx(50.0)
    assert r.cliff([1.0, 0.0]) == [15.0, 0.0]
    assert r.wheels_mm_s([0.4, -0.1]) == [400.0, -100.0]
    assert r.head_degrees([TILT_RAD, math.radians(34), 0.0, math.radians(-10)]) == \
        pytest.approx([34.0, 0.0, -10.0])
    assert r.jsonable({'a': [1.0, math.inf], 'b': math.nan, 'c': 'x'}) == \
        {'a': [1.0, None], 'b': None, 'c': 'x'}


@pytest.mark.parametrize('origin, host, loopback_only, allowed', [
    (None, '127.0.0.1:8080', True, True),  # not a browser
    ('http://127.0.0.1:8080', '127.0.0.1:8080', True, True),
    ('http://localhost:8080', 'localhost:8080', True, True),
    ('http://[::1]:8080', '[::1]:8080', True, True),
    ('http://evil.example', '127.0.0.1:8080', True, False),
    ('http://127.0.0.1:9999', '127.0.0.1:8080', True, False),  # another local site
    ('http://evil.example:8080', 'evil.example:8080', True, False),  # DNS rebinding
    ('null', '127.0.0.1:8080', True, False),
    ('http://robot.lab:8080', 'robot.lab:8080', False, True),  # --host 0.0.0.0
    ('http://evil.example', 'robot.lab:8080', False, False),
])
def test_only_the_pages_own_origin_may_open_a_websocket(origin, host, loopback_only, allowed):
    assert origin_allowed(origin, host, loopback_only) is allowed


def test_loopback_addresses():
    assert is_loopback('127.0.0.1') and is_loopback('::1') and is_loopback('localhost')
    assert not is_loopback('0.0.0.0') and not is_loopback('192.168.1.2')


def test_robots_are_found_by_their_odometry_topic():
    graph = [RobotTopics('miro02').odom, RobotTopics('miro02').cmd_vel, RobotTopics('a1').odom,
             SimTopics().object_pose('ball'), '/clock', '/x/y/sensors/odom', '/9x/sensors/odom',
             '/sensors/odom', 'miro/sensors/odom']
    assert robots_in(graph) == ['a1', 'miro02']


# -- the web server, on a real socket, with a stand-in for the bridge ---------------------------
class FakeBridge:
    """What the web server asks of the bridge, recorded."""

    def __init__(self):
        self.commands = []
        self.scene = SceneState()
        self.shown = {}  # channel: Frame
        self.overlays = {}  # channel: (stamp, overlay) paired with its frame

    def open(self, owner):
        self.commands.append(('open', owner))

    def submit(self, command, owner):
        self.commands.append((command, owner))

    def release(self, owner):
        self.commands.append(('release', owner))

    def frames(self, owner):
        return dict(self.shown)

    def overlay(self, owner, channel, frame):
        return self.overlays.get(channel)

    def state(self, owner):
        return json.dumps({'t': 'state', 'robot': None})

    def scene_message(self, since):
        return self.scene.scene_message(since), self.scene.seq

    def tf_message(self, since):
        return self.scene.tf_message(since), self.scene.seq

    def texture(self, key):
        return self.scene.textures.get(key)

    def got(self, kind):
        return [command for command, _ in self.commands if isinstance(command, kind)]


@contextlib.asynccontextmanager
async def web_gui(bridge):
    """(server, its URL, the warnings it gave) while it serves on a free port."""
    warnings = []
    server = GuiServer(bridge, log=lambda line: None, warn=warnings.append)
    sock = listen('127.0.0.1', 0)
    stop = types.SimpleNamespace(requested=False)
    serving = asyncio.create_task(serve(server, sock, stop))
    try:
        yield server, url(sock), warnings
    finally:
        stop.requested = True
        await serving


async def until(predicate, timeout_s=5.0):
    """Let the server work until predicate() holds (the limit only guards against a hang)."""
    deadline = time.monotonic() + timeout_s
    while not predicate():
        assert time.monotonic() < deadline, 'timed out'
        await asyncio.sleep(0.005)


async def next_of_kind(ws, kind, timeout_s=5.0):
    deadline = time.monotonic() + timeout_s
    while True:
        msg = await ws.receive(timeout=max(0.01, deadline - time.monotonic()))
        if msg.type == aiohttp.WSMsgType.TEXT and json.loads(msg.data).get('t') == kind:
            return json.loads(msg.data)
        assert msg.type in (aiohttp.WSMsgType.TEXT, aiohttp.WSMsgType.BINARY), msg


def test_bad_messages_are_ignored_and_the_page_stays_connected():
    async def run():
        bridge = FakeBridge()
        async with web_gui(bridge) as (server, address, warnings), \
                aiohttp.ClientSession() as session, \
                session.ws_connect(address + 'ws') as ws:
            assert (await next_of_kind(ws, 'config'))['t'] == 'config'
            for text in ('{"t": []}', '{"t": "drive", "linear": ' + '9' * 400 + ', "angular": 0}',
                         '{"t": "robot", "name": "' + '\U0001F600' * 3000 + '"}') * 50:
                await ws.send_str(text)
            await ws.send_str('{"t": "stop"}')
            await until(lambda: bridge.got(p.Stop))
            assert not ws.closed and bridge.commands[0] == ('open', 1)
            assert len(bridge.commands) == 2  # nothing of the bad ones reached the bridge
            # Throttled: a line for each of the three causes, not 150.
            assert len(warnings) == 3 and all('ignored' in line for line in warnings)
    asyncio.run(run())


def test_a_binary_or_oversized_message_is_said_for_what_it_is():
    async def run():
        async with web_gui(FakeBridge()) as (server, address, warnings), \
                aiohttp.ClientSession() as session:
            async with session.ws_connect(address + 'ws') as ws:
                await ws.send_bytes(b'\x00\x01')
                await until(lambda: warnings)
            async with session.ws_connect(address + 'ws') as ws:
                await ws.send_str('{"t": "stop", "x": "' + 'a' * web_server.MAX_MESSAGE_BYTES + '"}')
                await until(lambda: len(warnings) == 2)
            return warnings
    binary, oversized = asyncio.run(run())
    assert 'a binary message ignored' in binary
    assert 'its socket is closed' in oversized and f'at most {web_server.MAX_MESSAGE_BYTES} ' \
        'bytes' in oversized and 'non-text' not in oversized


def test_bad_http_requests_cost_one_warning_and_no_traceback(capfd, caplog):
    bad = (b'GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nno colon in this header\r\n\r\n',
           b'GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nX: ' + b'a' * 20000 + b'\r\n\r\n',
           b'GET /\x00 HTTP/1.1\r\n\r\n', b'GET / HTTP/9.9\r\n\r\n')

    async def bad_request(address, i):
        host, port = address.split('//')[1].strip('/').split(':')
        reader, writer = await asyncio.open_connection(host, int(port))
        writer.write(bad[i % len(bad)])
        await writer.drain()
        answer = await reader.read()
        writer.close()
        return answer

    async def run():
        async with web_gui(FakeBridge()) as (server, address, warnings):
            answers = [await bad_request(address, i) for i in range(100)]
            return answers, warnings

    with caplog.at_level('DEBUG'):
        answers, warnings = asyncio.run(run())
    assert all(answer.split(b' ')[1] == b'400' for answer in answers)
    # A line for each of the four causes, not for each of the 100 requests.
    assert len(warnings) == len(bad)
    assert not any('Traceback' in line or '\n' in line for line in warnings)
    out, err = capfd.readouterr()
    assert 'Traceback' not in out + err and 'Error handling request' not in out + err
    assert not [rec for rec in caplog.records if rec.levelname in ('WARNING', 'ERROR')]


def test_a_drag_reaches_the_simulator_at_most_30_times_a_second_the_newest_last():
    async def run():
        bridge = FakeBridge()
        async with web_gui(bridge) as (server, address, warnings), \
                aiohttp.ClientSession() as session, \
                session.ws_connect(address + 'ws') as ws:
            start = time.monotonic()
            for i in range(200):  # as fast as a mouse could never move
                await ws.send_str(json.dumps({'t': 'place', 'name': BALL_NAME, 'x': i * 0.01,
                                              'y': 0.0}))
            await until(lambda: bridge.got(p.Place) and bridge.got(p.Place)[-1].x == 1.99)
            return bridge.got(p.Place), time.monotonic() - start

    places, elapsed = asyncio.run(run())
    assert len(places) <= 2 + elapsed * web_server.PLACE_RATE_HZ
    assert places[0].x == 0.0 and places[-1] == p.Place(BALL_NAME, 1.99, 0.0)


def test_a_frames_overlay_goes_before_it_and_again_when_a_later_one_of_that_frame_comes():
    from miro_ball.gui.frames import Frame

    async def run():
        bridge = FakeBridge()
        caml = p.CHANNELS.index('caml')
        bridge.shown[caml] = Frame(seq=1, stamp=2.0, jpeg=b'jpeg')
        bridge.overlays[caml] = (2.0, {'objects': [{'kind': 'ball'}], 'view': None})
        async with web_gui(bridge) as (server, address, warnings), \
                aiohttp.ClientSession() as session, \
                session.ws_connect(address + 'ws') as ws:
            said = []
            while not said or said[-1] != 'frame':
                msg = await ws.receive(timeout=5.0)
                if msg.type == aiohttp.WSMsgType.BINARY:
                    said.append('frame')
                elif json.loads(msg.data)['t'] == 'overlay':
                    said.append(json.loads(msg.data))
            bridge.overlays[caml] = (2.04, {'objects': [], 'view': None})
            later = await next_of_kind(ws, 'overlay')
            return said, later

    said, later = asyncio.run(run())
    first, frame = said[-2:]
    assert frame == 'frame' and first == {'t': 'overlay', 'ch': 0, 'frame': 2.0, 'stamp': 2.0,
                                          'objects': [{'kind': 'ball'}], 'view': None}
    assert later == {'t': 'overlay', 'ch': 0, 'frame': 2.0, 'stamp': 2.04, 'objects': [],
                     'view': None}


def test_a_page_that_shows_the_world_gets_it_whole_then_what_moved_and_its_pictures():
    from test_gui_scene import Warnings, marker, picture, transforms  # the scene's builders

    async def run():
        bridge = FakeBridge()
        warn = Warnings()
        bridge.scene.apply_markers([marker('ball'), marker('wall', 1), picture('logo')], warn)
        bridge.scene.apply_tf(transforms(), warn)
        async with web_gui(bridge) as (server, address, warnings), \
                aiohttp.ClientSession() as session, \
                session.ws_connect(address + 'ws') as ws:
            await ws.send_str(json.dumps({'t': 'view', 'channels': [], 'world': True}))
            whole = await next_of_kind(ws, 'scene')
            frames = await next_of_kind(ws, 'tf')
            bridge.scene.apply_markers([marker('ball', xyz=(0.0, 0.0, 0.05))], warn)
            moved = await next_of_kind(ws, 'scene')
            async with session.get(address + 'texture/logo.png') as response:
                png = (response.status, response.content_type, await response.read())
            missing = []
            for path in ('texture/nothing.png', 'texture/..%2Fserver.py', 'texture/logo'):
                async with session.get(address + path) as response:
                    missing.append(response.status)
            server.event([1], p.tone_message([440, 100, 5]))
            tone = await next_of_kind(ws, 'tone')
            return whole, frames, moved, png, missing, tone

    whole, frames, moved, png, missing, tone = asyncio.run(run())
    assert {m['id'] for m in whole['markers']} == {'ball/0', 'wall/1', 'picture/3'}
    assert len(frames['frames']) == len(transforms())
    assert [m['id'] for m in moved['markers']] == ['ball/0'] and moved['removed'] == []
    assert png[:2] == (200, 'image/png') and png[2].startswith(b'\x89PNG')
    assert missing == [404, 404, 404]
    assert tone == {'t': 'tone', 'hz': 440, 'volume': 100, 'ticks': 5}


def test_a_page_that_stopped_reading_is_cut_off_as_the_server_stops():
    """A page that took nothing more (a busy browser's) held the GUI's server for ever as
    it stopped, and the GUI deaf to SIGINT and SIGTERM until ros2 launch killed it."""
    import base64
    import socket

    from miro_ball.gui.frames import Frame

    async def run():
        loop = asyncio.get_running_loop()
        bridge = FakeBridge()
        bridge.shown[0] = Frame(seq=1, stamp=1.0, jpeg=bytes(8 << 20))  # more than a socket holds
        page = socket.socket()
        page.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
        page.setblocking(False)
        async with web_gui(bridge) as (server, address, warnings):
            host, port = address.split('//')[1].strip('/').split(':')
            await loop.sock_connect(page, (host, int(port)))
            key = base64.b64encode(b'a page that reads'[:16]).decode()
            await loop.sock_sendall(page, (
                f'GET /ws HTTP/1.1\r\nHost: {host}:{port}\r\nUpgrade: websocket\r\n'
                f'Connection: Upgrade\r\nSec-WebSocket-Key: {key}\r\n'
                'Sec-WebSocket-Version: 13\r\n\r\n').encode())
            await until(lambda: any(0 in p.in_flight for p in server.pages.values()))
        # Stopped (a hang would be the guard's timeout): the page's connection is cut.
        with contextlib.suppress(ConnectionError):
            while await loop.sock_recv(page, 1 << 16):
                pass
        page.close()
        return bridge.commands

    commands = asyncio.run(asyncio.wait_for(run(), timeout=10.0))  # a hang guard only
    assert commands == [('open', 1), ('release', 1)]


def test_the_pages_hearing_levels_spectrum_and_sound():
    import base64

    import numpy as np

    from miro_ball.gui.hearing import BANDS, MAX_AUDIO_SAMPLES, MicMeter, speaker_message
    from miro_ball.miro.hearing import mic_window

    meter = MicMeter()
    meter.mic, meter.listen = 1, True
    t = np.arange(2000) / 20000
    tone = (np.sin(2 * np.pi * 2500 * t) * 3276.8).astype(np.int16)  # RMS -23 dB
    blocks = [mic_window(np.stack([np.zeros(500), tone[k:k + 500], np.zeros(500),
                                   np.zeros(500)]).astype(np.int16)) for k in range(0, 2000, 500)]
    assert [meter.add(b) for b in blocks[:3]] == [[], [], []]
    shown, heard = (json.loads(text) for text in meter.add(blocks[3]))
    assert shown['levels'][1] == pytest.approx(-23.0, abs=0.2) and shown['levels'][0] == -100
    peak = int(np.argmax(shown['spectrum']))
    assert len(shown["spectrum"]) == BANDS and peak == int((2500 / 10 - 1) / (1000 / BANDS))
    assert np.array_equal(np.frombuffer(base64.b64decode(heard['data']), '<i2'), tone)
    text, cut = speaker_message(np.ones(MAX_AUDIO_SAMPLES + 5, np.int16))
    assert cut and len(base64.b64decode(json.loads(text)['data'])) == 2 * MAX_AUDIO_SAMPLES


def test_demo_modes_topics_become_what_the_page_draws_and_garbage_is_refused():
    import base64

    from miro2_msg.msg import AnimalState, ObjectBall, ObjectFace, ObjectTag, Objects
    from sensor_msgs.msg import Image
    from std_msgs.msg import Float32MultiArray, String

    from miro_ball.animal.actions import ACTIONS
    from miro_ball.gui import demo_mode_panel

    state = AnimalState()
    state.emotion.valence, state.sleep.wakefulness = 0.5, 0.25
    assert demo_mode_panel.animal_state(state) == {'emotion': [0.5, 0.0], 'mood': [0.0, 0.0],
                                        'sleep': [0.25, 0.0]}
    state.mood.arousal = math.nan
    with pytest.raises(ValueError):
        demo_mode_panel.animal_state(state)
    assert demo_mode_panel.priorities(Float32MultiArray(data=[0.5] * len(ACTIONS))) == [0.5] * len(ACTIONS)
    for bad in ([0.5] * (len(ACTIONS) + 1), [math.inf] * len(ACTIONS)):
        with pytest.raises(ValueError):
            demo_mode_panel.priorities(Float32MultiArray(data=bad))
    assert demo_mode_panel.action(String(data='orient')) == 'orient'
    with pytest.raises(ValueError):
        demo_mode_panel.action(String(data='<script>'))
    found = Objects(balls=[ObjectBall(centre=[0.5, 0.25], radius=0.125)],
                    faces=[ObjectFace(corner=[0.25, 0.5], size=[0.125, 0.25])],
                    tags=[ObjectTag(id=3, centre=[0.75, 0.5])])
    assert demo_mode_panel.objects(found) == [
        {'kind': 'ball', 'x': 0.5, 'y': 0.25, 'r': 0.125},
        {'kind': 'face', 'x': 0.25, 'y': 0.5, 'w': 0.125, 'h': 0.25},
        {'kind': 'tag 3', 'x': 0.75, 'y': 0.5}]
    assert len(demo_mode_panel.objects(Objects(tags=[ObjectTag()] * 100))) == 20  # bounded
    view = demo_mode_panel.attention_view(Image(width=4, height=2, step=4, encoding='mono8',
                                     data=bytes(range(8))))
    assert base64.b64decode(view['data']) == bytes(range(8))
    for bad in (Image(width=4, height=2, step=4, encoding='rgb8', data=bytes(24)),
                Image(width=4, height=2, step=4, encoding='mono8', data=bytes(3)),
                Image(width=4000, height=2000, step=4000, encoding='mono8', data=bytes(10))):
        with pytest.raises(ValueError):
            demo_mode_panel.attention_view(bad)
