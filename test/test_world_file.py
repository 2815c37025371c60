"""World files: the bundled ones match the MDK's, and a broken file says what is wrong."""
import math
import time

import pytest

from miro_sim_bullet.scene.world_file import bundled_worlds, load_world
from miro_sim_bullet.scene.world_model import MAX_ROBOTS, RobotSpec, WorldError


def is_blue(colour):
    r, g, b = colour
    return b > 0.5 and r < 0.3 and g < 0.3


def write(tmp_path, text, name='mine.toml'):
    path = tmp_path / name
    path.write_text(text)
    return str(path)


def test_bundled_worlds_are_installed_with_the_package():
    assert {'miro', 'empty', 'football', 'football_pitch', 'petshop', 'cube',
            'tables', 'den'} <= set(bundled_worlds())
    assert 'table' not in bundled_worlds()


@pytest.mark.parametrize('name', bundled_worlds())
def test_every_bundled_world_loads_with_unique_names_and_only_the_ball_blue(name):
    world = load_world(name)
    assert world.description and 1 <= len(world.robots)
    names = [r.name for r in world.robots if r.name] + [s.name for s in world.shapes if s.name]
    assert len(names) == len(set(names)) and 'ball' not in names
    assert all(s.name for s in world.shapes if s.mass > 0)
    assert not is_blue(world.ground_colour)
    assert not any(is_blue(s.colour) for s in world.shapes)
    assert world.ball is None or is_blue(world.ball.colour)


def test_default_world_reproduces_the_mdk_arena():
    world = load_world('miro')
    assert world.robots == (RobotSpec(None, (0.0, 0.0, 0.0)),)
    assert world.ball.position == (0.6, -0.3) and world.ball.radius == 0.1
    assert world.ground_height == -1.0
    floor = [s for s in world.shapes if s.kind == 'cylinder']
    assert len(floor) == 1 and floor[0].radius == 1.25
    assert floor[0].position[2] + floor[0].length / 2 == pytest.approx(0.0)
    panels = [s for s in world.shapes if s.kind == 'box']
    assert len(panels) == 12
    for panel in panels:
        assert math.hypot(*panel.position[:2]) == pytest.approx(1.21)
        assert panel.size == (0.01, 0.65, 0.30)
        assert panel.position[2] == pytest.approx(0.15)


def panel_centres(world):
    return sorted((round(s.position[0], 6), round(s.position[1], 6)) for s in world.shapes)


def test_football_is_the_closed_mdk_pitch():
    world = load_world('football')
    expected = sorted([(x, y) for x in (-1.625, -0.975, -0.325, 0.325, 0.975, 1.625)
                       for y in (-1.3, 1.3)]
                      + [(x, y) for x in (-1.95, 1.95) for y in (-0.975, -0.325, 0.325, 0.975)])
    assert panel_centres(world) == expected
    for panel in world.shapes:
        # Width along the side it stands on, bottom on the floor.
        along_x = abs(panel.position[1]) == pytest.approx(1.3)
        width_direction = (-math.sin(panel.yaw), math.cos(panel.yaw))
        assert abs(width_direction[0 if along_x else 1]) == pytest.approx(1.0)
        assert panel.position[2] - panel.size[2] / 2 == pytest.approx(0.0)
    assert world.ground_size == (3.9, 2.6) and world.ground_height == 0.0
    assert world.robots == (RobotSpec(None, (0.0, 0.0, 0.0)),)
    assert world.ball.position == (0.6, -0.3)


def test_football_pitch_has_the_three_course_robots():
    world = load_world('football_pitch')
    assert world.robots == (RobotSpec('miro01', (0.0, 0.0, 0.0)),
                            RobotSpec('miro02', (-0.5, 0.2, 0.5)),
                            RobotSpec('miro03', (0.5, 0.2, -0.5)))
    assert panel_centres(world) == panel_centres(load_world('football'))


def test_petshop_is_the_small_pen_with_three_robots():
    world = load_world('petshop')
    assert [r.name for r in world.robots] == ['miro01', 'miro02', 'miro03']
    assert world.robots[2].pose == (0.5, 0.2, 0.5)
    expected = sorted([(x, y) for x in (-0.65, 0.0, 0.65) for y in (-0.65, 0.65)]
                      + [(x, y) for x in (-0.975, 0.975) for y in (-0.325, 0.325)])
    assert panel_centres(world) == expected
    assert world.ground_size == (1.95, 1.3)


