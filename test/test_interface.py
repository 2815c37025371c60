"""MiRo's names: one module says them, for any robot name."""
import pytest

from miro_ball.miro.interface import (EYES, RobotTopics, SimTopics, check_name,
                                      default_robot_name)


def test_topics_live_under_the_robot_name():
    t = RobotTopics('miro02')
    assert t.cmd_vel == '/miro02/control/cmd_vel'
    assert t.eye_compressed('caml') == '/miro02/sensors/caml/compressed'
    assert t.camera_info('camr') == '/miro02/sensors/camr/camera_info'
    assert t.imu('head') == '/miro02/sensors/imu_head'
    assert t.controller_debug('caml') == '/miro02/kick_blue_ball/debug/caml/compressed'
    assert EYES == ('caml', 'camr')


def test_the_simulator_has_names_of_its_own():
    sim = SimTopics()
    assert sim.ball == '/miro_sim/ball' and sim.set_pose == '/miro_sim/set_pose'
    assert sim.object_pose('cube') == '/miro_sim/objects/cube'


@pytest.mark.parametrize('name', ['', 'bad name', '2miro', 'miro/02', 'm' * 65, None, 7])
def test_names_that_cannot_be_ros_namespaces_are_refused_in_one_line(name):
    with pytest.raises(ValueError) as err:
        RobotTopics(name)
    assert '\n' not in str(err.value)


def test_default_name_follows_the_mdk_environment_variable():
    assert default_robot_name({}) == 'miro'
    assert default_robot_name({'MIRO_ROBOT_NAME': 'miro03'}) == 'miro03'
    assert check_name('miro_03') == 'miro_03'
