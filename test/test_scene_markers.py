"""The scene as markers and the robots' frames: what RViz, Foxglove and the GUI's world view
draw.

Built straight from the simulated world (no ROS graph): every object of every bundled world
is there as the world file says, the movers go out only when they move, a robot's LEDs hang
in link frames whose poses on /tf are the simulator's own.
"""
import pytest
from visualization_msgs.msg import Marker

from miro_ball.miro.body import ILLUM_NAMES
from miro_ball.miro.interface import BALL_NAME, EYE_SIDE, frame_id
from miro_ball.miro.tf_tree import TfTree
from miro_sim_bullet.physics.world import SimWorld
from miro_sim_bullet.ros.scene import SceneMarkers
from miro_sim_bullet.physics import model as rb
from miro_sim_bullet.ros import convert, tf
from miro_sim_bullet.scene.world_file import bundled_worlds


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


def test_a_robots_leds_hang_in_their_link_frames(built):
    """The robots are drawn from their robot_description; the scene adds their LEDs' colours."""
    layout = SceneMarkers(built).layout().markers
    for name in built.robots:
        mine = [m for m in layout if m.ns == name]
        assert all(m.frame_locked for m in mine)
        assert sorted(m.header.frame_id for m in mine) == sorted(
            frame_id(name, led) for led in ILLUM_NAMES)


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
    assert not markers.layout_changed()
    world.robot.set_illum([0xFFFF0000] * 6)
    assert markers.layout_changed()
    red = [m for m in markers.layout().markers if m.text.startswith('led_')]
    assert len(red) == 6 and all((m.color.r, m.color.g) == (1.0, 0.0) for m in red)
    world.close()


def test_the_frames_on_tf_are_where_the_simulator_has_the_links():
    """/tf's transforms of one tick, composed, put the head and the eyes' optical frames
    where the simulator draws the eyes from."""
    world = SimWorld('empty')
    robot = world.robot
    robot.set_kinematic_targets((0.0, 0.5, 0.6, -0.1))
    world.run(1.0)
    when = convert.stamp(world.time)
    tree = TfTree()
    assert tree.set_message(tf.static_transforms([robot.name], when)) == []
    for (parent, child), pose in zip(tf.robot_pairs(robot.name),
                                     tf.robot_poses([robot.sensors])[0]):
        tree.set(parent, child, pose[:3], pose[3:])
    for eye in ('caml', 'camr'):
        position, rotation = robot.eye_pose(EYE_SIDE[eye])
        optical = tree.lookup('world', frame_id(robot.name, f'{eye}_optical'))
        assert optical[:3, 3] == pytest.approx(position, abs=1e-5)
        assert optical[:3, 2] == pytest.approx(rotation[:, 0], abs=1e-5)  # z looks out
        assert optical[:3, 0] == pytest.approx(-rotation[:, 1], abs=1e-5)  # x right
    head = tree.lookup('world', frame_id(robot.name, 'head'))
    position, rotation = robot.link_frame(rb.HEAD)
    assert head[:3, 3] == pytest.approx(position, abs=1e-5)
    assert head[:3, :3] == pytest.approx(rotation, abs=1e-5)
    world.close()
