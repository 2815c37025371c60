"""A world's sounds: ``[[sound]]`` sources and the ``[hearing]`` options (docs/worlds.md).

A sound plays from a point: a sound file (WAV, FLAC, OGG: what libsndfile reads), a tone
or white noise, at a level (its RMS 1 m away, in dB of the microphones' full scale), from
``start`` seconds of simulated time until ``stop`` (or for ever), a file once or looped.

Which files may be read (docs/limits.md): a sound request comes from anyone on the ROS
graph (or a web page, through a bridge), so a file is one of the bundled sounds
(worlds/sounds/), or lies in a folder the simulator was started with (its sound_folders
parameter) or, for a world file, beside that file (its folder and below), once every
symbolic link and '..' is resolved; and it is a regular file (a FIFO, a device or a folder
would block or never end). Its header is checked before a sample is read: 8 to 192 kHz, at
most MAX_CHANNELS channels and MAX_SOUND_S seconds. Any mistake is refused in one line, as
every other mistake in a world file.
"""
import importlib.resources
import math
import stat
from dataclasses import dataclass
from pathlib import Path

from miro_ball.common.files import allowed_path, open_regular

KINDS = ('file', 'tone', 'noise')
MAX_SOUNDS = 32
MAX_SOUND_S = 600.0  # a file's length: held as float32 at 20 kHz, 10 minutes are 48 MB
SAMPLE_RATE_RANGE_HZ = (8000, 192000)  # a header outside asked for a 320 GiB filter
MAX_CHANNELS = 8
MAX_SOUND_FILE_BYTES = 300_000_000  # 10 minutes of 8 channels at 48 kHz, 16 bits, and more
# Decoding holds the file's frames as float32 before they are brought to 20 kHz: 10 minutes at
# 192 kHz took 1 GB and 11 s; 10 minutes at 48 kHz take about 0.3 GB for a moment.
MAX_FRAMES = 600 * 48000
LEVEL_RANGE_DB = (-120.0, 0.0)
TONE_RANGE_HZ = (20.0, 9000.0)  # below the microphones' Nyquist frequency


@dataclass(frozen=True)
class Sound:
    name: str
    position: tuple  # x, y, z (m)
    kind: str  # file | tone | noise
    level_db: float  # RMS 1 m away, dB of full scale
    file: str = ''  # absolute path, for a file (checked: _sound_file)
    frequency: float = 0.0  # Hz, for a tone
    loop: bool = False  # a file starts again when it ends
    start: float = 0.0  # s of simulated time
    stop: float = math.inf


@dataclass(frozen=True)
class Hearing:
    """How the world sounds beyond its sources."""
    wheel_noise: bool = False  # each robot's wheels whirr as they turn
    reflections: bool = False  # the ground's and the room's walls' echoes (image sources)
    absorption: float = 0.5  # of the walls, 0..1: the energy a reflection loses
    room: tuple = ()  # x0, y0, x1, y1, height (m): the walls' box; () = no walls, ground only


def parse_sounds(parser, value):
    """The checked [[sound]] tables, as Sounds; parser is the world file's (its checks)."""
    tables = parser.array('sound', value)
    if len(tables) > MAX_SOUNDS:
        parser.fail('sound', f'at most {MAX_SOUNDS} sounds, got {len(tables)}')
    return tuple(_sound(parser, f'sound[{i}]', i, table) for i, table in enumerate(tables))


def _sound(parser, where, index, table):
    parser.keys(where, table, {'name', 'position', 'file', 'tone', 'noise', 'level', 'loop',
                               'start', 'stop'})
    kinds = [kind for kind in ('file', 'tone', 'noise') if kind in table]
    if len(kinds) != 1:
        parser.fail(where, "needs exactly one of 'file' (a sound file), 'tone' (Hz) or "
                           "'noise = true'")
    kind, = kinds
    name = parser.name(f'{where}.name', table['name'], 'sound name') \
        if 'name' in table else f'sound{index}'
    level = parser.number(f'{where}.level', table.get('level', -30.0))
    lo, hi = LEVEL_RANGE_DB
    if not lo <= level <= hi:
        parser.fail(f'{where}.level', f'must be {lo:g}..{hi:g} dB (RMS 1 m away, of full '
                                      f'scale), got {level:g}')
    start = parser.number(f'{where}.start', table.get('start', 0.0), minimum=0.0)
    stop = parser.number(f'{where}.stop', table['stop'], positive=True) \
        if 'stop' in table else math.inf
    if stop <= start:
        parser.fail(f'{where}.stop', f'must be after start ({start:g} s), got {stop:g}')
    loop = table.get('loop', False)
    if not isinstance(loop, bool):
        parser.fail(f'{where}.loop', f'must be true or false, got {loop!r}'[:120])
    extra = {}
    if kind == 'tone':
        # Not parser.number: a tone's Hz go past the file's limit of 1000 on a number.
        hz = table['tone']
        lo, hi = TONE_RANGE_HZ
        if isinstance(hz, bool) or not isinstance(hz, (int, float)) or not lo <= hz <= hi:
            parser.fail(f'{where}.tone', f'must be {lo:g}..{hi:g} Hz, got {hz!r}'[:120])
        extra['frequency'] = float(hz)
    elif kind == 'noise':
        if table['noise'] is not True:
            parser.fail(f'{where}.noise', 'must be true')
    else:
        extra['file'] = _sound_file(parser, f'{where}.file', table['file'])
    if loop and kind != 'file':
        parser.fail(f'{where}.loop', 'only a file loops (a tone and noise play on)')
    return Sound(name=name, position=parser.vector(f'{where}.position',
                                                   table.get('position', [0, 0, 0]), 3),
                 kind=kind, level_db=level, loop=loop, start=start, stop=stop, **extra)


