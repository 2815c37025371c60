"""The grader: scores, table and JSON (pure), its command line, and whole gradings of our
controller, of one that does nothing and of one that dies at once printing garbage."""
import json
import subprocess
import sys

import pytest

from miro_ball.grade import parse_args
from miro_ball.grading.scores import notes, report, to_json, total_line
from miro_ball.run.episode import EpisodeResult
from miro_ball.run.process_rig import last_bytes, printable_tail

PY = sys.executable
PLACE = ((0.1, 0.2, 0.5), (0.6, -0.3))


def result(index=1, **facts):
    return EpisodeResult(index, *PLACE, **{'commands': 100, 'sim_time': 5.0, **facts})


def test_an_episode_is_won_by_kicking_without_falling():
    assert result(kicked=True, time_to_kick=3.0).success
    assert not result(kicked=True, time_to_kick=3.0, fell=True).success
    assert not result().success


def test_what_went_wrong_with_the_command_is_said():
    assert notes(result()) == []
    assert notes(result(exit_code=1, exited_after_s=0.24, ended='command exited')) == [
        'exited with code 1 after 0.2 s']
    assert notes(result(commands=0)) == ['never published on control/cmd_vel']
    assert 'flooded control/cmd_vel: 20000 messages' in notes(result(commands=100000))[0]
    assert notes(result(killed=True)) == ['ignored Ctrl+C, killed']
    assert notes(result(ended='the simulator did not take the placement')) == [
        'the simulator did not take the placement']


def test_output_tails_are_safe_to_print():
    raw = b'ok line\n\x1b[31mred\x1b[0m\n\xff\xfe bytes\r\n' + b'x' * 500 + b'\n\n'
    tail = printable_tail(raw, lines=3, width=50)
    assert tail[0] == '?[31mred?[0m'
    assert tail[1] == '?? bytes'
    assert tail[2] == 'x' * 50 + '...'
    assert all(c.isprintable() and c != '\ufffd' for line in tail for c in line)
    assert printable_tail(b'') == []


def test_the_total_counts_every_planned_episode():
    results = [result(1, kicked=True, time_to_kick=2.0, distance_m=1.0),
               result(2, kicked=True, time_to_kick=4.0, fell=True, distance_m=0.5),
               result(3, distance_m=0.25)]
    line = total_line(results, 4)
    assert line.startswith('score 1/4 (25 %) (only 3 ran): kicked 2, median time to kick 2.0 s')
    assert 'fell 1, driven 1.75 m' in line


def test_report_has_a_row_per_episode_then_the_output_of_those_that_failed():
    results = [result(2, commands=0, output_tail=['Traceback', 'boom']),
               result(1, kicked=True, time_to_kick=2.5)]
    text = report(results, 2).splitlines()
    assert text[0].split()[:2] == ['#', 'placement']
    assert text[1].split()[0] == '1' and '2.5 s' in text[1]
    assert text[2].split()[0] == '2' and text[2].endswith('never published on control/cmd_vel')
    assert text[-3:] == ['episode 2: never published on control/cmd_vel; the last lines of '
                         'its output:', '    Traceback', '    boom']


def test_json_is_a_list_of_episodes_with_kicked_and_time_to_kick():
    data = json.loads(to_json([result(2), result(1, kicked=True, time_to_kick=2.5)]))
    assert [(d['index'], d['kicked'], d['time_to_kick']) for d in data] == [
        (1, True, 2.5), (2, False, None)]
    assert data[0]['robot'] == list(PLACE[0]) and data[0]['success'] is True


