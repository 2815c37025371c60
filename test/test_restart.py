"""Restarts: either node killed with SIGKILL (a crash) and started again under the other.

The nodes run as child processes, as a user starts them, on the test's ROS domain;
the simulator free-runs (real_time_factor 0) and an in-process observer reads its
ground truth, the commands and /clock. Every assertion is on simulated time;
wall-clock limits only guard against a hang.
"""
import os
import signal

import pytest
from geometry_msgs.msg import TwistStamped
from nav_msgs.msg import Odometry
from simulation_interfaces.msg import Result, SimulationState
from simulation_interfaces.srv import GetEntityState, SetSimulationState, StepSimulation
from std_msgs.msg import Float32MultiArray

from miro_ball.common.isolation import isolated_env
from miro_ball.run.monitor import Monitor
from miro_ball.run.nodes import controller_command, sim_command
from miro_ball.run.processes import Processes
from miro_ball.miro.interface import BALL_NAME, default_robot_name, RobotTopics, SimTopics
from miro_sim_bullet.physics.robot import CMD_TIMEOUT_S
from miro_sim_bullet.physics.world import PHYSICS_DT_S
from rostools import drain, poll, Probe, spin_until

ROBOT = default_robot_name()
TOPICS = RobotTopics(ROBOT)
SIM = SimTopics()
KICK_WITHIN_S = 30.0  # simulated seconds from a controller's first command to the kick
TICK_S = 0.02  # the platform's tick, a step of the simulator here
TICK_STEPS = round(TICK_S / PHYSICS_DT_S)
HANG_GUARD_S = 120.0
# Once the wheels stop, the body rocks on its rear slider for up to ~0.15 s.
SETTLE_S = 0.3
MOVING, AT_REST = 0.05, 0.01  # m/s or rad/s, whichever is larger


@pytest.fixture
def nodes(tmp_path):
    """start(log name, 'sim' | 'paused sim' | 'controller') -> the node's Popen, started
    as a run starts it (a free-running simulator); what still runs is stopped at the end."""
    commands = {'sim': sim_command('miro', real_time_factor=0.0),
                'paused sim': sim_command('miro', real_time_factor=0.0, paused=True),
                'controller': controller_command(ROBOT)}
    with Processes(tmp_path, isolated_env(int(os.environ['ROS_DOMAIN_ID']))) as procs:
        yield lambda name, kind: procs.start(name, commands[kind])


@pytest.fixture
def probe(ros_context, executor):
    return Probe(ros_context, executor, name='restart_observer')


def seconds(stamp):
    return stamp.sec + stamp.nanosec * 1e-9


def watch_until_kicked(executor, probe, what):
    """Watch from now on until the ball is kicked; fails unless that happens within
    KICK_WITHIN_S simulated seconds of the first command a controller sends from now."""
    drain(executor)  # what a previous run left queued is not this run's
    monitor = Monitor(probe.node, [ROBOT])
    commands = probe.watch(TwistStamped, TOPICS.cmd_vel)
    assert spin_until(executor, lambda: monitor.judge.kicked or (
        commands and monitor.sim_time > seconds(commands[0].header.stamp) + KICK_WITHIN_S),
        HANG_GUARD_S), \
        f'{what}: hung (simulated time {monitor.sim_time:.1f} s, {len(commands)} commands)'
    assert monitor.judge.kicked, \
        f'{what}: not kicked {KICK_WITHIN_S} s after the first command'
    return monitor


def step_until(executor, probe, predicate, max_steps=500):
    """Step the paused simulator a platform tick at a time until predicate() holds."""
    client = probe.node.create_client(StepSimulation, SIM.standard(StepSimulation))
    assert client.wait_for_service(timeout_sec=HANG_GUARD_S), 'no simulator'
    for _ in range(max_steps):
        future = client.call_async(StepSimulation.Request(steps=TICK_STEPS))
        # An answer can be lost while the service's reply path is still being matched:
        # then this tick is asked for again.
        executor.spin_until_future_complete(future, timeout_sec=2.0)
        result = future.result() and future.result().result
        assert result is None or result.result == Result.RESULT_OK, result.error_message
        # Time for the controller to answer this tick; the limit only bounds each try.
        if poll(executor, predicate, timeout_s=0.2):
            return
    pytest.fail(f'nothing after {max_steps} ticks')