def test_cube_world_has_a_light_cube_on_the_arena_floor_and_no_ball():
    world = load_world('cube')
    assert world.ball is None
    (cube,) = [s for s in world.shapes if s.mass > 0]
    assert cube.name == 'cube' and cube.size == (0.075,) * 3 and cube.mass == 0.000419
    assert cube.position == (0.6, -0.3, 0.0375)


def tops(world):
    return [s for s in world.shapes if s.kind == 'box' and s.size == (1.5, 0.8, 0.03)]


def on_a_top(world, x, y):
    """Whether the floor point (x, y) is over some table top."""
    for top in tops(world):
        dx, dy = x - top.position[0], y - top.position[1]
        c, s = math.cos(top.yaw), math.sin(top.yaw)
        if abs(c * dx + s * dy) <= 0.75 and abs(-s * dx + c * dy) <= 0.4:
            return True
    return False


def test_tables_world_puts_everything_on_a_table_top():
    world = load_world('tables')
    assert len(tops(world)) == 16
    legs = [s for s in world.shapes if s.kind == 'cylinder' and s.radius == 0.02]
    assert len(legs) == 64
    assert all(top.position[2] + 0.015 == pytest.approx(1.0) for top in tops(world))
    assert all(leg.position[2] + leg.length / 2 == pytest.approx(0.97) for leg in legs)
    (robot,) = world.robots
    assert robot.floor == 1.0 and on_a_top(world, *robot.pose[:2])
    assert not on_a_top(world, -0.76, 0.0)  # the free edge the cliff tests use
    assert world.ball.floor == 1.0 and on_a_top(world, *world.ball.position)
    cube = next(s for s in world.shapes if s.name == 'cube')
    assert cube.position[2] - 0.0375 == pytest.approx(1.0)
    assert all(on_a_top(world, cube.position[0] + dx, cube.position[1] + dy)
               for dx in (-0.0375, 0.0375) for dy in (-0.0375, 0.0375))
    cans = [s for s in world.shapes if s.name and s.name.startswith('can')]
    assert sorted(c.name for c in cans) == [f'can{i}' for i in range(10)]
    for can in cans:
        rim = [(can.position[0] + 0.085 * math.cos(a), can.position[1] + 0.085 * math.sin(a))
               for a in (k * math.pi / 8 for k in range(16))]
        assert all(on_a_top(world, *p) for p in rim), can.name
        bottom = can.position[2] - can.length / 2
        # On the table, or stacked across cans whose tops are its bottom.
        under = [c for c in cans if c.position[2] + c.length / 2 == pytest.approx(bottom)
                 and abs(c.position[0] - can.position[0]) < 2 * can.radius]
        assert bottom == pytest.approx(1.0) or len(under) == 2, can.name


def test_user_world_file_by_path(tmp_path):
    world = load_world(write(tmp_path, '[robot]\npose = [0.1, 0.2, 1.0]\n[[sphere]]\n'
                                       'position = [1, 0, 0.2]\nradius = 0.2\nmass = 0.5\n'))
    assert world.robots == (RobotSpec(None, (0.1, 0.2, 1.0)),) and world.ball is None
    assert world.shapes[0].kind == 'sphere' and world.shapes[0].mass == 0.5
    assert world.shapes[0].name == 'sphere0'


def test_old_robot_table_takes_a_name_and_floor(tmp_path):
    world = load_world(write(tmp_path, '[robot]\nname = "rover"\npose = [1, 2, 0]\n'
                                       'floor = 0.5\n[ball]\nfloor = 0.5\n'))
    assert world.robots == (RobotSpec('rover', (1.0, 2.0, 0.0), 0.5),)
    assert world.ball.floor == 0.5


def test_a_world_without_robots_gets_one_unnamed_at_the_origin(tmp_path):
    assert load_world(write(tmp_path, '')).robots == (RobotSpec(None, (0.0, 0.0, 0.0)),)


