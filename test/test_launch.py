"""python -m miro_ball.launch as a user runs it: the football pitch comes up from one command
(the simulator, a controller per robot, the GUI), a robot kicks, and one Ctrl+C ends every
process; a process whose file says on_exit="shutdown" (every node of ours) stops the others
when it ends, one that says respawn is restarted, and any other leaves them running, as in
ROS 2's launch."""
import signal
import sys
import urllib.request

from geometry_msgs.msg import PointStamped

from miro_ball.common import proc_tree
from miro_ball.controller.names import NODE_NAME as CONTROLLER
from miro_ball.miro.interface import SimTopics
from program import Program
from rostools import Probe, spin_until

UP_GUARD_S = 120.0  # a hang guard only
ROBOTS = ('miro01', 'miro02', 'miro03')  # the football pitch's


class Launch(Program):
    """python -m miro_ball.launch ... in a session of its own, its output read as it comes."""

    def __init__(self, *args):
        super().__init__('miro_ball.launch', *args, guard_s=UP_GUARD_S)

    def ctrl_c(self):
        """One SIGINT; (exit code, the descendants left, its whole output)."""
        children = proc_tree.descendants(self.proc.pid)
        self.proc.send_signal(signal.SIGINT)
        code, output = self.finish()
        return code, proc_tree.wait_gone(children, 0), output


def test_football_comes_up_from_one_command_a_robot_kicks_and_one_ctrl_c_ends_it_all(
        ros_context, executor):
    probe = Probe(ros_context, executor, 'launch_probe')
    touches = probe.watch(PointStamped, SimTopics().touches)
    launch = Launch('football', 'gui_port:=0')
    try:
        url = launch.line('[miro_gui] miro_gui: open ').split(' open ', 1)[1].strip()
        with urllib.request.urlopen(url, timeout=10) as page:
            assert page.status == 200 and b'<html' in page.read().lower()
        spin_until(executor, lambda: any(t.header.frame_id in ROBOTS for t in touches),
                   UP_GUARD_S, 'a robot touching the ball')
        names = set(probe.node.get_fully_qualified_node_names())
        assert {f'/{robot}/{CONTROLLER}' for robot in ROBOTS} | {'/miro_sim'} <= names
    finally:
        code, left, output = launch.ctrl_c()
    # Every process stopped on its Ctrl+C: one that had not within the launcher's grace
    # (runner.STOP_GRACE_S) would have been killed, said so, and made the exit code 1.
    assert code == 0 and left == [] and 'killed' not in output, output
    assert 'Traceback' not in output and output.rstrip().endswith('[launch] stopped'), output
    for label in ('miro_sim', *(f'{robot}/kick_blue_ball' for robot in ROBOTS)):
        assert f'\n[{label}] ' in output, label


def launch_file(folder, text):
    path = folder / 'test.launch.xml'
    path.write_text(f'<launch>{text}</launch>')
    return str(path)


def script(folder, name, code):
    """An <executable> cmd attribute running code (a file of its own) with this Python."""
    (folder / f'{name}.py').write_text(code)
    return f'{sys.executable} {folder / name}.py'


def waiter_and_quitter(folder, quitter_says=''):
    """A launch file: a waiter that stays until Ctrl+C or a file 'go' appears, and a
    quitter that ends with code 3 once the waiter is up (its attributes: quitter_says)."""
    ready, go = folder / 'ready', folder / 'go'
    waiter = script(folder, 'waiter', f"""import os, pathlib, signal, sys, time
signal.signal(signal.SIGINT, lambda *_: sys.exit(print('stopped by Ctrl+C')))
pathlib.Path({str(ready)!r}).write_text(str(os.getpid()))
while not os.path.exists({str(go)!r}):
    time.sleep(0.01)
print('still here')
""")
    quitter = script(folder, 'quitter', f"""import os, sys, time
while not os.path.exists({str(ready)!r}):  # the waiter is up
    time.sleep(0.01)
print('bye')
sys.exit(3)
""")
    return launch_file(folder, f'''<executable name="waiter" cmd="{waiter}"/>
                                  <executable name="quitter" cmd="{quitter}" {quitter_says}/>''')


def test_a_process_whose_file_says_on_exit_shutdown_stops_the_others_when_it_ends(tmp_path):
    code, output = Launch(waiter_and_quitter(tmp_path, 'on_exit="shutdown"')).finish()
    assert code == 1, output
    assert '[quitter] bye\n[launch] quitter exited with code 3; stopping the others\n' in output
    assert output.endswith('[waiter] stopped by Ctrl+C\n[launch] ended\n'), output
    assert proc_tree.wait_gone([int((tmp_path / 'ready').read_text())], 0) == []


