"""Two machines: the simulator on one, the controller on the other, over a network.

Two network namespaces joined by a veth pair stand in for the machines (10.231.0.1
and .2, addresses that exist only inside the namespaces made here). Fast DDS tells
hosts apart by their addresses, so it takes no shared-memory shortcut between them:
the images and commands cross the veth pair, as the byte counters confirm. The
nodes run as the README says for two machines: the same ROS_DOMAIN_ID on both and
either ROS_AUTOMATIC_DISCOVERY_RANGE=SUBNET (discovery by multicast) or LOCALHOST with
ROS_STATIC_PEERS naming both addresses (no multicast discovery). Either way Fast DDS
wants a route for multicast: a namespace has no default route, so it gets one for
224.0.0.0/4 (without, even static peers never exchange data). An observer on the
simulator's side (this file run as a script) says whether the ball was kicked.
Skipped where namespaces can't be made (not root, no `ip`, no permission).

Run alone it is also the observer: python test/test_two_hosts.py --observe LIMIT
"""
import os
import shutil
import subprocess
import sys
import time

import pytest

from miro_ball.common.isolation import isolated_env
from miro_ball.run.nodes import controller_command, sim_command
from miro_ball.run.processes import Processes
from miro_ball.miro.interface import default_robot_name

SUBNET = '10.231.0.{}/24'  # only ever inside the two namespaces made here
LIMIT_S = 40.0  # simulated seconds for the kick
MIN_BYTES = 1_000_000  # camera frames crossed the link, not just discovery
HANG_GUARD_S = 120.0  # the observer's; the test waits a little longer for it
KICKED = 'observer: kicked at'


def ip(*args):
    return subprocess.run(['ip', *args], capture_output=True, text=True)


class Machines:
    """Two namespaces 'a' and 'b' joined by a veth pair, a at .1 and b at .2."""

    def __init__(self):
        tag = os.getpid() % 1_000_000
        self.names = {'a': f'miro2h_a{tag}', 'b': f'miro2h_b{tag}'}
        self.links = {'a': f'm2ha{tag}', 'b': f'm2hb{tag}'}
        self.made = []

    def make(self):
        """None when made, else why they can't be made here."""
        for side in 'ab':
            made = ip('netns', 'add', self.names[side])
            if made.returncode:
                return f'ip netns add: {made.stderr.strip()}'
            self.made.append(self.names[side])
        a, b = self.names['a'], self.names['b']
        steps = [('link', 'add', self.links['a'], 'netns', a, 'type', 'veth',
                  'peer', 'name', self.links['b'], 'netns', b)]
        for number, side in enumerate('ab', start=1):
            ns, link = self.names[side], self.links[side]
            steps += [('-n', ns, 'addr', 'add', SUBNET.format(number), 'dev', link),
                      ('-n', ns, 'link', 'set', link, 'up'),
                      ('-n', ns, 'link', 'set', 'lo', 'up'),
                      ('-n', ns, 'route', 'add', '224.0.0.0/4', 'dev', link)]
        for step in steps:
            done = ip(*step)
            if done.returncode:
                return f'ip {" ".join(step)}: {done.stderr.strip()}'
        return None

    def command(self, side, cmd):
        """cmd run on that 'machine' (in its network namespace)."""
        return ['ip', 'netns', 'exec', self.names[side], *cmd]

    def bytes_received(self, side):
        """Bytes that arrived on that side's end of the link."""
        path = f'/sys/class/net/{self.links[side]}/statistics/rx_bytes'
        read = subprocess.run(['ip', 'netns', 'exec', self.names[side], 'cat', path],
                              capture_output=True, text=True)
        return int(read.stdout)

    def remove(self):
        for name in self.made:  # the veth pair goes with its namespaces
            ip('netns', 'del', name)


# How the nodes find each other: the environment of both machines.
DISCOVERY = {
    'multicast': {'ROS_AUTOMATIC_DISCOVERY_RANGE': 'SUBNET'},
    'static-peers': {'ROS_AUTOMATIC_DISCOVERY_RANGE': 'LOCALHOST',
                     'ROS_STATIC_PEERS': ';'.join(SUBNET.format(n).split('/')[0]
                                                  for n in (1, 2))},
}


