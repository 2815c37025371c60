"""What the page and the GUI server say to each other over the WebSocket.

Page -> server: one JSON object per text message, {"t": kind, ...}. parse() turns
it into a command with every value checked and clamped to what MiRo accepts (the
simulator's own clamps), or raises Rejected saying why in one line. Nothing here
knows about ROS or the web server, so it is tested on its own.

Server -> page: JSON text for the readouts, the scene, the tones and the sound, and images as
binary messages: a FRAME_HEADER (channel number, stamp in seconds) followed by the
JPEG bytes as the robot sent them (the browser decodes them; the server never does). Demo
mode's overlay of a frame goes before it (and again when a later one for the same frame
comes), naming the frame's stamp.
"""
import json
import math
import struct
from dataclasses import dataclass

from miro_ball.animal.actions import ACTIONS
from miro_ball.miro.constants import (COSMETIC_CALIB, DOWNSTREAM_FLAG_DISABLE_CLIFF_REFLEX,
                                      JOINT_LIMITS_RAD, LIFT, LIFT_RAD_CALIB, PITCH,
                                      PLATFORM_TICK_S, TILT_RAD, WHEEL_MAX_SPEED_M_PER_S, YAW)
from miro_ball.miro.body import MICS
from miro_ball.miro.interface import TOUCH_PARTS, check_name
from miro_ball.miro.kinematics import clamp_wheel_speeds, clamped_cmd_vel, cmd_vel2wheel_speed
from miro_ball.miro.touch import TOUCH_COLUMNS, TOUCH_ROWS

# Image channels, in the order of their numbers on the wire.
CHANNELS = ('caml', 'camr', 'overhead', 'debug_caml', 'debug_camr')
FRAME_HEADER = struct.Struct('<Bd')  # channel, stamp (s); then the JPEG
MAX_FRAME_BYTES = 4 << 20  # a 1280x720 eye at quality 100 is well under 1 MB
MAX_TEXT_BYTES = 4096  # UTF-8; the page's longest command is a few hundred characters

# The MDK GUI's slider ranges where MiRo itself has no tighter limit.
MAX_TURN_RAD_S = 5.0
TONE_HZ = (200, 2000)
TONE_VOLUME = (1, 255)
TONE_TICKS = (1, 255)
ARGB_MAX = 0xFFFFFFFF
SIM_ACTIONS = ('pause', 'resume', 'step', 'reset')
MAX_RTF = 1000.0  # the simulator's own range of real_time_factor
MAX_PLACE_M = 100.0  # farther than any world reaches: the simulator says if it is off its floor
BATTERY_MARKS_V = (4.6, 4.8)  # the MDK GUI's battery bar: low, high
SOUND_KINDS = ('noise', 'tone')  # what a click in the world view plays


class Rejected(ValueError):
    """A message that is ignored; the text says why (for a rate-limited warning)."""


@dataclass(frozen=True)
class Drive:
    linear: float  # m/s forward
    angular: float  # rad/s, counter-clockwise


@dataclass(frozen=True)
class Stop:
    pass


@dataclass(frozen=True)
class Head:
    positions: tuple  # [tilt, lift, yaw, pitch] rad, as control/kinematic_joints takes them


@dataclass(frozen=True)
class Cosmetic:
    values: tuple  # droop, wag, eyelid l/r, ear l/r in 0..1


@dataclass(frozen=True)
class Illum:
    leds: tuple  # six 0xAARRGGBB


@dataclass(frozen=True)
class Tone:
    values: tuple  # frequency Hz, volume, duration in 20 ms ticks


@dataclass(frozen=True)
class Flags:
    data: int  # control/flags


@dataclass(frozen=True)
class SimAction:
    action: str  # one of SIM_ACTIONS


@dataclass(frozen=True)
class SelectRobot:
    name: str


@dataclass(frozen=True)
class Ack:
    channel: int  # the page has drawn the last frame of this channel


@dataclass(frozen=True)
class View:
    channels: frozenset  # names of the image channels the page shows now
    world: bool  # the page shows the world view (the scene and the frames)


