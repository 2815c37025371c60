"""A class graded in one command, cheaters among the students (test/cheats.py): every cheat
scores 0 or is impossible and is named; the honest controller kicks; a flood or a swarm
of children costs only its own episode; nothing outlives the grading."""
import csv
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import psutil
import pytest

from cheats import CHEATS
from miro_ball.grading import sandbox
from miro_ball.grading.command import Command
from miro_ball.miro.interface import SimTopics

PY = sys.executable
CHEATS_PY = Path(__file__).with_name('cheats.py')
# Students who are no cheats: a controller.py each.
PLAIN = {'honest': 'import runpy, sys\nsys.argv = ["miro_ball", "--ros-args", "-p", '
                   '"use_sim_time:=true"]\nrunpy.run_module("miro_ball", run_name="__main__")\n',
         'idle': 'import time\ntime.sleep(600)\n'}
# Caught on the graph, with the words the report uses.
CAUGHT = {'teleport_ball': SimTopics().set_pose, 'teleport_robot': SimTopics().set_pose,
          'reset': SimTopics().reset, 'pause': SimTopics().pause,
          'teleport_standard': SimTopics().standard('SetEntityState'),
          'pause_standard': SimTopics().standard('SetSimulationState'),
          'slow_down': '/miro_sim/set_parameters', 'fake_clock': 'a clock of its own',
          'fake_ground_truth': SimTopics().ball, 'fake_sensors': "faking the robot's sensors",
          'ground_truth': '/miro_sim/objects/ball'}


def make_class(folder, names):
    for name in names:
        student = folder / name
        student.mkdir(parents=True)
        if name in PLAIN:
            (student / 'controller.py').write_text(PLAIN[name])
        else:
            run = student / 'run'
            run.write_text(f'#!/bin/sh\nexec {PY} {CHEATS_PY} {name}\n')
            run.chmod(0o755)
    return folder