@pytest.fixture(params=list(DISCOVERY))
def machines(request):
    """(Machines, the nodes' discovery environment)."""
    if os.geteuid() != 0:
        pytest.skip('network namespaces need root')
    if shutil.which('ip') is None:
        pytest.skip('no `ip` command (iproute2)')
    made = Machines()
    try:
        why_not = made.make()
        if why_not:
            pytest.skip(f'network namespaces not permitted here: {why_not}')
        yield made, DISCOVERY[request.param]
    finally:
        made.remove()


def test_simulator_and_controller_on_two_machines_kick_the_ball(machines, tmp_path):
    machines, discovery = machines
    robot = default_robot_name()
    observer = [sys.executable, os.path.abspath(__file__), '--observe', str(LIMIT_S)]
    env = dict(isolated_env(int(os.environ['ROS_DOMAIN_ID'])), **discovery)
    procs = Processes(tmp_path, env)
    observer_proc = procs.start('observer', machines.command('a', observer))
    procs.start('kick_blue_ball', machines.command('b', controller_command(robot)))
    # The simulator waits, paused, until the observer has seen the controller.
    procs.start('miro_sim', machines.command('a', sim_command(
        'miro', real_time_factor=0.0, paused=True)))
    try:
        observer_proc.wait(timeout=HANG_GUARD_S + 30.0)
    finally:
        killed = procs.stop()
    logs = {name: (tmp_path / f'{name}.log').read_text()
            for name in ('observer', 'kick_blue_ball', 'miro_sim')}
    assert KICKED in logs['observer'], logs
    assert not killed, logs
    # The images went a -> b and the commands b -> a over the link.
    received = {side: machines.bytes_received(side) for side in 'ab'}
    print(f'over the link: {received["b"]} bytes to the controller, {received["a"]} to the '
          'simulator; ' + logs['observer'].strip())
    assert received['b'] > MIN_BYTES and received['a'] > 10_000, received


def observe(limit_s):
    """Resume the paused simulator once the controller on the other machine is seen (its
    command publisher and eye subscriptions), then watch the simulator's ground truth until
    the ball is kicked or limit_s simulated seconds pass; one line says which. Exit code 0
    when kicked."""
    import rclpy
    from rclpy.context import Context
    from rclpy.executors import SingleThreadedExecutor
    from std_srvs.srv import SetBool

    from miro_ball.run.monitor import Monitor
    from miro_ball.miro.interface import EYES, RobotTopics, SimTopics

    context = Context()
    rclpy.init(context=context, domain_id=int(os.environ['ROS_DOMAIN_ID']))
    node = rclpy.create_node('two_hosts_observer', context=context)
    robot = RobotTopics(default_robot_name())
    monitor = Monitor(node, [robot.name])
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(node)
    deadline = time.monotonic() + HANG_GUARD_S

    def waiting():
        executor.spin_once(timeout_sec=0.1)
        return time.monotonic() < deadline

    while not (node.count_publishers(robot.cmd_vel)
               and all(node.count_subscribers(robot.eye_compressed(eye)) for eye in EYES)):
        if not waiting():
            print('observer: the controller never showed up', flush=True)
            return 1
    resume = node.create_client(SetBool, SimTopics().pause)
    resumed = resume.wait_for_service(timeout_sec=30.0) and resume.call_async(
        SetBool.Request(data=False))
    while resumed and not resumed.done() and waiting():
        pass
    while not monitor.judge.kicked and monitor.sim_time < limit_s and waiting():
        pass
    frames = sum(w.frames for w in monitor.robots.values())
    if monitor.judge.kicked:
        print(f'{KICKED} {monitor.judge.kick_time:.1f} s simulated; {frames} controller '
              'frames seen',
              flush=True)
    else:
        print(f'observer: not kicked (simulated time {monitor.sim_time:.1f} s, {frames} '
              'controller frames seen)', flush=True)
    node.destroy_node()
    rclpy.try_shutdown(context=context)
    return 0 if monitor.judge.kicked else 1


if __name__ == '__main__' and sys.argv[1:2] == ['--observe']:
    sys.exit(observe(float(sys.argv[2])))
