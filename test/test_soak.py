"""The soak: the process tree it measures, its command line and a short run of the real thing
(its figures and verdict: test_soak_verdict)."""
import re
import subprocess
import sys

from miro_ball.bench.soak import process_tree, rss_mb
from miro_ball.common.proc_tree import descendants
from miro_ball.miro.interface import default_robot_name
from rostools import run_command


def test_the_process_tree_includes_children_with_their_memory():
    proc = subprocess.Popen(['sh', '-c', 'sleep 30 & echo forked; wait'], stdout=subprocess.PIPE,
                            text=True)
    try:
        assert proc.stdout.readline() == 'forked\n'
        tree = process_tree([('top', proc.pid)])
        assert tree['top'] == proc.pid and len(tree) == 2, tree
        assert all(rss_mb(pid) > 0 for pid in tree.values())
    finally:
        for pid in descendants(proc.pid):
            subprocess.run(['kill', str(pid)])
        proc.wait()
        proc.stdout.close()


def test_help_and_bad_minutes():
    ok = subprocess.run([sys.executable, '-m', 'miro_ball.bench.soak', '--help'],
                        capture_output=True, text=True)
    assert ok.returncode == 0 and '--minutes' in ok.stdout and '--gui' in ok.stdout
    bad = subprocess.run([sys.executable, '-m', 'miro_ball.bench.soak', '--minutes', '-1'],
                         capture_output=True, text=True)
    assert bad.returncode == 2 and bad.stderr.strip().splitlines()[-1].startswith(
        'python -m miro_ball.bench.soak: error: --minutes')
    assert 'Traceback' not in bad.stderr


def test_a_short_soak_reports_every_process_and_the_growth(tmp_path):
    code, output = run_command([sys.executable, '-m', 'miro_ball.bench.soak', '--minutes',
                                '0.15', '--report-every', '3', '--out', str(tmp_path)])
    reports = re.findall(r'^after [0-9.]+ min: simulated [0-9.]+ min, RTF ([0-9.]+), '
                         r'(\d+) frames', output, re.M)
    assert len(reports) == 3, output
    assert all(float(rtf) > 0 for rtf, _ in reports), output
    assert sum(int(frames) for _, frames in reports) > 0, output
    for process in ('miro_sim', f'kick_blue_ball_{default_robot_name()}'):
        assert re.search(rf'^  {process} +RSS +[0-9.]+ MB  fds +\d+$', output, re.M), output
        assert re.search(rf'^  {process} +RSS +[0-9.]+ -> +[0-9.]+ MB +[-+][0-9.]+ %', output,
                         re.M), output
    assert re.search(r'^RTF per interval: [0-9.]+ [0-9.]+ [0-9.]+$', output, re.M), output
    judged = re.search(r'^verdict: (PASS|FAIL)$', output, re.M)
    assert judged and code == (0 if judged.group(1) == 'PASS' else 1), output
    for log in (tmp_path / 'soak').glob('*.log'):
        assert 'Traceback' not in log.read_text(), log