def grade(class_dir, out, *args):
    done = subprocess.run([PY, '-m', 'miro_ball.grade', '--class', str(class_dir), '--out',
                           str(out), '--grace', '2', *args],
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stdout + done.stderr
    assert 'Traceback' not in done.stderr
    [report] = out.iterdir()
    return done.stdout, report


def still_running(pattern):
    return subprocess.run(['pgrep', '-f', pattern], capture_output=True).returncode == 0


@pytest.fixture(scope='module')
def graded(tmp_path_factory):
    """One grading of the whole class, two episodes at a time: (stdout, report folder,
    episodes by student)."""
    root = tmp_path_factory.mktemp('class')
    class_dir = make_class(root / 'students', ['honest', *CHEATS])
    stdout, report = grade(class_dir, root / 'out', '--count', '1', '--limit', '8',
                           '--jobs', '2')
    episodes = {e['student']: e for e in
                json.loads((report / 'results.json').read_text())['episodes']}
    return stdout, report, episodes


def test_the_honest_controller_kicks(graded):
    _, _, episodes = graded
    honest = episodes['honest']
    assert honest['success'] and honest['cheated'] is None and honest['time_to_kick'] > 0


@pytest.mark.parametrize('cheat', sorted(CAUGHT))
def test_each_cheat_on_the_graph_is_caught_and_named(graded, cheat):
    stdout, report, episodes = graded
    episode = episodes[cheat]
    assert not episode['success'] and episode['ended'] == 'cheated'
    assert CAUGHT[cheat] in episode['cheated']
    assert f'cheated 1 ({episode["cheated"][:20]}' in stdout
    assert 'cheated' in (report / 'index.html').read_text()
    log = (report / cheat / 'episode_01' / 'command.log').read_text(errors='replace')
    assert 'service answered' not in log and 'got ground truth' not in log  # nothing did


def test_the_grader_and_the_teachers_files_can_not_be_touched(graded):
    _, report, episodes = graded
    log = (report / 'edit_grader' / 'episode_01' / 'command.log').read_text(errors='replace')
    assert 'could not edit' in log and '\nedited' not in log
    assert 'home /root []' in log or "home /root ['.pyenv']" in log  # only the Python it runs
    assert 'HOME' in log and 'SSH_AUTH_SOCK' not in log
    assert "class folder ['edit_grader']" in log  # no other student's code
    assert 'KICK_DISTANCE_M = 0.0' not in (Path(__file__).parents[1] / 'miro_ball' / 'run'
                                           / 'judge.py').read_text()
    assert not episodes['edit_grader']['success']


def test_no_episode_reaches_another(graded):
    _, report, _ = graded
    log = (report / 'other_domains' / 'episode_01' / 'command.log').read_text(errors='replace')
    assert 'lock files none' in log
    assert 'simulators on domains [0] mine 0' in log  # its own simulator only


def test_nothing_a_command_starts_outlives_its_episode(graded):
    _, report, _ = graded
    log = (report / 'surviving_child' / 'episode_01' / 'command.log').read_text(errors='replace')
    assert 'child pid' in log  # it was there during the episode
    assert not still_running('cheats.py surviving_child')
    assert not still_running('cheats.py children')


def test_a_flood_or_a_swarm_of_children_costs_only_that_episode(graded):
    stdout, report, episodes = graded
    swarm = (report / 'children' / 'episode_01' / 'command.log').read_text(errors='replace')
    assert 'could not start child' in swarm  # the sandbox's process limit
    flood = episodes['flood']
    assert any('flooded control/cmd_vel' in note for note in flood['notes'])
    assert flood['log_bytes'] > (report / 'flood' / 'episode_01' / 'command.log').stat().st_size
    assert (report / 'flood' / 'episode_01' / 'command.log').stat().st_size < 2 << 20
    assert episodes['honest']['success']


SWARM = ('import os, time\n'
         'n = 0\n'
         'try:\n'
         '    while n < 100000:\n'
         '        if os.fork() == 0:\n'
         '            time.sleep(600)\n'
         '            os._exit(0)\n'
         '        n += 1\n'
         'except OSError:\n'
         '    print("full", n, flush=True)\n'
         'time.sleep(600)\n')


def sandboxed(tmp_path, name, code, uid):
    scratch = tmp_path / f'scratch_{name}'
    scratch.mkdir()
    os.chown(scratch, uid, uid)
    argv = sandbox.command_line([PY, '-c', code], workdir=tmp_path, scratch=scratch,
                                env={'HOME': str(scratch)}, uid=uid)
    return Command(argv, env={}, cwd='/', log_path=tmp_path / f'{name}.log', sandboxed=True,
                   preexec_fn=lambda: sandbox.limit_resources(True))


def until_said(command, words, wall_s=30.0):
    """Whether the command said words (wall time: a sandboxed process has no ROS clock)."""
    deadline = time.monotonic() + wall_s
    while not any(words in line for line in command.output_tail()):
        if time.monotonic() >= deadline:
            return False
        time.sleep(0.05)
    return True


def test_a_swarm_that_filled_its_users_process_limit_is_gone_when_stop_returns(tmp_path):
    """The next episode of a host runs as the same user: it must find the limit free."""
    uid = sandbox.sandbox_uid()
    if uid is None:
        pytest.skip('a sandbox user of its own needs root')
    swarm = sandboxed(tmp_path, 'swarm', SWARM, uid)
    assert until_said(swarm, 'full')
    swarm.stop(0.0)
    assert not [p for p in psutil.process_iter(['uids', 'status'])
                if p.info['uids'] and p.info['uids'].real == uid
                and p.info['status'] != psutil.STATUS_ZOMBIE]
    after = sandboxed(tmp_path, 'after', 'import threading\n'
                      'ts = [threading.Thread(target=lambda: None) for _ in range(50)]\n'
                      '[t.start() for t in ts]\nprint("started", len(ts), flush=True)\n', uid)
    assert until_said(after, 'started 50')
    after.stop(1.0)


def test_the_report_has_a_row_per_student(graded):
    _, report, episodes = graded
    with open(report / 'results.csv') as table:
        rows = {row['student']: row for row in csv.DictReader(table)}
    assert set(rows) == set(episodes)
    assert rows['honest']['score'] == '1' and rows['fake_clock']['cheated'] == '1'


def test_the_same_seed_gives_the_same_table(tmp_path):
    """Students whose episodes do not depend on timing: the tables are byte-identical."""
    class_dir = make_class(tmp_path / 'students', ['fake_sensors', 'teleport_ball'])
    tables = []
    for run in ('first', 'second'):
        _, report = grade(class_dir, tmp_path / run, '--count', '2', '--limit', '2',
                          '--seed', '7', '--no-video')
        tables.append((report / 'results.csv').read_bytes())
    assert tables[0] == tables[1]


def test_ctrl_c_stops_the_grading_and_every_episode_under_way(tmp_path):
    import signal
    import time

    class_dir = make_class(tmp_path / 'students', ['idle'])
    # This test's own student (test_grade_ray grades an 'idle' one too, maybe meanwhile).
    idle = f'{class_dir.resolve()}/idle/controller.py'
    grading = subprocess.Popen([PY, '-m', 'miro_ball.grade', '--class', str(class_dir),
                                '--out', str(tmp_path / 'out'), '--count', '3',
                                '--limit', '600', '--command-wait', '0'],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 120
    while not still_running(idle):  # the first episode is under way
        assert time.monotonic() < deadline and grading.poll() is None, grading.stderr.read()
        time.sleep(0.2)
    grading.send_signal(signal.SIGINT)
    out, err = grading.communicate(timeout=60)
    assert grading.returncode == 130 and 'Traceback' not in err, err
    assert not still_running(idle)
    [report] = (tmp_path / 'out').iterdir()
    assert json.loads((report / 'results.json').read_text())['episodes'] == []
    assert any(line.startswith('idle') and '0/3' in line for line in out.splitlines())
    assert 'interrupted: 0 of 3 episodes ran' in out