@pytest.mark.parametrize('argv, message', [
    ([], 'no command to grade'),
    (['--count', '0', '--', PY], '--count must be in 1..1000'),
    (['--limit', 'nan', '--', PY], '--limit must be in (0, 3600]'),
    (['--', 'no-such-program-here'], 'command not found: no-such-program-here'),
    (['--json', '/no/such/dir/g.json', '--', PY], '--json: no folder /no/such/dir'),
])
def test_a_bad_command_line_is_one_line(argv, message, capsys):
    with pytest.raises(SystemExit) as stop:
        parse_args(argv)
    err = capsys.readouterr().err.strip().splitlines()
    assert stop.value.code == 2
    assert err[-1].startswith('python -m miro_ball.grade: error: ') and message in err[-1]


def grade(tmp_path, *args, timeout=120):
    """Run the grader as a user would; (its output, the episodes from --json)."""
    out = subprocess.run(
        [PY, '-m', 'miro_ball.grade', '--json', str(tmp_path / 'g.json'),
         '--out', str(tmp_path / 'logs'), '--grace', '2', *args],
        capture_output=True, text=True, timeout=timeout, cwd=tmp_path)
    assert out.returncode == 0, out.stdout + out.stderr
    assert 'Traceback' not in out.stderr
    return out.stdout, json.loads((tmp_path / 'g.json').read_text())


def test_a_world_the_grader_cannot_use_is_refused(tmp_path):
    out = subprocess.run([PY, '-m', 'miro_ball.grade', '--world', 'football_pitch', '--', PY],
                         capture_output=True, text=True, timeout=60)
    assert out.returncode == 2
    assert out.stderr.strip().endswith('the grader needs one robot and the ball, it has 3 '
                                       'robot(s) and a ball')


def test_our_controller_kicks(tmp_path):
    stdout, episodes = grade(tmp_path, '--count', '1', '--limit', '20', '--video',
                             str(tmp_path / 'video'), '--',
                             PY, '-m', 'miro_ball', '--ros-args', '-p', 'use_sim_time:=true')
    [episode] = episodes
    assert episode['kicked'] and not episode['fell'] and episode['ended'] == 'kicked'
    assert 0 < episode['time_to_kick'] < 20 and episode['distance_m'] > 0.3
    assert episode['notes'] == [] and not episode['killed']
    assert 'score 1/1 (100 %)' in stdout
    assert (tmp_path / 'video' / 'episode_01.mp4').stat().st_size > 10_000


def test_a_controller_that_does_nothing_scores_zero(tmp_path):
    stdout, episodes = grade(tmp_path, '--count', '2', '--limit', '3',
                             '--real-time-factor', '0', '--command-wait', '1', '--',
                             PY, '-c', 'import time; time.sleep(1000)')
    assert [(e['kicked'], e['time_to_kick']) for e in episodes] == [(False, None)] * 2
    assert all(e['distance_m'] < 0.01 for e in episodes)  # settling after the placement
    assert all(e['ended'] == 'limit' and e['sim_time'] >= 3 for e in episodes)
    assert all(e['notes'] == ['never published on control/cmd_vel'] for e in episodes)
    assert 'score 0/2 (0 %)' in stdout


def test_a_command_that_dies_printing_garbage_is_reported(tmp_path):
    garbage = 'import os, sys; os.write(1, bytes(range(256)) * 4); sys.exit(3)'
    stdout, [episode] = grade(tmp_path, '--count', '1', '--', PY, '-c', garbage)
    assert not episode['kicked'] and episode['ended'] == 'command exited'
    assert episode['exit_code'] == 3 and episode['exited_after_s'] < 30
    assert episode['notes'][0].startswith('exited with code 3 after')
    assert episode['output_tail'] and 'score 0/1 (0 %)' in stdout
    assert 'the last lines of its output:' in stdout
    assert all(c.isprintable() for line in stdout.splitlines() for c in line)


def test_only_the_end_of_a_huge_output_is_read(tmp_path):
    log = tmp_path / 'command.log'
    log.write_bytes(b'x' * 200_000 + b'\nthe end\n')
    assert last_bytes(log, 100).endswith(b'\nthe end\n') and len(last_bytes(log, 100)) == 100
    assert last_bytes(log) == log.read_bytes()[-65536:]
