"""MiRo's names: one module says them, for any robot name."""
import pytest

from miro_ball.controller.names import debug_topic
from miro_ball.miro.interface import (EYES, RobotTopics, SimTopics, check_name,
                                      default_robot_name, frame_id, robot_name, robot_namespace,
                                      robot_of_namespace, ROBOT_INTERFACE, TOPIC)


def test_topics_live_under_the_robot_name():
    t = RobotTopics('miro02')
    assert t.cmd_vel == '/miro02/control/cmd_vel'
    assert t.eye_compressed('caml') == '/miro02/sensors/caml/compressed'
    assert t.camera_info('camr') == '/miro02/sensors/camr/camera_info'
    assert t.imu('head') == '/miro02/sensors/imu_head'
    assert RobotTopics().cmd_vel == 'control/cmd_vel'  # relative, for a node in the namespace
    assert debug_topic('miro02', 'caml') == '/miro02/kick_blue_ball/debug/caml/compressed'
    assert frame_id('miro02', 'base_link') == 'miro02/base_link'
    assert EYES == ('caml', 'camr')


def test_the_simulator_has_names_of_its_own():
    sim = SimTopics()
    assert sim.ball == '/miro_sim/ball' and sim.set_pose == '/miro_sim/set_pose'
    assert sim.object_pose('cube') == '/miro_sim/objects/cube'


@pytest.mark.parametrize('name', ['', 'bad name', '2miro', 'miro/02', 'm' * 65, 7])
def test_names_that_cannot_be_ros_namespaces_are_refused_in_one_line(name):
    with pytest.raises(ValueError) as err:
        RobotTopics(name)
    assert '\n' not in str(err.value)


def test_default_name_follows_the_mdk_environment_variable():
    assert default_robot_name({}) == 'miro'
    assert default_robot_name({'MIRO_ROBOT_NAME': 'miro03'}) == 'miro03'
    assert check_name('miro_03') == 'miro_03'


def test_one_rule_names_the_robot():
    assert robot_name(environ={}) == 'miro'
    assert robot_name(environ={'MIRO_ROBOT_NAME': 'miro03'}) == 'miro03'
    assert robot_name('miro04', environ={'MIRO_ROBOT_NAME': 'miro03'}) == 'miro04'
    assert robot_namespace('miro04') == '/miro04'
    assert robot_of_namespace('/class_a/miro05') == 'miro05'
    with pytest.raises(ValueError, match="--robot '1x' must be"):
        robot_name('1x')
    with pytest.raises(ValueError, match=r"\$MIRO_ROBOT_NAME 'a b' must be"):
        robot_name(environ={'MIRO_ROBOT_NAME': 'a b'})


def test_the_interface_is_one_table_with_one_eye_qos():
    assert len({row.key for row in ROBOT_INTERFACE}) == len(ROBOT_INTERFACE)
    assert len({row.name for row in ROBOT_INTERFACE}) == len(ROBOT_INTERFACE)
    eyes = {TOPIC[key].qos for key in ('eye_compressed', 'eye_raw', 'camera_info')}
    assert len(eyes) == 1
    assert {row.direction for row in ROBOT_INTERFACE} == {'sensor', 'control'}
    prefix = {'sensor': 'sensors/', 'control': 'control/'}  # as on the real MiRo
    ros_names = {'joint_states', 'robot_description'}  # robot_state_publisher's, for the body
    assert all(row.name.startswith(prefix[row.direction]) or row.name in ros_names
               for row in ROBOT_INTERFACE)


def test_every_row_of_the_interface_is_served_by_the_simulator():
    """A sensor row is drawn by the eyes (CAMERA), heard by the ears (MICS) or made by a
    producer at its rate; a control row is applied (RobotInterface refuses to start
    without a handler)."""
    from miro_ball.miro.interface import CAMERA, CONTROL, MICS, ONCE, ROBOT_INTERFACE, SENSOR
    from miro_sim_bullet.ros.streams import PRODUCERS

    streams = {row.key for row in ROBOT_INTERFACE if row.direction == SENSOR
               and row.rate not in (CAMERA, MICS)}
    assert set(PRODUCERS) == streams
    for row in ROBOT_INTERFACE:
        if row.direction == SENSOR:
            assert row.rate in (CAMERA, MICS, ONCE) or 0 < row.rate <= 1000, row
        else:
            assert row.direction == CONTROL and row.rate is None, row
