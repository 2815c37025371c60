"""Every parameter of both nodes set at run time at its bounds and beyond: applied (or, for
those read only at start, refused with the reason), never accepted and ignored, and the
node keeps working."""
from dataclasses import fields

from rclpy.parameter import Parameter

from miro_ball.controller.params import GROUPS
from miro_sim_bullet.ros.node import FIXED_PARAMS
from miro_sim_bullet.ros.params import SimParams
from test_param_bounds import beyond

CONTROLLER_FIXED = ('tick',)


def exercise(node, groups, fixed, current):
    """Set every bounded parameter to its bounds and beyond; current(name) reads the value
    the node works with."""
    for cls in groups:
        for f in fields(cls):
            if 'range' not in f.metadata or isinstance(f.default, tuple):
                continue
            low, high = f.metadata['range']
            for value in (low, high):
                result = node.set_parameters([Parameter(f.name, value=value)])[0]
                if f.name in fixed:
                    assert not result.successful and 'restart' in result.reason, f.name
                elif result.successful:
                    assert current(f.name) == value, f.name
                else:  # only a rule between two parameters may refuse a value in range
                    assert 'min_radius' in result.reason or 'odd' in result.reason, \
                        (f.name, result.reason)
            for value in beyond(low, high):
                before = current(f.name)
                result = node.set_parameters([Parameter(f.name, value=value)])[0]
                assert not result.successful and current(f.name) == before, f.name


def test_simulator_parameters_at_run_time(paused_sim):
    node = paused_sim
    exercise(node, [SimParams], FIXED_PARAMS, lambda name: getattr(node.params, name))
    node.set_parameters([Parameter('real_time_factor', value=0.0),
                         Parameter('step_count', value=20)])
    before = node.sim.time
    node.advance(100)
    assert node.sim.time > before


def test_controller_parameters_at_run_time(ros_context, executor):
    from test_controller_node import drives_at_a_ball_ahead, Rig, short_hold

    rig = Rig(ros_context, executor, short_hold())
    node = rig.node
    try:
        def current(name):
            for values in node.values.values():
                if hasattr(values, name):
                    return getattr(values, name)
        exercise(node, GROUPS, CONTROLLER_FIXED, current)
        # Back to the defaults, and it drives at the ball.
        defaults = [Parameter(f.name, value=f.default) for cls in GROUPS[1:]
                    for f in fields(cls) if not isinstance(f.default, tuple)]
        assert all(r.successful for r in node.set_parameters(defaults))
        node.set_parameters([Parameter('head_hold_s', value=0.1)])
        assert drives_at_a_ball_ahead(rig)
    finally:
        rig.close()


def test_a_flood_of_changes_is_a_few_log_lines_and_each_is_applied(paused_sim, capfd):
    """A client toggling a switch a thousand times a second logged a line a change (demo
    mode's core/config/command: 1,900 lines in 6 s)."""
    node = paused_sim
    capfd.readouterr()
    for index in range(200):
        quality = 50 + index % 2
        assert node.set_parameters([Parameter('jpeg_quality', value=quality)])[0].successful
        assert node.params.jpeg_quality == quality
    said = [line for line in capfd.readouterr().err.splitlines() if 'set at run time' in line]
    assert 1 <= len(said) <= 2, said


def test_an_integer_for_a_float_parameter_is_held_as_a_double(make_sim):
    """-p real_time_factor:=0 is an integer to ROS: the parameter held it as one, and
    ros2 param get said "Integer value is: 0" of a double parameter; so did a run-time set."""
    node = make_sim(real_time_factor=0)
    held, = node.get_parameters(['real_time_factor'])
    assert (held.type_, held.value) == (Parameter.Type.DOUBLE, 0.0)
    assert node.set_parameters([Parameter('real_time_factor', value=2)])[0].successful
    held, = node.get_parameters(['real_time_factor'])
    assert (held.type_, held.value, node.params.real_time_factor) == (Parameter.Type.DOUBLE,
                                                                      2.0, 2.0)
    # Not a bool, and not a parameter that is an integer: those stay as they are.
    assert not node.set_parameters([Parameter('real_time_factor', value=True)])[0].successful
    assert node.set_parameters([Parameter('jpeg_quality', value=60)])[0].successful
    assert node.get_parameters(['jpeg_quality'])[0].type_ == Parameter.Type.INTEGER
