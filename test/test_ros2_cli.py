"""python -m miro_ball.ros2: ros2's everyday verbs against a running simulator, as a student
types them (each a process; the world is stepped by the test while it runs)."""
import os
import subprocess
import sys
import threading

import pytest
import rclpy
import yaml

from miro_ball.common.isolation import isolated_env
from miro_ball.miro.interface import default_robot_name, RobotTopics, SIM_NODE_NAME
from rostools import advance_until, kill_if_running, spin_until

T = RobotTopics(default_robot_name())
SIM = '/' + SIM_NODE_NAME


def ros2(args, paused_sim, executor, until=None):
    """(exit code, stdout, stderr) of one command; the world runs until it ends (or, with
    until(stdout so far), until that holds, when it is stopped)."""
    proc = subprocess.Popen([sys.executable, '-m', 'miro_ball.ros2', *args],
                            env=isolated_env(int(os.environ['ROS_DOMAIN_ID'])),
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        advance_until(paused_sim, executor, lambda: proc.poll() is not None)
        out, err = proc.communicate(timeout=10)
    finally:
        kill_if_running(proc)
    return proc.returncode, out, err


def test_topic_list_names_every_topic_of_the_robot_with_its_type(paused_sim, executor):
    code, out, _ = ros2(['topic', 'list', '-t'], paused_sim, executor)
    listed = dict(line.rsplit(' ', 1) for line in out.splitlines())
    assert code == 0
    assert set(T.all()) <= set(listed)
    assert listed[T.package] == '[miro2_msg/msg/SensorsPackage]'
    assert listed[T.cmd_vel] == '[geometry_msgs/msg/TwistStamped]'


def test_listings_wait_for_the_whole_graph_and_agree_run_after_run(paused_sim, executor):
    """Each process is heard of in its own time (seconds apart on a busy machine): a listing
    that answered after a fixed moment left nodes and topics out, differently each run."""
    env = isolated_env(int(os.environ['ROS_DOMAIN_ID']))
    others = [subprocess.Popen([sys.executable, '-m', 'miro_ball.ros2', 'topic', 'pub',
                                f'/listed_{k}', 'std_msgs/msg/String', '{data: hi}'],
                               env=env, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                               text=True) for k in range(2)]
    try:
        for proc in others:  # its node is made before it says so
            assert proc.stdout.readline().startswith('publisher: beginning loop')
        nodes = {f'/miro_ball_ros2_{proc.pid}' for proc in others} | {SIM}
        for verb, runs, expected in (('node', 2, nodes),
                                     ('topic', 2, {'/listed_0', '/listed_1', *T.all()})):
            answers = [ros2([verb, 'list'], paused_sim, executor) for _ in range(runs)]
            assert all(code == 0 and 'incomplete' not in err for code, _, err in answers)
            assert len({out for _, out, _ in answers}) == 1
            assert expected <= set(answers[0][1].split())
    finally:
        for proc in others:
            kill_if_running(proc)


def test_topic_info_names_the_node_of_each_endpoint(paused_sim, executor):
    # It answered as soon as the topic was heard of, before the name of its node.
    code, out, _ = ros2(['topic', 'info', '-v', T.package], paused_sim, executor)
    assert code == 0 and 'Publisher count: 1' in out
    assert f'Node name: {SIM_NODE_NAME}\n' in out and '_NODE_NAME_UNKNOWN_' not in out


@pytest.mark.parametrize('changes,consistent,whole', [
    ((0.0,), True, True),  # all heard of at once: answered at MIN_S
    ((0.0, 3.0), True, True),  # the last process heard of 3 s in: answered STABLE_S later
    ((0.0,), False, False),  # an endpoint never has its node: at LIMIT_S, said partial
    (tuple(round(0.8 * k, 1) for k in range(13)), True, False),  # never still to the end
])
def test_a_listing_is_the_answer_once_still_and_consistent(changes, consistent, whole):
    from miro_ball.ros2.settling import LIMIT_S, MIN_S, Settling, STABLE_S

    settling, now = Settling(0.0), 0.0
    while not settling.see(now, sum(t <= now for t in changes), consistent):
        now = round(now + 0.1, 1)
    assert settling.whole == whole and settling.listing == sum(t <= now for t in changes)
    assert now == (max(MIN_S, changes[-1] + STABLE_S) if whole else LIMIT_S)


def test_echo_once_prints_a_message_as_yaml_and_a_field_alone(paused_sim, executor):
    code, out, _ = ros2(['topic', 'echo', T.battery, '--once'], paused_sim, executor)
    assert code == 0 and out.endswith('---\n')
    battery = yaml.safe_load(out.split('---')[0])
    assert battery['voltage'] == pytest.approx(4.8)
    assert battery['header']['frame_id'] == f'{T.name}/base_link'
    code, out, _ = ros2(['topic', 'echo', T.package, '--once', '--field', 'cliff.data'],
                        paused_sim, executor)
    assert code == 0 and yaml.safe_load(out.split('---')[0]) == [1.0, 1.0]


def test_pub_at_a_rate_drives_miro(paused_sim, executor):
    code, out, _ = ros2(['topic', 'pub', T.cmd_vel, 'geometry_msgs/msg/TwistStamped',
                         '{twist: {linear: {x: 0.2}}}', '-r', '10', '-t', '10'],
                        paused_sim, executor)
    x, _, _ = paused_sim.sim.robots[T.name].pose()
    assert code == 0 and 'publishing #10' in out
    assert x > 0.05


def test_hz_is_fifty_in_simulated_time(paused_sim, executor):
    proc = subprocess.Popen([sys.executable, '-m', 'miro_ball.ros2', 'topic', 'hz', T.package],
                            env=isolated_env(int(os.environ['ROS_DOMAIN_ID'])),
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    lines = []
    reader = threading.Thread(target=lambda: lines.extend(proc.stdout), daemon=True)
    reader.start()
    try:
        advance_until(paused_sim, executor, lambda: proc.poll() is not None
                      or any('average rate' in line for line in lines))
    finally:
        kill_if_running(proc)
    rate = next(line for line in lines if 'average rate' in line)
    assert float(rate.split(':')[1]) == pytest.approx(50.0, abs=2.0)


def test_interface_show_lists_miros_own_fields():
    out = subprocess.run([sys.executable, '-m', 'miro_ball.ros2', 'interface', 'show',
                          'miro2_msg/msg/SensorsPackage'], capture_output=True, text=True,
                         timeout=60)
    assert out.returncode == 0
    top = [line.split()[1] for line in out.stdout.splitlines()
           if line and not line.startswith(('#', '\t'))]
    assert top[:3] == ['header', 'battery', 'cliff'] and top[-1] == 'body_pose'
    assert '\tfloat32 voltage' in out.stdout  # BatteryState expanded under battery
    # The comments ros2 keeps: the type's own, and a nested constant's (they were dropped)
    assert out.stdout.startswith('# Every 50 Hz sensor reading of one platform tick')
    assert '\tuint8 POWER_SUPPLY_TECHNOLOGY_LION = 2    # Lithium-ion battery\n' in out.stdout


def test_params_and_services_of_the_simulator(paused_sim, executor):
    code, out, _ = ros2(['param', 'get', SIM, 'camera_rate'], paused_sim, executor)
    assert code == 0 and out.strip() == 'Double value is: 15.0'
    code, out, _ = ros2(['param', 'list', SIM], paused_sim, executor)
    assert code == 0 and '  camera_rate' in out.splitlines()
    # A refusal is said on stderr with exit status 0, as ros2 param set does (it was 1)
    code, out, err = ros2(['param', 'set', SIM, 'camera_rate', '10'], paused_sim, executor)
    assert (code, out) == (0, '') and err.startswith('Setting parameter failed: camera_rate '
                                                     'is read at start only'), err
    code, out, err = ros2(['param', 'set', SIM, 'camera_rat', '10'], paused_sim, executor)
    assert (code, out) == (0, '') and err.startswith(  # not rclpy's "Invalid access to ..."
        "Setting parameter failed: no parameter 'camera_rat' on /miro_sim; did you mean "
        "'camera_rate'") and len(err.splitlines()) == 1, err
    paused_sim.robots[T.name].robot.set_cmd_vel(0.3, 0.0)
    advance_until(paused_sim, executor, lambda: paused_sim.sim.robots[T.name].pose()[0] > 0.05)
    code, out, _ = ros2(['service', 'call', f'{SIM}/reset_simulation',
                         'simulation_interfaces/srv/ResetSimulation'], paused_sim, executor)
    assert code == 0 and 'Result(result=1,' in out.split('response:')[1]  # RESULT_OK
    assert abs(paused_sim.sim.robots[T.name].pose()[0]) < 0.01  # back where it started


def test_a_service_call_says_it_waits_for_a_service_not_there_yet(ros_context, executor):
    """ros2 service call's line while its service is not there (it was never printed); once
    the service comes, the request goes and its answer is printed."""
    from std_srvs.srv import Trigger

    proc = subprocess.Popen([sys.executable, '-m', 'miro_ball.ros2', 'service', 'call',
                             '/late/trigger', 'std_srvs/srv/Trigger'],
                            env=isolated_env(int(os.environ['ROS_DOMAIN_ID'])),
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        assert proc.stdout.readline() == 'waiting for service to become available...\n'
        node = rclpy.create_node('late', context=ros_context)
        node.create_service(Trigger, '/late/trigger',
                            lambda request, response: Trigger.Response(success=True))
        executor.add_node(node)
        spin_until(executor, lambda: proc.poll() is not None, 30.0, 'the call to end')
        out, err = proc.communicate(timeout=10)
    finally:
        kill_if_running(proc)
    assert (proc.returncode, err) == (0, ''), err
    assert out.startswith('requester: making request: std_srvs.srv.Trigger_Request(')
    assert 'response:\nstd_srvs.srv.Trigger_Response(success=True' in out


@pytest.mark.parametrize('args,says', [
    (['topic', 'echo', '/nothing/here', '--once'], 'no topic /nothing/here'),
    (['topic', 'echo', T.odom, '--once', '--field', 'pose.x'], "no field 'x'"),
    (['topic', 'pub', T.cmd_vel, 'geometry_msgs/msg/TwistStamped', '{twist: {linar: {}}}',
      '--once'], "no field 'twist.linar'"),
    (['topic', 'pub', T.cmd_vel, 'geometry_msgs/msg/TwistStamped', '{twist: [', '--once'],
     'not valid YAML'),
    (['topic', 'pub', T.cmd_vel, 'geometry_msgs/msg/Twistt', '{}', '--once'],
     'no interface geometry_msgs/msg/Twistt'),
    (['interface', 'show', 'nonsense'], 'is not a type name'),
    (['param', 'get', '/no_such_node', 'x'], 'no node /no_such_node'),
    (['param', 'get', SIM, 'camera_rat'],  # not rclpy's "Invalid access to undeclared"
     "no parameter 'camera_rat' on /miro_sim; did you mean 'camera_rate'"),
    (['topic', 'pub', '--once', '/bad topic', 'std_msgs/msg/String', '{data: hi}'],
     "'/bad topic' is not a ROS name"),
    (['service', 'call', '/a//b', 'std_srvs/srv/Trigger'], "'/a//b' is not a ROS name"),
    # A traceback from inside rclpy; and "no service" for a service that is there
    (['param', 'set', SIM, 'step_count', '9' * 23], "'" + '9' * 23 + "' is beyond an "
     'integer parameter (64 bits: -9223372036854775808 to 9223372036854775807)'),
    (['service', 'call', f'{SIM}/reset_simulation',
      'simulation_interfaces/srv/GetSimulationState'],
     f'{SIM}/reset_simulation is a simulation_interfaces/srv/ResetSimulation service, not '
     'simulation_interfaces/srv/GetSimulationState'),
    (['topic', 'pub', '--once', T.cmd_vel, 'geometry_msgs/msg/TwistStamped',
      '{twist: ' + '[' * 5000 + ']' * 5000 + '}'], 'the values are nested too deeply'),
    (['topic', 'pub', '--once', '/x', 'std_msgs/msg/String', '{data: [&a0 [1, 2], '
      + ', '.join(f'&a{k} [{", ".join([f"*a{k - 1}"] * 10)}]' for k in range(1, 10)) + ']}'],
     'the values use YAML aliases'),
])
def test_bad_input_is_one_line_and_exit_1(args, says, paused_sim, executor):
    code, out, err = ros2(args, paused_sim, executor)
    assert code == 1 and says in err and len(err.strip().splitlines()) == 1, err


def test_a_typo_in_a_verb_or_option_is_refused_with_exit_2():
    for args in (['topic', 'lst'], ['topic', 'echo'], ['topic', 'pub', '/x', 'T', '{}', '-r',
                                                       'nan']):
        out = subprocess.run([sys.executable, '-m', 'miro_ball.ros2', *args],
                             capture_output=True, text=True, timeout=60)
        assert out.returncode == 2 and 'Traceback' not in out.stderr
