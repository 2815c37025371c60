"""The grader's notes, table and total, and its command line (pure)."""
import sys

import pytest

from miro_ball.grade import parse_args
from miro_ball.grading.command import printable_tail
from miro_ball.grading.episode_facts import complete, episode_folder, notes
from miro_ball.grading.hosts import lost
from miro_ball.grading.scores import report, total_line

PY = sys.executable
PLACE = ((0.1, 0.2, 0.5), (0.6, -0.3))


def result(index=1, **facts):
    spec = {'student': '', 'index': index, 'robot': list(PLACE[0]), 'ball': list(PLACE[1])}
    return complete(spec, {**lost(''), 'ended': 'limit', 'commands': 100, 'sim_time': 5.0,
                           **facts})


def test_an_episode_is_won_by_kicking_without_falling():
    assert result(kicked=True, time_to_kick=3.0)['success']
    assert not result(kicked=True, time_to_kick=3.0, fell=True)['success']
    assert not result(kicked=True, time_to_kick=3.0, cheated='published on /clock')['success']
    assert not result()['success']


def test_what_went_wrong_with_the_command_is_said():
    assert notes(result()) == []
    crashed = result(exit_code=1, sim_time=0.24, ended='command exited')
    assert notes(crashed) == ['exited with code 1 after 0.2 s simulated'] and crashed['crashed']
    assert notes(result(commands=0)) == ['never published on control/cmd_vel']
    assert 'flooded control/cmd_vel: 20000 messages' in notes(result(commands=100000))[0]
    assert notes(result(killed=True)) == ['ignored Ctrl+C, killed']
    assert notes(result(cheated='published on /clock')) == ['cheated: published on /clock']
    assert notes(result(ended='the grading host died')) == ['the grading host died']


def test_an_episodes_files_go_in_its_students_folder():
    assert episode_folder('alice', 3) == 'alice/episode_03'
    assert episode_folder('', 12) == 'command/episode_12'
    assert result(video='video.mp4')['video'] == 'command/episode_01/video.mp4'


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
    assert 'fell 1, cheated 0, driven 1.75 m' in line


def test_report_has_a_row_per_episode_then_the_output_of_those_that_failed():
    results = [result(2, commands=0, output_tail=['Traceback', 'boom']),
               result(1, kicked=True, time_to_kick=2.5)]
    text = report(results, 2).splitlines()
    assert text[0].split()[:2] == ['#', 'placement']
    assert text[1].split()[0] == '1' and '2.5 s' in text[1]
    assert text[2].split()[0] == '2' and text[2].endswith('never published on control/cmd_vel')
    assert text[-3:] == ['episode 2: never published on control/cmd_vel; the last lines of '
                         'its output:', '    Traceback', '    boom']


@pytest.mark.parametrize('argv, message', [
    ([], 'give either --class DIR or a command to grade after --'),
    (['--class', 'x', '--', PY], 'give either --class DIR or a command'),
    (['--count', '0', '--', PY], '--count must be in 1..1000'),
    (['--limit', 'nan', '--', PY], '--limit must be in (0, 3600]'),
    (['--', 'no-such-program-here'], 'command not found: no-such-program-here'),
    (['--world', '/no/such/world.toml', '--', PY], '--world: no file /no/such/world.toml'),
    (['--world', '/dev/null', '--', PY], '--world: /dev/null is not a regular file'),
    (['--json', '/no/such/dir/g.json', '--', PY], '--json: no folder /no/such/dir'),
])
def test_a_bad_command_line_is_one_line(argv, message, capsys):
    with pytest.raises(SystemExit) as stop:
        parse_args(argv)
    err = capsys.readouterr().err.strip().splitlines()
    assert stop.value.code == 2
    assert err[-1].startswith('python -m miro_ball.grade: error: ') and message in err[-1]
