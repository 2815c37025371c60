"""One simulator per ROS domain: a second one refuses to start, in one line, and a running
one says once, in one line, when another /clock publisher appears."""
import os
import subprocess
import sys
import time

import pytest
import rclpy
from rosgraph_msgs.msg import Clock

from miro_ball.common.isolation import isolated_env
from miro_ball.miro.interface import CLOCK
from rostools import kill_if_running, run_command

DOMAIN = os.environ['ROS_DOMAIN_ID']
LIGHT = ['--ros-args', '-p', 'renderer:=tiny', '-p', 'eye_workers:=false']
HANG_GUARD_S = 60.0
# Discovery usually shows the other simulator in a few tens of ms, but where another
# process on the domain has just left (earlier tests), it can wait for the next
# periodic announcement (Fast DDS: every 3 s). The look ends as soon as it finds one.
LOOK_S = '5.0'


def simulator(*extra):
    return [sys.executable, '-m', 'miro_sim_bullet', *LIGHT, *extra]


@pytest.fixture
def first():
    """A simulator process on the test's domain, up and stepping; its output so far."""
    proc = subprocess.Popen(simulator(), env=isolated_env(int(DOMAIN)), text=True,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
    output = []
    read_until(proc, output, 'real-time factor')
    yield proc, output
    kill_if_running(proc)


def read_until(proc, output, text):
    """Read the process's output line by line until a line holds text; the wall-clock
    limit only guards against a hang."""
    deadline = time.monotonic() + HANG_GUARD_S
    while time.monotonic() < deadline:
        line = proc.stdout.readline()
        assert line, 'exited:\n' + ''.join(output)
        output.append(line)
        if text in line:
            return line
    pytest.fail(f'no {text!r} in:\n' + ''.join(output))


def test_a_second_simulator_on_the_domain_refuses_in_one_line(first):
    code, output = run_command(simulator('-p', f'peer_check_s:={LOOK_S}'),
                               timeout_s=HANG_GUARD_S)
    assert code == 2, output
    lines = output.splitlines()
    assert len(lines) == 1, output
    assert lines[0].startswith('miro_sim: error: /clock is already published on ROS domain '
                               f'{DOMAIN} by /miro_sim')
    assert 'export ROS_DOMAIN_ID=' in lines[0]


def test_a_running_simulator_names_a_second_clock_publisher_once(first, ros_context):
    proc, output = first
    other = rclpy.create_node('second_clock', context=ros_context)
    other.create_publisher(Clock, CLOCK, 10)
    line = read_until(proc, output, '/second_clock')
    assert f'publishers on {CLOCK} (/miro_sim, /second_clock) on ROS domain {DOMAIN}' in line
    proc.terminate()
    rest, _ = proc.communicate(timeout=HANG_GUARD_S)
    said = (''.join(output) + rest).count('/second_clock')
    other.destroy_node()
    assert proc.returncode == 0 and said == 1, ''.join(output) + rest


def test_the_look_can_be_skipped(first):
    """peer_check_s:=0 starts anyway (and the running one says so)."""
    proc, output = first
    second = subprocess.Popen(simulator('-p', 'peer_check_s:=0.0'),
                              env=isolated_env(int(DOMAIN)), text=True,
                              stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
    try:
        read_until(second, [], 'real-time factor')
        read_until(proc, output, 'another simulator shares this domain')
    finally:
        kill_if_running(second)
