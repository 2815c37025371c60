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
    # The standard simulation_interfaces' services: the type in snake_case, by type or name.
    from simulation_interfaces.srv import GetEntitiesStates
    assert sim.standard(GetEntitiesStates) == '/miro_sim/get_entities_states'
    assert sim.standard('SetEntityState') == '/miro_sim/set_entity_state'


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
    """A sensor row is drawn by the eyes (CAMERA) or made by its producer when its kind says;
    a control row is applied (RobotInterface refuses to start without a handler)."""
    from miro_ball.miro.interface import CAMERA, CONTROL, ROBOT_INTERFACE, SENSOR
    from miro_ball.miro.stream_kinds import BLOCK, LATCHED, Periodic
    from miro_sim_bullet.ros.streams import PRODUCERS

    streams = {row.key for row in ROBOT_INTERFACE if row.direction == SENSOR
               and row.kind != CAMERA}
    assert set(PRODUCERS) == streams
    for row in ROBOT_INTERFACE:
        if row.direction == SENSOR:
            assert row.kind in (CAMERA, BLOCK, LATCHED) or (
                isinstance(row.kind, Periodic) and 0 < row.kind.hz <= 1000), row
        else:
            assert row.direction == CONTROL and row.kind is None, row


def test_each_kind_of_stream_is_due_on_its_own_steps():
    """At a 2 ms step: 50 Hz on every 10th step, 40 Hz on the step nearest each k / 40 s, a
    microphone block (25 ms) on the first platform tick that has all its samples, the eyes
    at camera_rate from the first step; a latched stream on none (sent when made)."""
    from miro_ball.miro.interface import PLATFORM
    from miro_ball.miro.stream_kinds import BLOCK, CAMERA, LATCHED, Periodic, Schedule, \
        Timing

    hum = Periodic(40.0)
    schedule = Schedule([PLATFORM, CAMERA, hum, BLOCK, LATCHED, PLATFORM],
                        Timing(dt=0.002, platform_steps=10, camera_rate=15.0))
    assert schedule.kinds == [PLATFORM, CAMERA, hum, BLOCK]
    due = {}
    for step in range(1, 251):  # half a simulated second
        for kind in schedule.due(step):
            due.setdefault(kind, []).append(step)
    assert due[PLATFORM] == list(range(10, 251, 10))
    assert due[hum] == [round(k / 40 / 0.002) for k in range(1, 21)]  # 12 or 13 apart
    assert due[BLOCK][:5] == [20, 30, 40, 50, 70]  # blocks end at 25, 50, 75, 100, 125 ms
    assert len(due[BLOCK]) == 20  # 40 a second
    assert due[CAMERA] == [1] + [round(k / 15 / 0.002) for k in range(1, 8)]
    schedule.restart()  # a world reset: counted from its start again
    assert schedule.due(10) == [PLATFORM, CAMERA]
