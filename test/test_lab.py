"""The lab run as a user runs it: every node of the run has a name of its own, and the run is
watched from its first instant (the simulator waits, paused, for the controllers and
its own observer)."""
import re
import signal
import sys
import time

import rclpy

from miro_ball.controller.names import NODE_NAME as CONTROLLER
from miro_ball.miro.interface import EYES, SIM_ACTION_NODE_NAME, SIM_NODE_NAME
from miro_ball.run.referee import ros_domain
from miro_sim_bullet.ros.params import SimParams
from miro_sim_bullet.scene.world_file import load_world
from program import Program
from rostools import run_command

HANG_GUARD_S = 180.0
FOOTBALL = 'football_pitch'  # three robots: miro01, miro02, miro03
FRAMES_PER_ROBOT_S = SimParams().camera_rate * len(EYES)
PROGRESS = re.compile(r'^  t = +([0-9.]+) s simulated, ball moved [0-9.]+ m, (\d+) frames',
                      re.M)


def node_names(domain, wanted):
    """Fully qualified names of the nodes on ROS domain ``domain`` (ours left out), once
    those wanted have shown up."""
    with ros_domain(domain) as context:
        node = rclpy.create_node('lab_names_probe', context=context)
        ours = node.get_fully_qualified_name()
        deadline = time.monotonic() + HANG_GUARD_S
        while not wanted <= set(node.get_fully_qualified_node_names()):
            assert time.monotonic() < deadline, node.get_fully_qualified_node_names()
            time.sleep(0.1)  # discovery runs in the middleware's own threads
        names = node.get_fully_qualified_node_names()
        node.destroy_node()
    names.remove(ours)
    return names


def test_every_node_of_the_football_lab_run_has_a_name_of_its_own(tmp_path):
    robots = [spec.name for spec in load_world(FOOTBALL).robots]
    # A quarter of real time: the Ctrl+C below comes at the first progress line after the
    # start (2 s of wall time), long before a kick ends the run (at real time, once, it came first).
    run = Program('miro_ball.lab', '--world', FOOTBALL, '--no-video', '--limit', '60',
                  '--real-time-factor', '0.25', '--out', str(tmp_path), guard_s=HANG_GUARD_S)
    try:
        domain = int(run.line('ROS domain ').split('ROS domain ')[1].split(';')[0])
        controllers = {f'/{robot}/{CONTROLLER}' for robot in robots}
        ours = controllers | {f'/{SIM_NODE_NAME}', f'/{SIM_ACTION_NODE_NAME}', '/miro_lab'}
        names = node_names(domain, ours)
        assert len(names) == len(set(names)), sorted(names)
        assert sorted(names) == sorted(ours)
        # Ctrl+C once the simulated time runs.
        while float(PROGRESS.search(run.line('  t = ')).group(1)) == 0.0:
            pass
    finally:
        run.proc.send_signal(signal.SIGINT)
        _, output = run.finish()
    assert re.search(r'^  kicked: +(yes|no)\n  ended: +interrupted \(Ctrl\+C\)$', output,
                     re.M), output
    simulated = float(re.search(r'simulated time: +([0-9.]+) s', output).group(1))
    assert simulated > 0, output
    assert 'FAILED' not in output, output


def test_the_lab_run_is_watched_from_its_first_instant(tmp_path):
    """The video's first frame is the start, with the robots and the ball where the world
    puts them; no progress line counts more frames than the simulated time allows."""
    world = load_world(FOOTBALL)
    _, output = run_command([sys.executable, '-m', 'miro_ball.lab', '--world', FOOTBALL,
                                '--limit', '3', '--out', str(tmp_path)])
    assert 'FAILED' not in output, output
    start = re.search(r'^  started at t = ([0-9.]+) s: (.*); the ball at \((.*)\)$', output,
                      re.M)
    assert start and float(start.group(1)) == 0.0, output
    seen = dict(re.findall(r'(\w+) at \(([^)]*)\)', start.group(2)))
    for spec in world.robots:
        x, y = (float(v) for v in seen[spec.name].split(','))
        assert abs(x - spec.pose[0]) <= 0.011 and abs(y - spec.pose[1]) <= 0.011, output
    ball = [float(v) for v in start.group(3).split(',')]
    assert all(abs(b - w) <= 0.011 for b, w in zip(ball, world.ball.position)), output
    first_frame = re.search(r'^  video: .*\(\d+ frames, t = ([0-9.]+) to', output, re.M)
    assert first_frame and float(first_frame.group(1)) == 0.0, output
    progress = [(float(t), int(frames)) for t, frames in PROGRESS.findall(output)]
    slack_s = 0.5  # the observer hears /clock and the annotated frames on their own topics
    # The first progress line is printed as soon as the start is seen: a busy machine may
    # let the clock run on a tick or two before the observer has heard everything.
    assert progress and progress[0][0] <= slack_s, output
    assert all(frames <= (t + slack_s) * FRAMES_PER_ROBOT_S * len(world.robots)
               for t, frames in progress), output
