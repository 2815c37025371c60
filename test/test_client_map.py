"""client_map against the simulator in simulated time: MiRo turns on the spot, and its
map shows the ball and the arena's wall where the simulator's ground truth has them,
through either lens; what it publishes and writes is that map."""
import importlib.resources
import math
import os
import re
import subprocess
import sys

import cv2
import numpy as np
import pytest
from sensor_msgs.msg import CompressedImage, Image

from miro_ball.common.isolation import isolated_env
from miro_ball.examples.client_map import build_parser, Mapper
from miro_ball.miro.camera_model import LENSES
from miro_ball.miro.interface import default_robot_name, EYES, frame_id, RobotTopics
from rostools import advance_ticks, drain, Probe, spin_until
from test_fuzz_topics import fuzz

T = RobotTopics(default_robot_name())
SPIN = 1.5  # rad/s
# The eyes see about half the floor round MiRo at once: two thirds of a turn map it all.
TURN = 4.2  # rad


def blue(rgb):
    r, g, b = (rgb[..., i].astype(int) for i in range(3))
    return (b > 60) & (b > r + 40) & (b > g + 40)


def floor_coloured(rgb):
    return rgb.min(axis=-1) > 200  # the white floor disc, lit


def bare_arena(folder):
    """The arena's world file without its pictures: their white backgrounds are the white
    floor's colour, and this test tells floor from wall by colour."""
    text = (importlib.resources.files('miro_sim_bullet.worlds') / 'miro.toml').read_text()
    text = re.sub(r'^picture(_side)? = (\[.*?\]|".*?")\n', '', text, flags=re.M | re.S)
    path = folder / 'bare_arena.toml'
    path.write_text(text)
    return str(path)


def wall_depth(world, x, y):
    """How far (x, y) lies beyond the inner face of the arena's wall (m; < 0 inside): the
    largest distance past a panel's face along that panel's normal."""
    panels = [s for s in world.shapes if s.kind == 'box']
    return np.max([x * math.cos(p.yaw) + y * math.sin(p.yaw)
                   - (math.hypot(*p.position[:2]) - p.size[0] / 2) for p in panels], axis=0)


def linked(executor, sim_node, client):
    """Spin until the client hears the simulator's eyes and sensors."""
    interface = sim_node.robots[T.name]
    assert spin_until(executor, lambda: all(
        pub.get_subscription_count() for eye in EYES for pub in
        (interface.pub_eyes[eye][0], interface.pub_eyes[eye][2])) and all(
        sub.get_publisher_count() for sub in client.subscriptions))


def spin_and_map(sim_node, executor, context, args):
    """Run client_map with --spin until MiRo has turned TURN; (the client, the maps it
    published). The client is stopped (as on exit) before it is returned."""
    client = Mapper(build_parser().parse_args(['--spin', str(SPIN), *args]), context=context)
    executor.add_node(client)
    maps = Probe(context, executor).watch(Image, f'/{T.name}/client_map/map')
    linked(executor, sim_node, client)
    robot = sim_node.sim.robots[T.name]
    turned, last = 0.0, robot.pose()[2]
    while turned < TURN:
        advance_ticks(sim_node, executor, rounds=40)
        yaw = robot.pose()[2]
        turned += abs(math.remainder(yaw - last, 2 * math.pi))
        last = yaw
    executor.remove_node(client)  # as run() does: stop() once the client no longer spins
    client.stop()
    advance_ticks(sim_node, executor, count=10)
    client.destroy_node()
    return client, maps