def test_movable_shapes_are_named_and_static_ones_only_if_asked(tmp_path):
    world = load_world(write(tmp_path, '[[box]]\nsize = [1, 1, 1]\n'
                                       '[[box]]\nsize = [1, 1, 1]\nmass = 1\n'
                                       '[[box]]\nsize = [1, 1, 1]\nname = "plinth"\n'
                                       '[[cylinder]]\nradius = 1\nlength = 1\nmass = 1\n'
                                       'name = "drum"\n'))
    assert [s.name for s in world.shapes] == [None, 'box1', 'plinth', 'drum']


def test_a_table_expands_into_a_top_and_four_legs_turned_with_it(tmp_path):
    world = load_world(write(tmp_path, '[[table]]\nposition = [2, 1]\nyaw = 1.5707963267948966'
                                       '\nheight = 0.5\n'))
    top, *legs = world.shapes
    assert top.position == pytest.approx((2, 1, 0.485)) and top.size == (1.5, 0.8, 0.03)
    assert sorted((round(leg.position[0], 6), round(leg.position[1], 6)) for leg in legs) == \
        [(1.62, 0.32), (1.62, 1.68), (2.38, 0.32), (2.38, 1.68)]
    assert all(leg.length == pytest.approx(0.47) and leg.mass == 0 for leg in legs)


def test_a_single_wall_panel_needs_no_end(tmp_path):
    (panel,) = load_world(write(tmp_path, '[[wall]]\nfrom = [1, 2]\ncount = 1\n'
                                          'floor = 0.2\n')).shapes
    assert panel.position == pytest.approx((1, 2, 0.35)) and panel.size == (0.01, 0.65, 0.3)


def robots(count, name=lambda i: f'miro{i:02d}'):
    return ''.join(f'[[robot]]\nname = "{name(i)}"\n' for i in range(count))


@pytest.mark.parametrize('text, expected', [
    ('[robot]\nposes = [0, 0, 0]\n', "robot: unknown key 'poses'"),
    ('[ball]\nradius = -1\n', 'ball.radius: must be > 0'),
    ('[ball]\nposition = [1]\n', 'ball.position: must be a list of 2 numbers'),
    ('[[box]]\nposition = [0, 0, 0]\n', "box[0]: missing 'size'"),
    ('[[ring]]\ncount = 0\n', 'ring[0].count: must be a whole number'),
    ('[ground]\ncolour = [2, 0, 0]\n', 'ground.colour: colour components must be in 0..1'),
    ('[robot\n', 'not valid TOML'),
    ('[[robot]]\n[[robot]]\n', 'robot[0].name: required when the world has several robots'),
    (robots(2, lambda i: 'twin'), "robot[1].name: 'twin' is already the name"),
    (robots(1) + '[[box]]\nname = "miro00"\nsize = [1, 1, 1]\n',
     "box[0].name: 'miro00' is already the name"),
    ('[[sphere]]\nname = "ball"\nradius = 1\n', "sphere[0].name: 'ball' is reserved"),
    (robots(2, lambda i: ['ok', 'bad name'][i]), "robot[1].name: robot name 'bad name' must"),
    ('[robot]\nname = ""\n', "robot.name: robot name '' must"),
    (robots(MAX_ROBOTS + 1), f'robot: must list 1 to {MAX_ROBOTS} robots, got 17'),
    ('[[wall]]\nfrom = [0, 0]\nto = [1, 0]\ncount = 1000000\n',
     'wall[0].count: must be a whole number from 1 to 1000'),
    ('[[ring]]\ncount = 1000\n' * 3, 'ring[2]: more than 2000 shapes'),
    ('[[box]]\nsize = [1e17, 1, 1]\n', 'box[0].size[0]: must be within +-1000'),
    ('[robot]\npose = [0, 1' + '0' * 400 + ', 0]\n', 'robot.pose[1]: must be within +-1000'),
    ('[[wall]]\nfrom = [0, 0]\ncount = 2\n', "wall[0]: missing 'to'"),
    ('[[table]]\nheight = 0.02\n', "table[0].height: must be more than the top's thickness"),
    ('a = ' + '[' * 5000 + ']' * 5000 + '\n', 'nested too deeply'),
    ('[[sound]]\nposition = [0, 0, 0]\n', "sound[0]: needs exactly one of 'file'"),
    ('[[sound]]\ntone = 440\nnoise = true\n', "sound[0]: needs exactly one of 'file'"),
    ('[[sound]]\nfile = "nowhere.wav"\n', "sound[0].file: no sound file 'nowhere.wav' in the allowed folders"),
    ('[[sound]]\nfile = "broken.toml"\n', "sound[0].file: cannot read 'broken.toml' as sound"),
    ('[[sound]]\ntone = 20000\n', 'sound[0].tone: must be 20..9000 Hz'),
    ('[[sound]]\nnoise = true\nlevel = 10\n', 'sound[0].level: must be -120..0 dB'),
    ('[[sound]]\nnoise = true\nstart = 2\nstop = 1\n', 'sound[0].stop: must be after start'),
    ('[[sound]]\ntone = 300\nloop = true\n', 'sound[0].loop: only a file loops'),
    ('[[sound]]\nnoise = true\nvolume = 3\n', "sound[0]: unknown key 'volume'"),
    ('[hearing]\nroom = [0, 0, -1, 1, 1]\n', 'hearing.room: must be [x0, y0, x1, y1, height]'),
    ('[hearing]\nechoes = true\n', "hearing: unknown key 'echoes'"),
])
def test_mistakes_name_the_file_and_the_key(tmp_path, text, expected):
    path = write(tmp_path, text, 'broken.toml')
    with pytest.raises(WorldError) as err:
        load_world(path)
    message = str(err.value)
    assert message.startswith(path + ': ') and expected in message
    assert '\n' not in message and len(message) < 300


