"""The GUI's message checks and readout units, without ROS or a browser."""
import json
import math
import random

import pytest

from miro_ball.gui import protocol as p
from miro_ball.gui import readouts as r
from miro_ball.gui.server import is_loopback, origin_allowed
from miro_ball.miro.constants import (DOWNSTREAM_FLAG_DISABLE_CLIFF_REFLEX, JOINT_LIMITS_RAD,
                                      TILT_RAD, WHEEL_MAX_SPEED_M_PER_S)
from miro_ball.miro.interface import RobotTopics, SimTopics, robots_in
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
    'x' * (p.MAX_TEXT_CHARS + 1),
])
def test_malformed_messages_are_rejected_with_a_one_line_reason(text):
    with pytest.raises(p.Rejected) as err:
        p.parse(text)
    assert '\n' not in str(err.value) and len(str(err.value)) < 200


def test_any_garbage_is_rejected_or_gives_values_within_miros_ranges():
    rng = random.Random(8)
    atoms = [0, 1, -1, 0.5, 1e308, -1e308, 1e-320, 'x', None, True, [], {}, [1] * 6,
             2 ** 64, -(2 ** 64)]
    for _ in range(3000):
        kind = rng.choice(list(p.KINDS) + ['bogus'])
        keys = list(p.KINDS.get(kind, ((), None))[0]) + ['t', 'junk']
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


def test_readouts_in_the_mdk_guis_units():
    assert r.sonar_text(0.0) == 'short' and r.sonar_text(math.inf) == 'inf'
    assert r.sonar_text(0.456) == '0.46m' and r.sonar_text(math.nan) == '-'
    x, y, z, magnitude = r.accel([0.0, 0.0, 9.81])
    assert (x, y, z) == (0.0, 0.0, pytest.approx(50.0)) and magnitude == pytest.approx(50.0)
    assert r.cliff([1.0, 0.0]) == [15.0, 0.0]
    assert r.wheels_mm_s([0.4, -0.1]) == [400.0, -100.0]
    assert r.head_degrees([TILT_RAD, math.radians(34), 0.0, math.radians(-10)]) == \
        pytest.approx([34.0, 0.0, -10.0])
    assert r.yaw_of(math.sin(0.5), math.cos(0.5)) == pytest.approx(1.0)
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
