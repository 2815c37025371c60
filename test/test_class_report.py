"""A whole class: who is found in the class folder, and the report a teacher reads.
Pure Python: no ROS, no simulator."""
import csv
import json
import os
from pathlib import Path
from datetime import datetime
from html.parser import HTMLParser

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from miro_ball.grading.class_report import (mark, report_folder, summaries, summary_line,
                                            write_report)
from miro_ball.grading.students import discover

HOSTILE = '<script>alert(1)</script>'
META = {'seed': 7, 'count': 3, 'world': 'miro', 'limit_s': 60.0, 'real_time_factor': 1.0,
        'isolation': 'Each command ran as user nobody in a network namespace of its own.',
        'started': '2026-11-23T18:40:00+00:00', 'wall_s': 93.5}


def episode(student, index, **changes):
    """One episode as the report gets it (episode_facts.complete): a miss by default."""
    result = {'student': student, 'index': index, 'robot': [0.5, -0.25, 1.0],
              'ball': [0.0, 0.3], 'success': False, 'kicked': False, 'time_to_kick': None,
              'fell': False, 'distance_m': 1.2, 'sim_time': 60.0, 'wall_time': 61.3,
              'ended': 'limit', 'cheated': None, 'crashed': False, 'exit_code': None,
              'killed': False, 'commands': 3000, 'notes': [], 'output_tail': [], 'video': None}
    result.update(changes)
    return result


def kick(student, index, t):
    return episode(student, index, success=True, kicked=True, time_to_kick=t, ended='kicked')


# --- discovery ---------------------------------------------------------------------------------

def make_class(root):
    (root / 'alice').mkdir()
    (root / 'alice' / 'run').write_text('#!/bin/sh\nexit 0\n')
    (root / 'alice' / 'run').chmod(0o755)
    (root / 'alice' / 'controller.py').write_text('')  # run wins
    (root / 'bob').mkdir()
    (root / 'bob' / 'controller.py').write_text('print(1)\n')
    (root / 'carol').mkdir()
    (root / 'carol' / 'notes.txt').write_text('nothing to run')
    (root / 'dave').mkdir()
    os.mkfifo(root / 'dave' / 'run')
    (root / 'eve').mkdir()
    (root / 'eve' / 'controller.py').symlink_to('/etc/passwd')
    (root / 'frank').mkdir()
    (root / 'frank' / 'src.py').write_text('')
    (root / 'frank' / 'controller.py').symlink_to('src.py')  # inside the folder: fine
    (root / 'bad name').mkdir()
    (root / 'bad name' / 'controller.py').write_text('')
    (root / '.git').mkdir()
    (root / 'README.txt').write_text('')
    (root / 'grace').mkdir()
    (root / 'grace' / 'run').write_text('#!/bin/sh\n')  # not executable, no controller.py


def test_discover_finds_each_kind_and_says_why_others_are_skipped(tmp_path):
    make_class(tmp_path)
    students, skipped = discover(tmp_path, python='/usr/bin/python3')
    assert [s.name for s in students] == ['alice', 'bob', 'frank']
    alice, bob, frank = students
    assert alice.command == [str(tmp_path / 'alice' / 'run')]
    assert alice.folder == tmp_path / 'alice'
    assert bob.command == ['/usr/bin/python3', str(tmp_path / 'bob' / 'controller.py')]
    assert frank.command == ['/usr/bin/python3', str(tmp_path / 'frank' / 'controller.py')]
    reasons = dict(skipped)
    assert set(reasons) == {'.git', 'README.txt', 'bad name', 'carol', 'dave', 'eve', 'grace'}
    assert 'FIFO' in reasons['dave']
    assert 'outside' in reasons['eve']
    assert 'characters' in reasons['bad name']
    assert 'hidden' in reasons['.git']
    assert 'not a folder' in reasons['README.txt']
    assert 'no executable run' in reasons['carol']
    assert 'not executable' in reasons['grace']


def test_a_student_whose_every_episode_crashed_the_same_way_is_told_why_in_one_line():
    said = "bwrap: Can't chdir to students/alice"
    crashed = [episode('alice', i, crashed=True, ended='command exited', exit_code=1,
                       output_tail=['starting', said]) for i in (1, 2)]
    alice, = summaries(['alice'], crashed, 2)
    assert summary_line(alice).endswith(f'crashed 2 (every episode: {said})')
    # Not when one episode did not crash, nor when they crashed in different ways.
    assert summaries(['alice'], crashed[:1] + [episode('alice', 2)], 2)[0]['why'] is None
    other = dict(crashed[1], output_tail=['ImportError: no module named cv3'])
    assert summaries(['alice'], [crashed[0], other], 2)[0]['why'] is None


