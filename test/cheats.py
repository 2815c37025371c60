"""Cheating "controllers" for the grader's tests: python test/cheats.py CHEAT.

Each does what a student gaming the grader would try, as the grader runs it (in its
sandbox, MIRO_ROBOT_NAME set), and says on its output what it saw, for the test to read.
"""
import os
import sys
import time

import rclpy
from geometry_msgs.msg import PointStamped, PoseStamped, TwistStamped
from nav_msgs.msg import Odometry
from rclpy.parameter import Parameter
from rcl_interfaces.srv import SetParameters
from rosgraph_msgs.msg import Clock
from simulation_interfaces.msg import EntityState, SimulationState
from simulation_interfaces.srv import SetEntityState, SetSimulationState
from std_srvs.srv import SetBool, Trigger

from miro_ball.miro.interface import BALL_NAME, default_robot_name, RobotTopics, SimTopics

ROBOT = default_robot_name()
SIM = SimTopics()
MINE = RobotTopics(ROBOT)
RUN_S = 30.0  # wall: longer than any episode of the tests


def say(*words):
    print(*words, flush=True)


def probe_of(domain):
    """A node on ROS domain ``domain``, with a context and an executor of its own."""
    from rclpy.executors import SingleThreadedExecutor

    context = rclpy.Context()
    rclpy.init(context=context, domain_id=domain)
    node = rclpy.create_node('probe', context=context)
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(node)
    return node, executor, context


def drive_forward(node):
    """What an honest controller would publish too: MiRo's own command."""
    cmd = node.create_publisher(TwistStamped, MINE.cmd_vel, 10)
    return lambda: cmd.publish(TwistStamped())


def spin(node, every=None, seconds=RUN_S):
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        rclpy.spin_once(node, timeout_sec=0.02)
        if every:
            every()


def set_pose(name, x, y):
    msg = PoseStamped()
    msg.header.frame_id = name
    msg.pose.position.x, msg.pose.position.y = x, y
    msg.pose.orientation.w = 1.0
    return msg


def teleport(node, name):
    command = drive_forward(node)
    pub = node.create_publisher(PoseStamped, SIM.set_pose, 10)
    spin(node, lambda: (command(), pub.publish(set_pose(name, 2.0, 2.0))))


def call(node, *calls):
    """Calls each (kind, service, request) at once, driving meanwhile."""
    command = drive_forward(node)
    futures = [node.create_client(kind, service).call_async(request)
               for kind, service, request in calls]
    spin(node, lambda: (command(), [say('service', 'answered', future.result())
                                    for future in futures if future.done()]))


def teleport_by_the_standard(node):
    """The ball by the goal, through the standard simulation_interfaces' service."""
    ball = EntityState()
    ball.pose.position.x, ball.pose.position.z = 2.0, 0.1
    call(node, (SetEntityState, SIM.standard(SetEntityState),
                SetEntityState.Request(entity=BALL_NAME, state=ball)))


def fake(node, kind, topic, message):
    command = drive_forward(node)
    pub = node.create_publisher(kind, topic, 10)
    spin(node, lambda: (command(), pub.publish(message)))


def ground_truth(node):
    command = drive_forward(node)
    seen = []
    node.create_subscription(PoseStamped, SIM.object_pose(BALL_NAME), seen.append, 10)
    spin(node, lambda: (command(), seen and say('got', 'ground', 'truth', seen[-1].pose.position)))


def surviving_child(node):
    """Double-forks a child that would cheat in the next episode; says its pid."""
    if os.fork() == 0:
        os.setsid()
        if os.fork() == 0:
            say('child pid', os.getpid())
            time.sleep(600)
        os._exit(0)
    spin(node, drive_forward(node))


