"""The ros2 command line's message <-> YAML conversion and interface text, without a graph."""
import math

import pytest
import yaml
from geometry_msgs.msg import PoseArray, PoseWithCovariance, TwistStamped
from sensor_msgs.msg import Image
from std_msgs.msg import ByteMultiArray, Float32MultiArray, UInt8MultiArray

from miro_ball.ros2.interface_text import shown
from miro_ball.ros2.convert import field, fill, parse_yaml, to_data, to_yaml


def test_yaml_round_trips_a_message_in_field_order():
    msg = fill(TwistStamped(), parse_yaml('{header: {frame_id: miro/base_link}, '
                                          'twist: {linear: {x: 0.2}, angular: {z: -1}}}'))
    text = to_yaml(to_data(msg))
    assert text.splitlines()[:2] == ['header:', '  stamp:']
    assert fill(TwistStamped(), yaml.safe_load(text)) == msg
    assert field(msg, 'twist.angular.z') == -1.0


def test_long_arrays_are_cut_as_ros2_echo_cuts_them_and_nan_is_yaml():
    data = to_data(Image(data=bytes(300)))
    assert len(data['data']) == 129 and data['data'][-1] == '...'
    assert math.isnan(yaml.safe_load(to_yaml(to_data(Float32MultiArray(data=[math.nan]))))
                      ['data'][0])


def test_a_list_of_messages_is_filled_from_a_list_of_mappings():
    msg = fill(PoseArray(), {'poses': [{'position': {'x': 1.0}}, {}]})
    assert [p.position.x for p in msg.poses] == [1.0, 0.0]


def test_a_number_yaml_1_1_reads_as_text_fills_a_float_field_as_ros2_does():
    """PyYAML reads 1e-3 (no dot) as text: {x: 1e-3} was 'give a number, not '1e-3''."""
    msg = fill(TwistStamped(), parse_yaml('{twist: {linear: {x: 1e-3, y: -2E+2, z: .5e1}}}'))
    assert (msg.twist.linear.x, msg.twist.linear.y, msg.twist.linear.z) == (0.001, -200.0, 5.0)
    assert list(fill(Float32MultiArray(), parse_yaml('{data: [1e2]}')).data) == [100.0]
    for text in ('1e', 'e5', '1e5x', '0x10', 'inf'):
        with pytest.raises(ValueError, match='give a number'):
            fill(TwistStamped(), {'twist': {'linear': {'x': text}}})


@pytest.mark.parametrize('values,says', [
    ({'twist': {'linar': {}}}, "no field 'twist.linar'"),
    ({'twist': {'linear': {'x': 'fast'}}}, 'give a number'),
    ({'twist': 3}, 'give a mapping'),
    ({'header': {'stamp': {'sec': 1.5}}}, 'give an integer'),
])
def test_a_value_that_does_not_fit_is_named(values, says):
    with pytest.raises(ValueError, match=says):
        fill(TwistStamped(), values)


@pytest.mark.parametrize('cls,values,says', [
    # The generated classes check nothing by default: uint8 300 went out as 44, -1 and a
    # list item that is no mapping were tracebacks.
    (UInt8MultiArray, {'data': [1, 300]}, r'data\[1\] is a uint8: give an integer from 0 to 255'),
    (UInt8MultiArray, {'layout': {'data_offset': -1}}, 'from 0 to 4294967295, not -1'),
    (PoseArray, {'poses': [3]}, r'poses\[0\] is a Pose: give a mapping'),
    (PoseWithCovariance, {'covariance': [1.0]}, 'holds exactly 36 items'),
    (Float32MultiArray, {'data': [1.0, 'a']}, r'data\[1\] is a float: give a number'),
])
def test_integer_ranges_array_sizes_and_list_items_are_checked(cls, values, says):
    with pytest.raises(ValueError, match=says):
        fill(cls(), values)
    assert list(fill(ByteMultiArray(), {'data': [0, 255]}).data) == [b'\x00', b'\xff']


def test_a_type_name_of_any_length_is_refused_in_a_short_line():
    """interface show of a 100,000-letter name printed all of it back, and one of a name
    past 255 letters was a traceback ('File name too long')."""
    from miro_ball.common.definitions import package_messages
    from miro_ball.ros2.graph import CliError
    from miro_ball.ros2.verbs import interface_class

    for name in ('a' * 100_000, 'a' * 100_000 + '/msg/X', 'std_msgs/msg/' + 'X' * 100_000,
                 'std_msgs/msg/' + 'X' * 300):
        for look_up in (interface_class, shown):
            with pytest.raises((ValueError, CliError)) as refused:
                look_up(name)
            assert len(str(refused.value)) < 300 and '\n' not in str(refused.value)
    assert package_messages('x' * 300) == {}


def test_interface_text_expands_nested_types_a_tab_in():
    lines = shown('geometry_msgs/msg/TwistStamped')
    assert 'std_msgs/Header header' in lines and '\t\tint32 sec' in lines
    with pytest.raises(ValueError, match='not a type name'):
        shown('twist')


def test_interface_text_keeps_the_comments_ros2_keeps():
    """As ros2 interface show reads a file (rosidl's parser, line by line): a nested type's
    field comments go, but a constant's comment and a lone '#' stay; we dropped them all."""
    lines = shown('action_msgs/msg/GoalInfo')
    assert lines[:3] == ['# Goal ID', 'unique_identifier_msgs/UUID goal_id', '\t#']
    battery = shown('miro2_msg/msg/SensorsPackage')
    assert '\tuint8 POWER_SUPPLY_TECHNOLOGY_LION = 2    # Lithium-ion battery' in battery
    voltage = '\tfloat32 voltage          # Voltage in Volts (Mandatory)'
    assert voltage not in battery  # a field's comment, cut (to its '#', as ros2 cuts it)
    assert voltage in shown('miro2_msg/msg/SensorsPackage', nested_comments=True)
    bare = shown('action_msgs/msg/GoalInfo', comments=False)
    assert bare == ['unique_identifier_msgs/UUID goal_id', '\t#', '\tuint8[16] uuid',
                    'builtin_interfaces/Time stamp', '\tint32 sec', '\tuint32 nanosec']


def test_values_nested_deeper_than_any_message_are_refused_as_they_are_read():
    from miro_ball.ros2.convert import MAX_DEPTH

    assert parse_yaml('{a: ' + '[' * (MAX_DEPTH - 1) + ']' * (MAX_DEPTH - 1) + '}')
    for depth in (MAX_DEPTH, 5000):
        with pytest.raises(ValueError, match='nested too deeply'):
            parse_yaml('{a: ' + '[' * depth + ']' * depth + '}')