@dataclass(frozen=True)
class Place:
    name: str  # an object or robot of the simulator
    x: float  # m, world frame; height and orientation stay as they are
    y: float


@dataclass(frozen=True)
class Touch:
    part: str  # 'head' or 'body'
    u: float  # 0 front .. 1 back
    v: float  # 0 left .. 1 right


@dataclass(frozen=True)
class Hear:
    mic: int  # the microphone whose spectrum the page shows (MIC_L, MIC_R, MIC_C, MIC_T)
    listen: bool  # its samples to the page, to play
    shown: bool  # the page shows its Hearing panel (the microphones are read only then)


@dataclass(frozen=True)
class PlaceSound:
    x: float  # m, world frame, on the floor
    y: float
    kind: str  # one of SOUND_KINDS


@dataclass(frozen=True)
class StopSound:
    name: str  # of a sound playing


@dataclass(frozen=True)
class Demo:
    shown: bool  # the page shows its demo-mode panel (demo mode's topics are read only then)


@dataclass(frozen=True)
class DemoRun:
    run: bool  # start (true) or stop (false) demo mode for the page's robot


@dataclass(frozen=True)
class SetRtf:
    value: float  # the simulator's real_time_factor; 0 = as fast as possible


def _reject_constant(name):
    raise Rejected(f'{name} is not a number')


def _show(value):
    """A value from the page in a warning: its type and the start of it, on one line."""
    return f'{type(value).__name__} {repr(value)[:40]}'


def _number(msg, key, lo, hi, clamped):
    value = msg.get(key)
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise Rejected(f'{key} must be a number, got {_show(value)}')
    try:
        finite = math.isfinite(value)  # an integer of 400 digits is no float: OverflowError
    except OverflowError:
        finite = False
    if not finite:
        raise Rejected(f'{key} must be a finite number')
    if not lo <= value <= hi:
        clamped.append(key)
        value = min(max(value, lo), hi)
    return value


def _integer(msg, key, lo, hi, clamped):
    value = _number(msg, key, lo, hi, clamped)
    if value != int(value):
        raise Rejected(f'{key} must be an integer, got {value!r}')
    return int(value)


def _numbers(msg, key, ranges, clamped, integer=False):
    """A list with one value per (lo, hi) of ranges, each checked like _number."""
    values = msg.get(key)
    if not isinstance(values, list) or len(values) != len(ranges):
        raise Rejected(f'{key} must be a list of {len(ranges)} numbers')
    pick = _integer if integer else _number
    return tuple(pick({key: v}, key, lo, hi, clamped) for v, (lo, hi) in zip(values, ranges))


def _drive(msg, clamped):
    linear = _number(msg, 'linear', -WHEEL_MAX_SPEED_M_PER_S, WHEEL_MAX_SPEED_M_PER_S, clamped)
    angular = _number(msg, 'angular', -MAX_TURN_RAD_S, MAX_TURN_RAD_S, clamped)
    wanted = cmd_vel2wheel_speed(linear, angular)
    if clamp_wheel_speeds(*wanted) != wanted:
        clamped.append('wheel speed')
        linear, angular = clamped_cmd_vel(*wanted)
    return Drive(linear, angular)


def _head(msg, clamped):
    # Degrees on the page, like the MDK GUI; radians on the topic. Tilt is fixed.
    positions = [TILT_RAD, 0.0, 0.0, 0.0]
    for index, key in ((LIFT, 'lift'), (YAW, 'yaw'), (PITCH, 'pitch')):
        lo, hi = JOINT_LIMITS_RAD[index]
        positions[index] = math.radians(
            _number(msg, key, math.degrees(lo), math.degrees(hi), clamped))
        positions[index] = min(max(positions[index], lo), hi)  # rounding of the degrees
    return Head(tuple(positions))


def _flags(msg, clamped):
    reflex = msg.get('cliff_reflex')
    if not isinstance(reflex, bool):
        raise Rejected('cliff_reflex must be true or false')
    return Flags(0 if reflex else DOWNSTREAM_FLAG_DISABLE_CLIFF_REFLEX)