def test_a_binary_file_is_refused_in_one_line(tmp_path):
    path = tmp_path / 'image.toml'
    path.write_bytes(bytes(range(256)) * 4)
    with pytest.raises(WorldError, match=r'^\S+image.toml: not a UTF-8 text file$'):
        load_world(str(path))


def test_an_endless_file_is_refused_fast_without_reading_it_all(tmp_path):
    start = time.monotonic()
    with pytest.raises(WorldError, match="^'/dev/zero': cannot read world file: not a regular "
                                         'file$'):
        load_world('/dev/zero')
    big = tmp_path / 'big.toml'
    big.write_text('#' * 2_000_000)
    with pytest.raises(WorldError, match=r'big.toml: larger than 1000000 bytes$'):
        load_world(str(big))
    assert time.monotonic() - start < 2.0


def test_unknown_empty_and_missing_names(tmp_path):
    """Each says so, and its kind is MISSING; a file that is there and breaks a rule is
    INVALID, whatever its name says (the simulator's load_world answers by the kind)."""
    for name, said in (('nowhere', "^unknown world 'nowhere'.*miro"),
                       ('', '^empty world name: bundled worlds are .*miro'),
                       ('/no/such/world.toml', 'cannot read world file'),
                       ('package://miro_ball/worlds/models/box.toml', '^unknown world'),
                       (str(tmp_path / 'elsewhere.toml'), '^no world file')):
        with pytest.raises(WorldError, match=said) as err:
            load_world(name, world_folders=[tmp_path / 'allowed'] if 'elsewhere' in name
                       else None)
        assert err.value.kind == WorldError.MISSING, name
    broken = write(tmp_path, '[robot]\npose = "no world file"\n', 'unknown world.toml')
    with pytest.raises(WorldError, match='robot.pose') as err:
        load_world(broken)
    assert err.value.kind == WorldError.INVALID


def test_a_world_plays_sound_files_tones_and_noise_from_where_it_says(tmp_path):
    import numpy as np
    import soundfile
    soundfile.write(str(tmp_path / 'chirp.wav'), np.zeros(800), 8000)
    world = load_world(write(tmp_path, '[[sound]]\nname = "radio"\nfile = "chirp.wav"\n'
                                       'position = [1, 2, 0.5]\nloop = true\nlevel = -20\n'
                                       '[[sound]]\ntone = 440\nstop = 3\n'
                                       '[hearing]\nreflections = true\nroom = [-1, -1, 1, 1, 2]\n'))
    radio, tone = world.sounds
    assert (radio.name, radio.kind, radio.position, radio.loop, radio.level_db) == \
        ('radio', 'file', (1.0, 2.0, 0.5), True, -20.0)
    assert radio.file == str(tmp_path / 'chirp.wav')
    assert (tone.name, tone.kind, tone.frequency, tone.stop) == ('sound1', 'tone', 440.0, 3.0)
    assert world.hearing.reflections and world.hearing.room == (-1.0, -1.0, 1.0, 1.0, 2.0)
