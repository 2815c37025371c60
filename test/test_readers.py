"""One reader per sensor (miro.readers), and every reader of MiRo's sensors reads through it:
+inf sonar is "nothing in range" everywhere (REP 117), NaN is refused everywhere."""
from types import SimpleNamespace

import pytest
from rclpy.parameter import Parameter
from sensor_msgs.msg import Range
from std_msgs.msg import Float32MultiArray, UInt16

from miro_ball.miro.interface import SENSOR, TOPIC
from miro_ball.miro.readers import NOTHING_IN_RANGE, read, READERS, Refused
from rostools import spin_until

INF, NAN = float('inf'), float('nan')


def test_sonar_inf_is_nothing_in_range_nan_and_negative_are_refused():
    assert read('sonar', Range(range=INF)) == NOTHING_IN_RANGE == READERS['sonar'].nothing
    assert read('sonar', Range(range=0.42)) == pytest.approx(0.42)
    assert read('sonar', Range(range=-INF)) == 0.0  # REP 117: nearer than it can measure
    for bad in (NAN, -0.1):
        with pytest.raises(Refused, match='range'):
            read('sonar', Range(range=bad))


@pytest.mark.parametrize('key, msg', [
    ('cliff', Float32MultiArray(data=[1.0])),
    ('cliff', Float32MultiArray(data=[1.0, NAN])),
    ('cliff', Float32MultiArray(data=[1.0, 1.5])),
    ('light', Float32MultiArray(data=[0.5] * 3)),
    ('light', Float32MultiArray(data=[0.5, 0.5, 0.5, INF])),
    ('kinematic_joints', SimpleNamespace(position=[0.0, 0.1, NAN, 0.0])),
    ('battery', SimpleNamespace(voltage=NAN)),
    ('touch', SimpleNamespace(data='3')),
    ('mics', SimpleNamespace(data=[0] * 7)),
])
def test_each_reader_refuses_what_makes_no_sense_in_one_line(key, msg):
    with pytest.raises(Refused) as refused:
        read(key, msg)
    assert str(refused.value) and '\n' not in str(refused.value)


def test_every_reader_is_a_sensor_stream_with_units():
    for key, reader in READERS.items():
        assert TOPIC[key].direction == SENSOR and reader.units, key


def test_the_robot_object_reads_through_the_readers_as_the_gui_does():
    """Fed +inf, neither complains and both say nothing is in range; fed NaN, both say so
    and keep the last good value."""
    from miro_ball.gui.robot_part import READOUTS
    from miro_ball.robot.readings import READINGS, Readings

    assert {key for key, _ in READINGS.values()} <= READERS.keys()
    assert {key for key, _, _ in READOUTS} <= READERS.keys()

    class Connection:
        def __init__(self):
            self.callbacks, self.warnings = {}, []

        def subscribe(self, msg_type, topic, qos, callback):
            self.callbacks[topic] = callback

        def warn(self, key, text):
            self.warnings.append(text)

    connection = Connection()
    readings = Readings(connection)
    connection.callbacks['sensors/sonar'](Range(range=INF))
    assert readings.sensors().sonar == INF and not connection.warnings
    connection.callbacks['sensors/sonar'](Range(range=NAN))
    assert readings.sensors().sonar == INF and len(connection.warnings) == 1
    assert 'sensors/sonar ignored' in connection.warnings[0]


def test_the_gui_reads_inf_sonar_as_nothing_in_range(ros_context):
    from miro_ball.gui.frames import FrameStore
    from miro_ball.gui.robot_part import READOUTS, RobotPart

    warnings = []
    frames = FrameStore(warn=lambda *a: None, on_frame=lambda *a: None)
    part = RobotPart('miro02', context=ros_context, frames=frames,
                     warn=lambda key, text: warnings.append(text),
                     tell_pages=lambda robot, text: None)
    try:
        sonar = [row for row in READOUTS if row[0] == 'sonar']
        part._take_readouts(sonar, Range(range=INF))
        assert part.values['sonar_text'] == 'inf' and not warnings
        part._take_readouts(sonar, Range(range=NAN))
        assert part.values['sonar'] == INF and len(warnings) == 1
    finally:
        part.destroy_node()


@pytest.mark.parametrize('kind', ['kick_blue_ball', 'demo_mode'])
def test_fed_inf_sonar_no_controller_complains_nan_is_refused(ros_context, executor, kind):
    from miro_ball.animal.demo_mode import DEMO_MODE
    from miro_ball.controller.host import ControllerHost
    from miro_ball.controller.kick_blue_ball import KICK_BLUE_BALL

    hosted = {'kick_blue_ball': KICK_BLUE_BALL, 'demo_mode': DEMO_MODE}[kind]
    node = ControllerHost(hosted, context=ros_context, robot='miro_readers',
                          parameter_overrides=[Parameter('use_sim_time', value=False)])
    probe = node.create_publisher(Range, 'sensors/sonar', 10)
    touch = node.create_publisher(UInt16, 'sensors/touch_head', 10)
    executor.add_node(node)
    try:
        spin_until(executor, lambda: probe.get_subscription_count() > 0, what='discovery')
        probe.publish(Range(range=INF))
        sonar = node.readings['sonar']
        spin_until(executor, lambda: sonar.value is not None, what='the +inf reading')
        assert sonar.value == INF and not node.rejected
        assert node.percepts(sonar.stamp).sonar == INF
        probe.publish(Range(range=NAN))
        touch.publish(UInt16(data=5))  # sent after the NaN: when it is in, so is the NaN
        spin_until(executor, lambda: node.readings['touch_head'].value == 5, what='touch')
        assert node.rejected == {'sonar': 1} and sonar.value == INF
    finally:
        executor.remove_node(node)
        node.destroy_node()