def test_a_class_given_by_a_relative_path_is_the_same_class(tmp_path, monkeypatch):
    """Each command runs in its own folder: a relative path there meant another place, and
    every student of `--class students/` was scored crashed."""
    make_class(tmp_path)
    monkeypatch.chdir(tmp_path.parent)
    relative, _ = discover(tmp_path.name, python='/usr/bin/python3')
    absolute, _ = discover(tmp_path, python='/usr/bin/python3')
    assert relative == absolute
    assert all(s.folder.is_absolute() and Path(s.command[-1]).is_absolute() for s in relative)


def test_discover_refuses_what_is_no_class(tmp_path):
    with pytest.raises(ValueError, match='no student') as empty:
        discover(tmp_path)
    assert '\n' not in str(empty.value)
    (tmp_path / 'carol').mkdir()
    with pytest.raises(ValueError, match='no student'):
        discover(tmp_path)
    with pytest.raises(ValueError, match='not a folder'):
        discover(tmp_path / 'missing')
    os.mkfifo(tmp_path / 'pipe')
    with pytest.raises(ValueError, match='not a folder'):
        discover(tmp_path / 'pipe')


# --- summaries ---------------------------------------------------------------------------------

def test_a_cheated_episode_scores_nothing_even_kicked():
    episodes = [kick('alice', 1, 4.0), kick('alice', 2, 5.0),
                dict(kick('alice', 3, 0.5), cheated='published on /clock', ended='cheated'),
                episode('bob', 1, crashed=True, exit_code=1, ended='command exited'),
                episode('bob', 2, fell=True, ended='fell')]
    alice, bob, carol = summaries(['carol', 'bob', 'alice'], episodes, 3)
    assert (alice['score'], alice['kicked'], alice['cheated'], alice['median_time_to_kick']) \
        == (2, 2, 1, 4.5)
    assert alice['cheated_reasons'] == ['published on /clock']
    assert alice['marks'] == ['kick 4.0', 'kick 5.0', 'cheated']
    assert (bob['score'], bob['crashed'], bob['fell'], bob['ran']) == (0, 1, 1, 2)
    assert bob['marks'] == ['crashed', 'fell', 'not run']
    assert carol['score'] == 0 and carol['median_time_to_kick'] is None
    assert summary_line(alice) == ('alice       2/3 kicked, median 4.5 s, fell 0, cheated 1 '
                                   '(published on /clock), crashed 0')
    assert summary_line(carol) == 'carol       0/3 kicked, median -, fell 0, cheated 0, crashed 0'


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(st.booleans(), st.booleans(), st.booleans(),
                          st.floats(0, 60, allow_nan=False)), min_size=1, max_size=8))
def test_score_counts_kicks_without_fall_or_cheat(flags):
    episodes = [episode('x', i, kicked=k, fell=f, time_to_kick=t if k else None,
                        success=k and not f, cheated='set_pose' if c else None)
                for i, (k, f, c, t) in enumerate(flags, 1)]
    (summary,) = summaries(['x'], episodes, len(flags))
    wins = [t for k, f, c, t in flags if k and not f and not c]
    assert summary['score'] == len(wins)
    assert summary['marks'].count('cheated') == summary['cheated'] == sum(c for *_, c, _ in flags)
    assert (summary['median_time_to_kick'] is None) == (not wins)
    if wins:
        assert min(wins) <= summary['median_time_to_kick'] <= max(wins)
    assert [m.startswith('kick ') for m in summary['marks']] == \
        [k and not f and not c for k, f, c, _ in flags]


def test_mark_names_the_worst_first():
    assert mark(episode('a', 1, kicked=True, fell=True, crashed=True)) == 'fell'
    assert mark(episode('a', 1, crashed=True)) == 'crashed'
    assert mark(episode('a', 1)) == 'no'


# --- the report --------------------------------------------------------------------------------

def class_episodes():
    return [kick('alice', 2, 3.25), kick('alice', 1, 4.0),
            episode('alice', 3, video='alice-3.mp4', output_tail=['Traceback', 'boom']),
            episode(HOSTILE, 1, video=f'{HOSTILE}.mp4', output_tail=[HOSTILE, 'a & b'],
                    notes=[f'exited with code 1: {HOSTILE}'], crashed=True, exit_code=1),
            dict(kick(HOSTILE, 2, 1.0), cheated=HOSTILE, video='cheat.mp4'),
            kick('bob', 1, 2.0) | {'video': 'bob-1.mp4'}]


