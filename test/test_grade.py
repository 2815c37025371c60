"""The grader, whole: its refusals, and gradings of our controller, of one that does nothing
and of one that dies at once printing garbage (its pure parts: test_grade_report)."""
import json
import os
import subprocess
import sys

PY = sys.executable


def grade(tmp_path, *args, timeout=120):
    """Run the grader as a user would; (its output, the episodes of its report)."""
    out = subprocess.run(
        [PY, '-m', 'miro_ball.grade', '--out', str(tmp_path / 'out'), '--grace', '2', *args],
        capture_output=True, text=True, timeout=timeout, cwd=tmp_path)
    assert out.returncode == 0, out.stdout + out.stderr
    assert 'Traceback' not in out.stderr
    [report] = (tmp_path / 'out').iterdir()
    return out.stdout, json.loads((report / 'results.json').read_text())['episodes'], report


def test_a_fifo_world_is_refused_not_waited_on(tmp_path):
    fifo = tmp_path / 'world.toml'
    os.mkfifo(fifo)
    out = subprocess.run([PY, '-m', 'miro_ball.grade', '--world', str(fifo), '--', PY],
                         capture_output=True, text=True, timeout=60)
    assert out.returncode == 2 and 'is not a regular file' in out.stderr


def test_a_ray_address_where_nobody_answers_is_one_line_at_once(tmp_path):
    out = subprocess.run([PY, '-m', 'miro_ball.grade', '--ray', '127.0.0.1:1', '--out',
                          str(tmp_path / 'out'), '--', PY],
                         capture_output=True, text=True, timeout=60)
    assert out.returncode == 2 and 'Traceback' not in out.stderr
    assert not (tmp_path / 'out').exists()  # no empty report
    assert out.stderr.strip().splitlines()[-1].endswith(
        'no Ray cluster answers at 127.0.0.1:1 (start one with `ray start --head`, or check '
        'the address and port)')


def test_a_world_the_grader_cannot_use_is_refused(tmp_path):
    out = subprocess.run([PY, '-m', 'miro_ball.grade', '--world', 'football_pitch', '--', PY],
                         capture_output=True, text=True, timeout=60)
    assert out.returncode == 2
    assert out.stderr.strip().endswith('the grader needs one robot and the ball, it has 3 '
                                       'robot(s) and a ball')


def test_our_controller_kicks(tmp_path):
    stdout, episodes, report = grade(tmp_path, '--count', '1', '--limit', '20', '--',
                                     PY, '-m', 'miro_ball', '--ros-args', '-p',
                                     'use_sim_time:=true')
    [episode] = episodes
    assert episode['kicked'] and not episode['fell'] and episode['ended'] == 'kicked'
    assert 0 < episode['time_to_kick'] < 20 and episode['distance_m'] > 0.3
    assert episode['notes'] == [] and not episode['killed']
    assert 'score 1/1 (100 %)' in stdout
    assert (report / episode['video']).stat().st_size > 10_000
    assert (report / 'index.html').is_file() and (report / 'results.csv').is_file()


def test_a_controller_that_does_nothing_scores_zero(tmp_path):
    stdout, episodes, _ = grade(tmp_path, '--count', '2', '--limit', '3',
                             '--real-time-factor', '0', '--command-wait', '1', '--',
                             PY, '-c', 'import time; time.sleep(1000)')
    assert [(e['kicked'], e['time_to_kick']) for e in episodes] == [(False, None)] * 2
    assert all(e['distance_m'] < 0.01 for e in episodes)  # settling after the placement
    assert all(e['ended'] == 'limit' and e['sim_time'] >= 3 for e in episodes)
    assert all(e['notes'] == ['never published on control/cmd_vel'] for e in episodes)
    assert 'score 0/2 (0 %)' in stdout


def test_a_command_that_dies_printing_garbage_is_reported(tmp_path):
    garbage = 'import os, sys; os.write(1, bytes(range(256)) * 4); sys.exit(3)'
    stdout, [episode], _ = grade(tmp_path, '--count', '1', '--', PY, '-c', garbage)
    assert not episode['kicked'] and episode['ended'] == 'command exited'
    assert episode['exit_code'] == 3 and episode['crashed'] and episode['sim_time'] < 30
    assert episode['notes'][0].startswith('exited with code 3 after')
    assert episode['output_tail'] and 'score 0/1 (0 %)' in stdout
    assert 'the last lines of its output:' in stdout
    assert all(c.isprintable() for line in stdout.splitlines() for c in line)
