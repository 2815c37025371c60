"""World files: the bundled ones match the MDK's, and a broken file says what is wrong."""
import math

import pytest

from miro_sim_bullet.world_file import WorldError, bundled_worlds, load_world


def test_bundled_worlds_are_installed_with_the_package():
    assert {'miro', 'empty', 'table'} <= set(bundled_worlds())


def test_default_world_reproduces_the_mdk_arena():
    world = load_world('miro')
    assert world.robot_pose == (0.0, 0.0, 0.0)
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
    # Nothing in the arena but the ball is blue.
    for shape in world.shapes:
        r, g, b = shape.colour
        assert not (b > 0.5 and r < 0.3 and g < 0.3)


def test_user_world_file_by_path(tmp_path):
    path = tmp_path / 'mine.toml'
    path.write_text('[robot]\npose = [0.1, 0.2, 1.0]\n[[sphere]]\nposition = [1, 0, 0.2]\n'
                    'radius = 0.2\nmass = 0.5\n')
    world = load_world(str(path))
    assert world.robot_pose == (0.1, 0.2, 1.0) and world.ball is None
    assert world.shapes[0].kind == 'sphere' and world.shapes[0].mass == 0.5


@pytest.mark.parametrize('text, expected', [
    ('[robot]\nposes = [0, 0, 0]\n', "robot: unknown key 'poses'"),
    ('[ball]\nradius = -1\n', 'ball.radius: must be > 0'),
    ('[ball]\nposition = [1]\n', 'ball.position: must be a list of 2 numbers'),
    ('[[box]]\nposition = [0, 0, 0]\n', "box[0]: missing 'size'"),
    ('[[ring]]\ncount = 0\n', 'ring[0].count: must be a whole number'),
    ('[ground]\ncolour = [2, 0, 0]\n', 'ground.colour: colour components must be in 0..1'),
    ('[robot\n', 'not valid TOML'),
])
def test_mistakes_name_the_file_and_the_key(tmp_path, text, expected):
    path = tmp_path / 'broken.toml'
    path.write_text(text)
    with pytest.raises(WorldError) as err:
        load_world(str(path))
    message = str(err.value)
    assert message.startswith(str(path)) and expected in message
    assert '\n' not in message


def test_unknown_name_and_missing_file():
    with pytest.raises(WorldError, match="unknown world 'nowhere'.*miro"):
        load_world('nowhere')
    with pytest.raises(WorldError, match='cannot read world file'):
        load_world('/no/such/world.toml')