def test_without_on_exit_the_others_go_on_and_the_run_ends_when_none_is_left(tmp_path):
    """As under ros2 launch: a process that ends leaves the others running (ours stopped
    them whatever its file said); the exit code says that one failed."""
    launch = Launch(waiter_and_quitter(tmp_path))
    launch.line('[launch] quitter exited with code 3; the others go on (its file does not '
                'say on_exit="shutdown")')
    (tmp_path / 'go').touch()
    code, output = launch.finish()
    assert code == 1, output
    assert output.endswith('[waiter] still here\n[launch] waiter exited with code 0\n'
                           '[launch] ended\n'), output


def test_a_refused_simulator_stops_the_lab_it_was_launched_with():
    """The lab of miro_ball's own files with a world that is not there: miro_sim refuses
    it, and the controller is stopped with it rather than left driving another simulator
    on the domain (which ros2 launch did before the files said on_exit="shutdown")."""
    launch = Launch('lab', 'world:=/no/such/world.toml', 'gui:=false')
    launch.line('[launch] miro_sim exited with code 2; stopping the others')
    children = proc_tree.descendants(launch.proc.pid)  # the controller, unless it has gone
    code, output = launch.finish()
    assert code == 1, output
    assert 'Traceback' not in output and output.endswith('[launch] ended\n'), output
    assert proc_tree.wait_gone(children, 0) == []


def test_a_process_whose_file_says_respawn_is_restarted(tmp_path):
    count = tmp_path / 'starts'
    again = script(tmp_path, 'again', f"open({str(count)!r}, 'a').write('x'); print('up')")
    launch = Launch(launch_file(tmp_path, f'''<executable name="again" respawn="true"
                                            respawn_delay="0.1" cmd="{again}"/>'''))
    for _ in range(3):
        launch.line('[again] up')
    code, left, output = launch.ctrl_c()
    assert code == 0 and left == [], output
    assert output.count('[launch] again exited with code 0; respawning in 0.1 s') >= 2, output
    assert len(count.read_text()) >= 3  # each time, the program itself ran anew


def test_a_respawned_process_leaves_nothing_of_its_earlier_runs(tmp_path):
    """Each run starts a helper in its own process group and ends: the helper goes with it,
    not at the launcher's end (they were left running after '[launch] stopped')."""
    pids = tmp_path / 'helpers'
    starter = script(tmp_path, 'starter', f"""import subprocess, sys
helper = subprocess.Popen([sys.executable, '-c', 'import time; time.sleep(99)'])
open({str(pids)!r}, 'a').write(f'{{helper.pid}}\\n')
print('up')
""")
    launch = Launch(launch_file(tmp_path, f'''<executable name="starter" respawn="true"
                                            respawn_delay="0.1" cmd="{starter}"/>'''))
    try:
        for _ in range(3):
            launch.line('[starter] up')
        helpers = [int(pid) for pid in pids.read_text().split()]
        left_running = proc_tree.wait_gone(helpers[:2], 0)  # those of the ended runs
        code, left, output = launch.ctrl_c()
        assert left_running == [], output
        assert code == 0 and left == [] and output.rstrip().endswith('[launch] stopped'), output
        assert proc_tree.wait_gone([int(pid) for pid in pids.read_text().split()], 0) == []
    finally:  # on a failure, nothing left behind either
        proc_tree.send([int(pid) for pid in pids.read_text().split()], signal.SIGKILL)


def test_a_line_without_end_is_cut_and_what_follows_still_printed(tmp_path):
    from miro_ball.launch.runner import MAX_LINE_BYTES

    hog = script(tmp_path, 'hog', """import sys
sys.stdout.write('x' * 8_000_000)
sys.stdout.write('\\nend\\n')
""")
    launch = Launch(launch_file(tmp_path, f'<executable name="hog" cmd="{hog}"/>'))
    code, output = launch.finish()
    lines = output.splitlines()
    assert len(lines) == 5, [line[:80] for line in lines]  # the rest of the long line dropped
    assert code == 0 and lines[1:] == [
        f'[hog] {"x" * MAX_LINE_BYTES} [cut at {MAX_LINE_BYTES} bytes]', '[hog] end',
        '[launch] hog exited with code 0', '[launch] ended'], [line[:80] for line in lines]
