"""Every node ends on Ctrl+C (SIGINT) or SIGTERM, with or without a peer, exit code 0,
no traceback; the controller sends its zero twist on the way out.

Without a simulator there is no /clock, so the controller's spin sits in rcl's wait:
the case that used to ignore signals until the main job killed it.
"""
import os
import signal
import subprocess
import sys
import time

import pytest

from miro_ball.common.isolation import isolated_env
from rostools import kill_if_running

# Long enough for a slow CI machine; a node that ignores signals never gets there.
GUARD_S = 10.0
# The entry points, the line each logs once it is up, and extra arguments.
SIMULATOR = ('miro_sim_bullet', 'real-time factor', ['--ros-args', '-p', 'renderer:=tiny'])
# Alone, it says what it waits for: the blocked state that used to ignore signals.
CONTROLLER = ('miro_ball', 'waiting for /clock on ROS domain',
              ['--ros-args', '-p', 'use_sim_time:=true'])
BALL_MOVER = ('miro_ball.examples.ball_mover', "on the simulator's /clock", [])
# The controller's first tick on the simulator's /clock: it is running with its peer.
CONTROLLER_WITH_PEER = ('miro_ball', 'holding the head pose', CONTROLLER[2])


class Node:
    """One entry point as a child process on the test's ROS domain."""

    def __init__(self, module, ready, extra):
        self.ready = ready
        env = isolated_env(int(os.environ['ROS_DOMAIN_ID']))
        self.proc = subprocess.Popen([sys.executable, '-m', module, *extra], env=env,
                                     stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                     text=True)
        self.output = []

    def wait_ready(self):
        """Read the log until the node says it is up (or, without a marker, one line)."""
        deadline = time.monotonic() + 60.0
        while time.monotonic() < deadline:
            line = self.proc.stdout.readline()
            assert line, 'exited before it was up:\n' + ''.join(self.output)
            self.output.append(line)
            if self.ready is None or self.ready in line:
                return self
        pytest.fail('never came up:\n' + ''.join(self.output))

    def stop(self, signum):
        """Send the signal; return (exit code, seconds to exit, whole output)."""
        sent = time.monotonic()
        self.proc.send_signal(signum)
        try:
            rest, _ = self.proc.communicate(timeout=GUARD_S)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            rest, _ = self.proc.communicate()
            pytest.fail(f'still running {GUARD_S} s after {signal.Signals(signum).name}:\n'
                        + ''.join(self.output) + rest)
        return self.proc.returncode, time.monotonic() - sent, ''.join(self.output) + rest

    def kill(self):
        kill_if_running(self.proc)


@pytest.fixture
def nodes():
    started = []

    def start(spec):
        started.append(Node(*spec))
        return started[-1]
    yield start
    for node in started:
        node.kill()


def assert_clean_exit(result, what):
    code, seconds, output = result
    assert code == 0, f'{what}: exit code {code}\n{output}'
    assert 'Traceback' not in output, f'{what}:\n{output}'
    # The wake-up period is 0.1 s; the rest is shutting down DDS on a busy machine.
    assert seconds < 5.0, f'{what} took {seconds:.1f} s to stop'


@pytest.mark.parametrize('signum', [signal.SIGINT, signal.SIGTERM])
@pytest.mark.parametrize('spec', [SIMULATOR, CONTROLLER, BALL_MOVER],
                         ids=['simulator', 'controller', 'ball_mover'])
def test_alone(nodes, spec, signum):
    node = nodes(spec).wait_ready()
    assert_clean_exit(node.stop(signum), spec[0])


def test_controller_under_a_running_simulator_then_the_simulator(nodes):
    sim = nodes(SIMULATOR).wait_ready()
    controller = nodes(CONTROLLER_WITH_PEER).wait_ready()
    assert_clean_exit(controller.stop(signal.SIGINT), 'controller')
    assert_clean_exit(sim.stop(signal.SIGTERM), 'simulator')


def test_simulator_under_a_running_controller_then_a_second_ctrl_c(nodes):
    sim = nodes(SIMULATOR).wait_ready()
    controller = nodes(CONTROLLER_WITH_PEER).wait_ready()
    assert_clean_exit(sim.stop(signal.SIGINT), 'simulator')
    controller.proc.send_signal(signal.SIGINT)
    assert_clean_exit(controller.stop(signal.SIGINT), 'controller after two Ctrl+C')