def set_paused(executor, probe, paused):
    wanted = SimulationState.STATE_PAUSED if paused else SimulationState.STATE_PLAYING
    for _ in range(3):  # a fresh client's first answer can be lost, as step_until's
        answer = probe.call(executor, SetSimulationState, SIM.standard(SetSimulationState),
                            SetSimulationState.Request(state=SimulationState(state=wanted)))
        if answer is not None:
            break
    assert answer is not None, 'the simulator did not answer set_simulation_state'
    assert answer.result.result in (Result.RESULT_OK,
                                    SetSimulationState.Response.ALREADY_IN_TARGET_STATE), \
        answer.result.error_message


def sim_now(executor, probe):
    """Simulated time, as the simulator stamps an entity's state."""
    stamp = probe.call(executor, GetEntityState, SIM.standard(GetEntityState),
                       GetEntityState.Request(entity=BALL_NAME)).state.header.stamp
    return seconds(stamp)


def test_controller_starts_over_and_kicks_after_the_simulator_is_killed(
        nodes, executor, probe, tmp_path):
    sim = nodes('miro_sim_1', 'sim')
    controller = nodes('controller', 'controller')
    first = watch_until_kicked(executor, probe, 'first simulator')
    sim.kill()
    sim.wait()
    killed_at = first.sim_time
    # The new simulator starts paused and is stepped until the controller commands on its
    # timeline: free-running, it could be past killed_at before the controller hears it.
    nodes('miro_sim_2', 'paused sim')
    drain(executor)
    commands = probe.watch(TwistStamped, TOPICS.cmd_vel)
    step_until(executor, probe, lambda: any(
        seconds(c.header.stamp) < killed_at for c in commands))
    set_paused(executor, probe, False)
    watch_until_kicked(executor, probe, 'restarted simulator')
    controller.send_signal(signal.SIGINT)
    assert controller.wait(timeout=HANG_GUARD_S) == 0
    log = (tmp_path / 'controller.log').read_text()
    assert 'clock went back' in log and 'starting over' in log, log


def test_wheels_stop_after_the_command_timeout_when_the_controller_is_killed(
        nodes, executor, probe):
    # Stepped until the controller drives: free-running, a busy machine let the simulator
    # run on for seconds before the pause below (a kick, or commands after it).
    nodes('miro_sim', 'paused sim')
    monitor = Monitor(probe.node, [ROBOT])
    wheels = probe.watch(Float32MultiArray, TOPICS.wheel_speed_cmd)
    odometry = probe.watch(Odometry, TOPICS.odom)  # stamped: the exact simulated time
    controller = nodes('controller_1', 'controller')
    step_until(executor, probe, lambda: wheels and any(wheels[-1].data))
    # Paused, the simulator takes whatever command is still on its way at this very
    # instant: so no command can reach it later than the pause.
    set_paused(executor, probe, True)
    controller.kill()
    controller.wait()
    assert not monitor.judge.kicked, 'kicked before it was killed: nothing left to test'
    paused_at = sim_now(executor, probe)
    set_paused(executor, probe, False)
    assert spin_until(executor, lambda: odometry and seconds(
        odometry[-1].header.stamp) > paused_at + 2 * CMD_TIMEOUT_S, HANG_GUARD_S)
    speeds = [(seconds(m.header.stamp), max(abs(m.twist.twist.linear.x),
                                            abs(m.twist.twist.angular.z))) for m in odometry]
    # The dead controller's last command drives on until the timeout ...
    driven = [speed for t, speed in speeds if paused_at < t < paused_at + CMD_TIMEOUT_S - TICK_S]
    assert driven and max(driven) > MOVING, f'not driven after the controller died: {driven}'
    # ... and no longer: the body settles, then stays at rest.
    at_rest_from = paused_at + CMD_TIMEOUT_S + TICK_S + SETTLE_S
    after = [speed for t, speed in speeds if t >= at_rest_from]
    assert after and max(after) < AT_REST, \
        f'still moving {at_rest_from - paused_at:.2f} s after the last command: {after[:5]}'
    assert wheels[-1].data.tolist() == [0.0, 0.0], wheels[-1]

    nodes('controller_2', 'controller')
    watch_until_kicked(executor, probe, 'new controller')