def other_domains(node):
    """Looks for simulators on other ROS domains (other episodes), as --jobs 2 allowed."""
    lock_dir = '/tmp/miro_ball_domains'
    say('lock files', sorted(os.listdir(lock_dir)) if os.path.isdir(lock_dir) else 'none')
    # All domains at once: probed one after another they outlasted a short episode.
    probes = {domain: probe_of(domain) for domain in range(0, 12)}
    end = time.monotonic() + 1.5
    while time.monotonic() < end:
        for _, executor, _ in probes.values():
            executor.spin_once(timeout_sec=0.01)
    found = [domain for domain, (probe, _, _) in probes.items()
             if probe.get_publishers_info_by_topic('/clock')]
    for probe, executor, context in probes.values():
        executor.shutdown()
        probe.destroy_node()
        context.try_shutdown()
    say('simulators on domains', found, 'mine', os.environ.get('ROS_DOMAIN_ID'))
    spin(node, drive_forward(node))


def edit_grader(node):
    """Rewrites the judge and the report, reads the teacher's home."""
    import miro_ball.run.judge as judge

    for path in (judge.__file__, os.path.join(os.path.dirname(judge.__file__), 'x.py')):
        try:
            with open(path, 'a') as edited:
                edited.write('\nKICK_DISTANCE_M = 0.0\n')
            say('edited', path)
        except OSError as err:
            say('could not edit', path, err.strerror)
    for home in ('/root', '/home'):
        say('home', home, os.listdir(home) if os.path.isdir(home) else 'none')
    say('environment', sorted(os.environ))
    say('class folder', sorted(os.listdir(os.path.dirname(os.getcwd()))))
    spin(node, drive_forward(node))


def flood(node):
    """Floods control/cmd_vel and its own output."""
    cmd = node.create_publisher(TwistStamped, MINE.cmd_vel, 10)
    line = b'spam ' * 2000 + b'\n'
    end = time.monotonic() + RUN_S
    while time.monotonic() < end:
        for _ in range(100):
            cmd.publish(TwistStamped())
        os.write(1, line * 20)


def children(node):
    """Starts sleeping children until it can start no more."""
    count = 0
    try:
        while count < 100000:
            if os.fork() == 0:
                time.sleep(600)
                os._exit(0)
            count += 1
    except OSError as err:
        say('could not start child', count + 1, err.strerror)
    say('children started', count)
    spin(node, drive_forward(node))


CHEATS = {
    'teleport_ball': lambda n: teleport(n, BALL_NAME),
    'teleport_robot': lambda n: teleport(n, ROBOT),
    'reset': lambda n: call(n, (Trigger, SIM.reset, Trigger.Request())),
    'pause': lambda n: call(n, (SetBool, SIM.pause, SetBool.Request(data=True))),
    'teleport_standard': teleport_by_the_standard,
    'pause_standard': lambda n: call(n, (
        SetSimulationState, SIM.standard(SetSimulationState), SetSimulationState.Request(
            state=SimulationState(state=SimulationState.STATE_PAUSED)))),
    'slow_down': lambda n: call(n, (SetParameters, f'/{SIM.node}/set_parameters',
                                    SetParameters.Request(parameters=[Parameter(
                                        'real_time_factor', value=0.2).to_parameter_msg()]))),
    'fake_clock': lambda n: fake(n, Clock, '/clock', Clock()),
    'fake_ground_truth': lambda n: fake(n, PointStamped, SIM.ball, PointStamped()),
    'fake_sensors': lambda n: fake(n, Odometry, MINE.odom, Odometry()),
    'ground_truth': ground_truth,
    'surviving_child': surviving_child,
    'other_domains': other_domains,
    'edit_grader': edit_grader,
    'flood': flood,
    'children': children,
}


if __name__ == '__main__':
    name = sys.argv[1]
    rclpy.init()
    node = rclpy.create_node(f'student_{name}')
    say('cheat', name, 'robot', ROBOT)
    try:
        CHEATS[name](node)
    except KeyboardInterrupt:  # the end of the episode
        pass