def _sim(msg, clamped):
    action = msg.get('action')
    if action not in SIM_ACTIONS:
        raise Rejected(f'action must be one of {", ".join(SIM_ACTIONS)}')
    return SimAction(action)


def _robot(msg, clamped):
    try:
        return SelectRobot(check_name(msg.get('name')))
    except ValueError as err:
        raise Rejected(str(err)) from None


def _ack(msg, clamped):
    out_of_range = []
    channel = _integer(msg, 'ch', 0, len(CHANNELS) - 1, out_of_range)
    if out_of_range:
        raise Rejected(f'no image channel {msg["ch"]!r:.20}')
    return Ack(channel)


def _view(msg, clamped):
    channels = msg.get('channels')
    if not isinstance(channels, list) or len(channels) > 2 * len(CHANNELS) or \
            not all(isinstance(c, str) and c in CHANNELS for c in channels):
        raise Rejected(f'channels must be a list of names from {", ".join(CHANNELS)}')
    world = msg.get('world')
    if not isinstance(world, bool):
        raise Rejected('world must be true or false')
    return View(frozenset(channels), world)


def _place(msg, clamped):
    try:
        name = check_name(msg.get('name'), 'object name')
    except ValueError as err:
        raise Rejected(str(err)) from None
    return Place(name, float(_number(msg, 'x', -MAX_PLACE_M, MAX_PLACE_M, clamped)),
                 float(_number(msg, 'y', -MAX_PLACE_M, MAX_PLACE_M, clamped)))


def _hear(msg, clamped):
    listen, shown = _flag(msg, 'listen'), _flag(msg, 'shown')
    out_of_range = []
    mic = _integer(msg, 'mic', 0, len(MICS) - 1, out_of_range)
    if out_of_range:
        raise Rejected(f'mic must be 0..{len(MICS) - 1} ({", ".join(MICS)})')
    return Hear(mic, listen, shown)


def _sound(msg, clamped):
    kind = msg.get('kind')
    if not isinstance(kind, str) or kind not in SOUND_KINDS:
        raise Rejected(f'kind must be one of {", ".join(SOUND_KINDS)}')
    return PlaceSound(float(_number(msg, 'x', -MAX_PLACE_M, MAX_PLACE_M, clamped)),
                      float(_number(msg, 'y', -MAX_PLACE_M, MAX_PLACE_M, clamped)), kind)


def _unsound(msg, clamped):
    try:
        return StopSound(check_name(msg.get('name'), 'sound name'))
    except ValueError as err:
        raise Rejected(str(err)) from None


def _flag(msg, key):
    value = msg.get(key)
    if not isinstance(value, bool):
        raise Rejected(f'{key} must be true or false')
    return value


def _touch(msg, clamped):
    part = msg.get('part')
    if not isinstance(part, str) or part not in TOUCH_PARTS:
        raise Rejected(f'part must be one of {", ".join(TOUCH_PARTS)}')
    return Touch(part, float(_number(msg, 'u', 0.0, 1.0, clamped)),
                 float(_number(msg, 'v', 0.0, 1.0, clamped)))


# kind: (the keys it takes besides "t", builder)
KINDS = {
    'drive': (('linear', 'angular'), _drive),
    'stop': ((), lambda msg, clamped: Stop()),
    'head': (('lift', 'yaw', 'pitch'), _head),
    'cosmetic': (('values',), lambda msg, clamped: Cosmetic(
        _numbers(msg, 'values', [(0.0, 1.0)] * 6, clamped))),
    'illum': (('leds',), lambda msg, clamped: Illum(
        _numbers(msg, 'leds', [(0, ARGB_MAX)] * 6, clamped, integer=True))),
    'tone': (('values',), lambda msg, clamped: Tone(
        _numbers(msg, 'values', (TONE_HZ, TONE_VOLUME, TONE_TICKS), clamped, integer=True))),
    'flags': (('cliff_reflex',), _flags),
    'sim': (('action',), _sim),
    'robot': (('name',), _robot),
    'ack': (('ch',), _ack),
    'view': (('channels', 'world'), _view),
    'place': (('name', 'x', 'y'), _place),
    'touch': (('part', 'u', 'v'), _touch),
    'hear': (('mic', 'listen', 'shown'), _hear),
    'sound': (('x', 'y', 'kind'), _sound),
    'unsound': (('name',), _unsound),
    'demo': (('shown',), lambda msg, clamped: Demo(_flag(msg, 'shown'))),
    'demo_run': (('run',), lambda msg, clamped: DemoRun(_flag(msg, 'run'))),
    'rtf': (('value',), lambda msg, clamped: SetRtf(
        float(_number(msg, 'value', 0.0, MAX_RTF, clamped)))),
}