@pytest.mark.parametrize('lens', LENSES)
def test_map_shows_the_ball_and_the_arena_wall_where_they_are(lens, make_sim, executor,
                                                              ros_context, tmp_path):
    sim_node = make_sim(lens=lens, world=bare_arena(tmp_path))
    assert not sim_node.sim.description.pictures
    out = tmp_path / 'map.png'
    client, maps = spin_and_map(sim_node, executor, ros_context, ['--out', str(out)])
    robot = sim_node.sim.robots[T.name]
    fx, fy, _ = robot.pose()
    assert abs(robot.sensors.velocity[1]) < 0.05  # the zero twist on the way out

    fmap = client.map
    rgb = cv2.cvtColor(cv2.imread(str(out)), cv2.COLOR_BGR2RGB)  # written on the way out
    assert np.array_equal(rgb, fmap.image())
    last = maps[-1]
    assert (last.encoding, last.header.frame_id) == ('rgb8', frame_id(T.name, 'odom'))
    assert (last.height, last.width) == rgb.shape[:2] == (300, 300)

    rows, cols = np.mgrid[:fmap.cells, :fmap.cells]
    x, y = fmap.cell_to_world(rows, cols)
    seen, ball, floor = fmap.seen(), blue(rgb), floor_coloured(rgb)
    wall = seen & ~ball & ~floor

    # The ball: its floor point is blue, the streak starts at its near side and stays
    # in its shadow as seen from MiRo.
    bx, by, _ = sim_node.sim.ball_position()
    radius = sim_node.sim.description.ball.radius
    assert ball[fmap.world_to_cell(bx, by)]
    d = math.hypot(bx - fx, by - fy)
    along = ((x - fx) * (bx - fx) + (y - fy) * (by - fy)) / d  # from MiRo to the ball
    across = np.abs((x - fx) * (by - fy) - (y - fy) * (bx - fx)) / d
    near_edge = along[ball].min()
    print(f'{lens}: ball streak starts {near_edge - d:+.3f} m from the ball\'s floor point '
          f'({d:.2f} m away), spreads {(across[ball] / along[ball]).max():.3f} rad')
    assert d - radius - 0.02 < near_edge < d + 0.02
    # The streak's apex is the eye, ahead of the foot: seen from the foot it is wider.
    assert np.all(across[ball] < 2 * radius / d * along[ball])

    # The arena: floor inside the wall, wall colours only from its face on.
    depth = wall_depth(sim_node.sim.description, x, y)
    near_ball = cv2.dilate(ball.astype(np.uint8), np.ones((7, 7), np.uint8)) > 0
    print(f'{lens}: floor up to {depth[floor].max():+.3f} m past the wall\'s face, wall '
          f'colours from {depth[wall & ~near_ball].min():+.3f} m')
    assert depth[floor].max() < 0.03
    assert depth[wall & ~near_ball].min() > -0.05
    # ... all the way round: the floor ring the eyes see, and the wall beyond it.
    inside = (np.hypot(x - fx, y - fy) > 0.7) & (depth < -0.1) & ~near_ball
    assert (seen & floor)[inside].mean() > 0.98
    beyond = (depth > 0.05) & (np.hypot(x - fx, y - fy) < 1.35) & ~near_ball
    assert wall[beyond].mean() > 0.95


def test_hostile_messages_are_ignored_and_mapping_goes_on(make_sim, executor, ros_context,
                                                         tmp_path, capfd):
    """Corrupt JPEGs, unusable camera_info, NaN joints and poses, stamps anywhere: each
    is skipped with a warning; then the simulator's frames paint the ball where it is."""
    sim_node = make_sim()
    client = Mapper(build_parser().parse_args(['--out', str(tmp_path / 'map.png')]),
                    context=ros_context)
    executor.add_node(client)
    try:
        delivered = fuzz(client, Probe(ros_context, executor, 'fuzzer'), executor)
        assert min(delivered.values()) > 2
        linked(executor, sim_node, client)
        # A good JPEG of another size than camera_info's, of an instant with a pose,
        # delivered between two of the simulator's frames (the eyes keep the newest).
        pub = Probe(ros_context, executor, 'wrong_size').publisher(
            CompressedImage, T.eye_compressed('caml'))
        assert spin_until(executor, pub.get_subscription_count)
        advance_ticks(sim_node, executor, count=5, rounds=40)
        small = CompressedImage(format='jpeg', data=cv2.imencode(
            '.jpg', np.zeros((240, 320, 3), np.uint8))[1].tobytes())
        small.header.stamp.nanosec = 90_000_000
        pub.publish(small)
        drain(executor)
        advance_ticks(sim_node, executor, count=20, rounds=40)
        bx, by, _ = sim_node.sim.ball_position()
        assert blue(client.map.image())[client.map.world_to_cell(bx, by)]
    finally:
        executor.remove_node(client)
        client.destroy_node()
    said = capfd.readouterr().err
    for what in ('frame ignored: not a JPEG', "is not the camera's RGB uint8 640x360",
                 'camera_info ignored', 'kinematic_joints ignored', 'odom ignored'):
        assert what in said
    assert 'Traceback' not in said


@pytest.mark.parametrize('args, why', [
    (['--help'], None),
    (['--resolution', '0'], 'not within'),
    (['--size', '50', '--resolution', '0.002'], '25000 cells a side'),
    (['--out', 'map.jpg'], 'name a .png'),
])
def test_help_and_bad_options_in_one_line(args, why, tmp_path):
    done = subprocess.run([sys.executable, '-m', 'miro_ball.examples.client_map', *args],
                          capture_output=True, text=True, timeout=60, cwd=tmp_path,
                          env=isolated_env(int(os.environ['ROS_DOMAIN_ID'])))
    if why is None:
        assert done.returncode == 0 and '--spin' in done.stdout
    else:
        error = done.stderr.strip().splitlines()[-1]  # after the usage
        assert done.returncode == 2 and error.startswith('client_map: error:'), done.stderr
        assert why in error and 'Traceback' not in done.stderr
