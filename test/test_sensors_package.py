"""sensors/package (miro2_msg/SensorsPackage): every 50 Hz reading of a tick in one stamped
message, the same values as the separate topics of that tick; built at set-up."""
import pytest
from miro2_msg.msg import SensorsPackage
from nav_msgs.msg import Odometry
from sensor_msgs.msg import BatteryState, Imu, Range
from std_msgs.msg import Float32MultiArray, UInt16, UInt32

from miro_ball.common.definitions import package_messages
from miro_ball.miro.interface import default_robot_name, RobotTopics
from rostools import advance_ticks, message_class_without, Probe, spin_until

T = RobotTopics(default_robot_name())


def seconds(stamp):
    return stamp.sec + stamp.nanosec * 1e-9


def test_every_message_of_the_mdk_imports_under_its_ros2_name():
    import miro2_msg.msg as msgs

    names = {'SensorsPackage', 'Affect', 'Sleep', 'AnimalState', 'AnimalAdjust', 'Adjust',
             'AffectAdjust', 'SleepAdjust', 'AffectState', 'Objects', 'ObjectBall',
             'ObjectFace', 'ObjectTag', 'PriorityPeak', 'Push', 'VoiceState', 'FunnelWeb'}
    assert all(hasattr(msgs, name) for name in names)
    assert {t.rsplit('/', 1)[1] for t in package_messages('miro2_msg')} == names
    fields = SensorsPackage.get_fields_and_field_types()
    assert fields['header'] == 'std_msgs/Header' and fields['body_pose'] == 'geometry_msgs/Pose2D'
    assert len(fields) == 19


def test_package_is_50_hz_and_holds_the_ticks_separate_readings(paused_sim, ros_context,
                                                                   executor):
    probe = Probe(ros_context, executor)
    package = probe.watch(SensorsPackage, T.package)
    separate = {'odom': probe.watch(Odometry, T.odom),
                'battery': probe.watch(BatteryState, T.battery),
                'cliff': probe.watch(Float32MultiArray, T.cliff),
                'sonar': probe.watch(Range, T.sonar),
                'imu_head': probe.watch(Imu, T.imu('head')),
                'touch_body': probe.watch(UInt16, T.touch('body')),
                'flags': probe.watch(UInt32, T.sensor_flags),
                'wheel_speed_opto': probe.watch(Float32MultiArray, T.wheel_speed_opto)}
    interface = paused_sim.robots[T.name]
    spin_until(executor, lambda: interface.publisher('package').get_subscription_count() > 0
               and interface.publisher('imu', 'head').get_subscription_count() > 0)
    paused_sim.robots[T.name].robot.set_cmd_vel(0.2, 0.5)  # something that changes each tick
    advance_ticks(paused_sim, executor, 50)
    spin_until(executor, lambda: len(package) >= 50 and all(len(m) >= 50 for m in
                                                            separate.values()))
    assert len(package) == 50  # 50 Hz for 1 s of simulated time
    stamps = [seconds(m.header.stamp) for m in package]
    assert stamps == pytest.approx([0.02 * (k + 1) for k in range(50)])
    assert package[-1].header.frame_id == f'{T.name}/base_link'
    for k in (10, 49):
        tick = package[k]
        assert seconds(tick.header.stamp) == seconds(separate['odom'][k].header.stamp)
        for field, messages in separate.items():
            assert getattr(tick, field) == messages[k], field
    assert package[-1].body_pose.x > 0.05  # it moved: the values are live
    assert package[-1].battery.voltage > 4.0


def test_without_miro2_msg_the_simulator_runs_without_the_package_and_says_so(
        make_sim, ros_context, executor, monkeypatch, capfd):
    """A machine with no compiler has no miro2_msg: every other stream is there."""
    from miro_sim_bullet.ros import robot_interface

    monkeypatch.setattr(robot_interface, 'message_class', message_class_without('miro2_msg'))
    node = make_sim()
    interface = node.robots[T.name]
    assert [row.key for row in interface.missing_types] == ['package']
    with pytest.raises(KeyError):
        interface.publisher('package')
    assert 'sensors/package not published: its type miro2_msg/msg/SensorsPackage is not ' \
           'installed (build it: python -m miro_ball.build_interfaces)' in capfd.readouterr().err
    odom = Probe(ros_context, executor).watch(Odometry, T.odom)
    spin_until(executor, lambda: interface.publisher('odom').get_subscription_count() > 0)
    advance_ticks(node, executor, 5)
    assert spin_until(executor, lambda: len(odom) == 5)
