"""The scene as markers and link frames: what RViz, Foxglove and the GUI's world view draw.

Built straight from the simulated world (no ROS graph): every object of every bundled world
is there as the world file says, the movers go out only when they move, a robot's markers
hang in link frames whose poses are the simulator's own.
"""
import math

import numpy as np
import pytest
from visualization_msgs.msg import Marker

from miro_ball.miro.constants import LINK_FRAMES, LINK_NAMES
from miro_ball.miro.interface import BALL_NAME, EYE_SIDE, frame_id
from miro_sim_bullet.physics.world import SimWorld
from miro_sim_bullet.ros.frames import quaternion, RobotLinks
from miro_sim_bullet.ros.scene import SceneMarkers
from miro_sim_bullet.physics import model as rb
from miro_sim_bullet.ros import convert
from miro_sim_bullet.scene.world_file import bundled_worlds


def rotation_of(q):
    x, y, z, w = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


@pytest.fixture(scope='module', params=bundled_worlds())
def built(request):
    world = SimWorld(request.param)
    yield world
    world.close()


def test_every_object_of_the_world_file_is_drawn(built):
    description = built.description
    layout = SceneMarkers(built).layout().markers
    movers = SceneMarkers(built).movers_if_moved().markers
    namespaces = {m.ns for m in layout + movers}
    assert set(built.robots) <= namespaces
    assert {shape.name for shape in description.shapes if shape.name} <= namespaces
    statics = [m for m in layout if m.header.frame_id == 'world' and m.ns != 'picture']
    unnamed = sum(1 for shape in description.shapes if shape.mass == 0)
    ground = description.ground_height is not None
    assert len(statics) >= unnamed + ground
    if description.ball is not None:
        ball, = [m for m in movers if m.ns == BALL_NAME]
        assert ball.type == Marker.SPHERE and ball.header.frame_id == 'world'
        assert ball.scale.x == ball.scale.y == ball.scale.z == pytest.approx(
            2 * description.ball.radius)
        assert (ball.color.r, ball.color.g, ball.color.b) == pytest.approx(
            description.ball.colour)
        assert ball.pose.position.z == pytest.approx(description.ball.floor + description.ball.radius,
                                                     abs=0.01)
    keys = [(m.ns, m.id) for m in layout + movers]
    assert len(keys) == len(set(keys)), 'a marker would replace another'


def test_a_robot_hangs_in_its_link_frames(built):
    layout = SceneMarkers(built).layout().markers
    for name in built.robots:
        mine = [m for m in layout if m.ns == name]
        assert mine and all(m.frame_locked for m in mine)
        assert {m.header.frame_id for m in mine} <= {frame_id(name, n) for n in LINK_NAMES}
        assert {m.text for m in mine} >= {'body', 'head', 'ear_l', 'ear_r', 'tail'}


def test_movers_go_out_when_they_move_and_only_then():
    world = SimWorld('miro')
    markers = SceneMarkers(world)
    assert markers.movers_if_moved() is not None  # the first time: where they are
    world.run(0.2)
    assert markers.movers_if_moved() is None  # the ball lies still
    world.set_object_pose(BALL_NAME, (0.3, 0.4, None), None)
    ball, = [m for m in markers.movers_if_moved().markers if m.ns == BALL_NAME]
    assert (ball.pose.position.x, ball.pose.position.y) == pytest.approx((0.3, 0.4))
    world.close()


def test_the_layout_is_sent_again_when_the_leds_change():
    world = SimWorld('empty')
    markers = SceneMarkers(world)
    markers.layout()
    assert not markers.colours_changed()
    world.robot.set_illum([0xFFFF0000] * 6)
    assert markers.colours_changed()
    red = [m for m in markers.layout().markers if m.text.startswith('led_')]
    assert len(red) == 6 and all((m.color.r, m.color.g) == (1.0, 0.0) for m in red)
    world.close()


def test_the_link_frames_are_where_the_simulator_has_them():
    world = SimWorld('empty')
    robot = world.robot
    robot.set_kinematic_targets((0.0, 0.5, 0.6, -0.1))
    world.run(1.0)
    links = RobotLinks(world, robot.name)
    frames = {name: (rotation_of(q), np.array(p)) for name, (p, q) in
              zip(LINK_FRAMES, links.frames())}
    assert len(frames) == len(LINK_FRAMES) == len(links.frames())
    message = links.message(convert.stamp(world.time))
    assert message.header.frame_id == 'world' and len(message.poses) == len(LINK_FRAMES)
    for eye in ('caml', 'camr'):
        position, rotation = robot.eye_pose(EYE_SIDE[eye])
        optical_rot, optical_pos = frames[f'{eye}_optical']
        assert optical_pos == pytest.approx(position, abs=1e-6)
        assert optical_rot[:, 2] == pytest.approx(rotation[:, 0], abs=1e-6)  # z looks out
        assert optical_rot[:, 0] == pytest.approx(-rotation[:, 1], abs=1e-6)  # x right
        pose = message.poses[LINK_FRAMES.index(f'{eye}_optical')]
        q = (pose.orientation.x, pose.orientation.y, pose.orientation.z, pose.orientation.w)
        assert rotation_of(q) == pytest.approx(optical_rot, abs=1e-6)
    head_rot, head_pos = frames['head']
    position, rotation = robot.link_frame(rb.HEAD)
    assert head_pos == pytest.approx(position, abs=1e-6)
    assert head_rot == pytest.approx(rotation, abs=1e-6)
    world.close()


@pytest.mark.parametrize('angles', [(0, 0, 0), (math.pi, 0, 0), (0, math.pi, 0),
                                    (0.3, -2.0, 3.1), (math.pi / 2, math.pi / 2, 0)])
def test_quaternions_turn_as_their_matrices(angles):
    from miro_sim_bullet.bullet import pybullet as pb
    matrix = np.array(pb.getMatrixFromQuaternion(pb.getQuaternionFromEuler(angles))).reshape(3, 3)
    assert rotation_of(quaternion(matrix)) == pytest.approx(matrix, abs=1e-6)