def test_report_files_parse_and_agree(tmp_path):
    paths = write_report(tmp_path / 'r', META, ['alice', 'bob', 'nobody', HOSTILE],
                         class_episodes())
    assert sorted(p.name for p in paths) == ['index.html', 'results.csv', 'results.json']
    data = json.loads((tmp_path / 'r' / 'results.json').read_text())
    assert data['meta'] == META
    assert [(e['student'], e['index']) for e in data['episodes']] == \
        [(HOSTILE, 1), (HOSTILE, 2), ('alice', 1), ('alice', 2), ('alice', 3), ('bob', 1)]
    scores = {s['student']: s['score'] for s in data['students']}
    assert scores == {HOSTILE: 0, 'alice': 2, 'bob': 1, 'nobody': 0}
    with open(tmp_path / 'r' / 'results.csv', newline='') as f:
        rows = list(csv.DictReader(f))
    alice = next(r for r in rows if r['student'] == 'alice')
    assert (alice['score'], alice['episodes'], alice['median_time_to_kick']) == ('2', '3', '3.6')
    assert (alice['ep1'], alice['ep2'], alice['ep3']) == ('kick 4.0', 'kick 3.2', 'no')
    hostile = next(r for r in rows if r['student'] == HOSTILE)
    assert (hostile['ep1'], hostile['ep2'], hostile['cheated']) == ('crashed', 'cheated', '1')
    nobody = next(r for r in rows if r['student'] == 'nobody')
    assert nobody['ep1'] == 'not run' and nobody['median_time_to_kick'] == ''


def test_html_escapes_what_students_chose_and_links_failed_videos(tmp_path):
    write_report(tmp_path, META | {'isolation': 'sandbox <none>'}, [HOSTILE, 'alice', 'bob'],
                 class_episodes() + [episode('alice', 4, output_tail=['\x1b[31mred\x00'])])
    page = (tmp_path / 'index.html').read_text()
    assert '<script' not in page
    assert '&lt;script&gt;alert(1)&lt;/script&gt;' in page
    assert 'a &amp; b' in page and 'sandbox &lt;none&gt;' in page
    assert '\x1b' not in page and '\x00' not in page
    assert 'href="alice-3.mp4"' in page and 'href="cheat.mp4"' in page
    assert 'bob-1.mp4' not in page  # a won episode needs no video
    assert 'href="%3Cscript%3Ealert%281%29%3C/script%3E.mp4"' in page
    assert page.count('<pre>') == 3  # the failed episodes with output
    assert 'Traceback' in page and 'http' not in page  # nothing fetched from elsewhere


class Tags(HTMLParser):
    def __init__(self):
        super().__init__()
        self.seen = set()

    def handle_starttag(self, tag, attrs):
        self.seen.add(tag)


@settings(max_examples=40, deadline=None)
@given(st.text(max_size=30), st.text(max_size=30))
def test_no_text_a_student_chose_becomes_markup(tmp_path_factory, name, output):
    folder = tmp_path_factory.mktemp('r')
    episodes = [episode(name, 1, notes=[output], output_tail=[output, name], video=output,
                        cheated=output or None)]
    write_report(folder, META, [name], episodes)
    tags = Tags()
    tags.feed((folder / 'index.html').read_text())
    assert tags.seen <= {'html', 'head', 'meta', 'title', 'style', 'body', 'h1', 'h2', 'table',
                         'tr', 'th', 'td', 'a', 'p', 'details', 'summary', 'pre'}
    assert json.loads((folder / 'results.json').read_text())['students'][0]['student'] == name


def test_same_inputs_give_the_same_bytes(tmp_path):
    episodes = class_episodes()
    write_report(tmp_path / 'a', META, ['alice', 'bob'], episodes)
    write_report(tmp_path / 'b', dict(reversed(META.items())), ['bob', 'alice'],
                 list(reversed(episodes)))
    for name in ('index.html', 'results.csv', 'results.json'):
        assert (tmp_path / 'a' / name).read_bytes() == (tmp_path / 'b' / name).read_bytes()


def test_report_folder_is_the_time_and_never_shared(tmp_path):
    now = datetime(2026, 11, 23, 18, 40, 5)
    first = report_folder(tmp_path / 'grade', now)
    second = report_folder(tmp_path / 'grade', now)
    assert first == tmp_path / 'grade' / '20261123-184005'
    assert second == tmp_path / 'grade' / '20261123-184005-2'
    assert first.is_dir() and second.is_dir()