def bundled_sound(name):
    """The path of a bundled sound file (worlds/sounds/), or None when there is none."""
    bundled = _bundled_folder() / name
    return bundled if bundled.is_file() else None


def _sound_file(parser, where, value):
    """The resolved path of a sound file that may be read (see the module's docstring)."""
    import soundfile  # here: a world without sound files loads with the standard library only
    if not isinstance(value, str) or not value or '\0' in value or len(value) > 4096:
        parser.fail(where, f'must be the name of a sound file, got {value!r}'[:120])
    path = _allowed_sound(parser, where, value)
    try:
        with open_regular(path) as file:
            info = soundfile.info(file)
    except (OSError, RuntimeError, soundfile.LibsndfileError) as err:
        parser.fail(where, f'cannot read {value!r} as sound: {str(err)[:100]}')
    lo, hi = SAMPLE_RATE_RANGE_HZ
    if not lo <= info.samplerate <= hi:
        parser.fail(where, f'{value!r} says {info.samplerate} samples a second; a sound file '
                           f'must be {lo}..{hi} Hz')
    if not 1 <= info.channels <= MAX_CHANNELS:
        parser.fail(where, f'{value!r} has {info.channels} channels; at most {MAX_CHANNELS}')
    if info.frames <= 0:
        parser.fail(where, f'{value!r} holds no sound')
    if info.frames / info.samplerate > MAX_SOUND_S:
        parser.fail(where, f'{value!r} is longer than {MAX_SOUND_S:g} s')
    if info.frames > MAX_FRAMES:
        parser.fail(where, f'{value!r} holds {info.frames} frames; at most {MAX_FRAMES} (10 '
                           'minutes at 48 kHz, 2.5 at 192 kHz)')
    return str(path)


def _allowed_sound(parser, where, value):
    """value as a regular file in one of the allowed folders (bundled sounds first, then
    the world file's folder, then sound_folders; a relative path is looked for in each)."""
    path = allowed_path(value, [_bundled_folder(), *parser.sound_roots()])
    try:
        found = path and path.stat()
    except OSError:  # gone since
        found = None
    if not found:
        parser.fail(where, f'no sound file {value!r} in the allowed folders: a bundled sound '
                           f'({", ".join(bundled_sounds())}), a file beside the world file, or in '
                           "the simulator's sound_folders"[:300])
    if not stat.S_ISREG(found.st_mode):
        parser.fail(where, f'{value!r} is not a regular file (a FIFO, device or folder is '
                           'never opened)'[:200])
    if found.st_size > MAX_SOUND_FILE_BYTES:
        parser.fail(where, f'{value!r} is larger than {MAX_SOUND_FILE_BYTES} bytes')
    return path


def _bundled_folder():
    return Path(str(importlib.resources.files('miro_sim_bullet.worlds') / 'sounds')).resolve()


def bundled_sounds():
    """File names of the sounds installed with the package (worlds/sounds/)."""
    return sorted(p.name for p in _bundled_folder().iterdir() if p.suffix == '.ogg')


def parse_hearing(parser, table):
    """The checked [hearing] table, as Hearing."""
    if table is None:
        return Hearing()
    parser.keys('hearing', table, {'wheel_noise', 'reflections', 'absorption', 'room'})
    flags = {}
    for key in ('wheel_noise', 'reflections'):
        flags[key] = table.get(key, False)
        if not isinstance(flags[key], bool):
            parser.fail(f'hearing.{key}', 'must be true or false')
    absorption = parser.number('hearing.absorption', table.get('absorption', 0.5))
    if not 0.0 <= absorption <= 1.0:
        parser.fail('hearing.absorption', f'must be 0..1, got {absorption:g}')
    room = ()
    if 'room' in table:
        room = parser.vector('hearing.room', table['room'], 5)
        if room[2] <= room[0] or room[3] <= room[1] or room[4] <= 0:
            parser.fail('hearing.room', 'must be [x0, y0, x1, y1, height] with x1 > x0, '
                                        'y1 > y0, height > 0')
    return Hearing(absorption=absorption, room=room, **flags)