def parse(text):
    """(command, names of the values that were clamped) of one text message, or Rejected."""
    if not isinstance(text, str):
        raise Rejected('not a text message')
    # A character is 1 to 4 bytes: count the bytes (a lone surrogate counts as 3).
    size = len(text) if len(text) > MAX_TEXT_BYTES else \
        len(text.encode('utf-8', 'surrogatepass'))
    if size > MAX_TEXT_BYTES:
        raise Rejected(f'message of more than {MAX_TEXT_BYTES} bytes')
    try:
        msg = json.loads(text, parse_constant=_reject_constant)
    except (ValueError, RecursionError):  # digits beyond int's limit are a ValueError too
        raise Rejected('not JSON') from None
    if not isinstance(msg, dict):
        raise Rejected('not a JSON object')
    kind = msg.get('t')
    if not isinstance(kind, str) or kind not in KINDS:  # a list is not even hashable
        raise Rejected(f'unknown message kind {_show(kind)}')
    keys, build = KINDS[kind]
    extra = set(msg) - set(keys) - {'t'}
    if extra:
        raise Rejected(f'{kind}: unknown keys {", ".join(sorted(map(str, extra)))[:80]}')
    clamped = []
    return build(msg, clamped), clamped


def page_config():
    """What the page needs to build its controls: MiRo's ranges, said here once."""
    def degrees(index):
        return [round(math.degrees(v), 6) for v in JOINT_LIMITS_RAD[index]]

    return {'t': 'config', 'channels': CHANNELS,
            'max_linear': WHEEL_MAX_SPEED_M_PER_S, 'max_angular': MAX_TURN_RAD_S,
            'head': {'lift': degrees(LIFT), 'yaw': degrees(YAW), 'pitch': degrees(PITCH)},
            'head_calib': {'lift': math.degrees(LIFT_RAD_CALIB), 'yaw': 0.0, 'pitch': 0.0},
            'cosmetic_calib': COSMETIC_CALIB,
            'tone': {'hz': TONE_HZ, 'volume': TONE_VOLUME, 'ticks': TONE_TICKS},
            'tick_s': PLATFORM_TICK_S,
            'touch': {'rows': TOUCH_ROWS, 'columns': TOUCH_COLUMNS},
            'battery_marks': list(BATTERY_MARKS_V), 'mics': MICS,
            'sound_kinds': SOUND_KINDS, 'actions': ACTIONS}


def frame_message(channel, stamp, jpeg):
    """The binary WebSocket message of one image."""
    return FRAME_HEADER.pack(channel, stamp) + jpeg


def overlay_message(channel, frame_stamp, paired):
    """What demo mode made of the frame of ``channel`` stamped ``frame_stamp`` (pairing.py):
    paired is (its stamp, {objects, view}); the page draws it on that frame only."""
    stamp, overlay = paired
    return json.dumps({'t': 'overlay', 'ch': channel, 'frame': frame_stamp, 'stamp': stamp,
                       **overlay})


def tone_message(values):
    """The page plays what its robot was asked to play: [hz, volume, ticks] of control/tone."""
    hz, volume, ticks = values
    return json.dumps({'t': 'tone', 'hz': hz, 'volume': volume, 'ticks': ticks})
