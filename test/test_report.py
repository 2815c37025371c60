"""Each benchmark rewrites only its own section of BENCHMARKS.md; side by side figures."""
import re

import pytest

from miro_ball.bench.report import write_section


def test_a_section_is_replaced_and_the_rest_kept(tmp_path):
    path = tmp_path / 'BENCHMARKS.md'
    write_section(path, 'sim_bench', 'rtf 2')
    write_section(path, 'scenario_bench', '50/50')
    write_section(path, 'sim_bench', 'rtf 6')
    text = path.read_text()
    assert 'rtf 6' in text and 'rtf 2' not in text and '50/50' in text
    assert text.count('<!-- end of sim_bench -->') == 1


def test_a_section_whose_marker_names_an_older_module_is_replaced(tmp_path):
    path = tmp_path / 'BENCHMARKS.md'
    path.write_text('intro\n<!-- sim_bench: written by python -m miro_ball.lab.sim_bench -->\n'
                    'rtf 2\n<!-- end of sim_bench -->\nafter\n')
    write_section(path, 'sim_bench', 'rtf 6')
    text = path.read_text()
    assert text.startswith('intro\n<!-- sim_bench: written by python -m miro_ball.bench.')
    assert 'rtf 6' in text and 'rtf 2' not in text and text.endswith('after\n')


def test_a_ratio_beside_a_commit_pairs_the_runs_of_each_round():
    from miro_ball.bench.sim_bench import rtf_table

    def run(round_, rtf):
        return {'round': round_, 'real_time_factor': rtf, 'renderer': 'egl',
                'frames_per_wall_s': 1.0, 'frames_lost': 0, 'ms_per_camera_instant': 1.0,
                'peak_pss_mb': 1.0, 'peak_rss_mb': 1.0}

    case = ('default world, 2 eyes', 'miro', 1, 'egl')
    # The machine slowed down in round 1 for both: the rounds' ratios are 2x each, while
    # the ratio of the medians would say 3x; round 2 of the commit failed and is not paired.
    runs = {(case, 'this tree'): [run(0, 10.0), run(1, 3.0), run(2, 9.0)],
            (case, 'abc123'): [run(0, 5.0), run(1, 1.5)]}
    ours = rtf_table(runs, 'abc123')[2]
    assert '| 9.00 (3.00-10.00) | 2.00x (2.00-2.00) |' in ours


def test_the_previous_landing_names_a_commit_of_this_repository():
    import subprocess

    from miro_ball.bench import baseline

    shallow = subprocess.run(['git', '-C', str(baseline.ROOT), 'rev-parse',
                              '--is-shallow-repository'], capture_output=True, text=True)
    if shallow.stdout.strip() == 'true':
        pytest.skip('a shallow clone has not the history to check it against')
    commit = baseline.landed()
    done = subprocess.run(['git', '-C', str(baseline.ROOT), 'rev-parse', '--verify',
                           f'{commit}^{{commit}}'], capture_output=True, text=True)
    assert done.returncode == 0, f'.ci/landed names {commit!r}, not a commit here'


@pytest.mark.parametrize('content, refusal', [
    (None, 'can not be read (No such file or directory)'), (b' \n', 'names no commit'),
    (b'\xff\xfe\x00', 'is not text')])
def test_a_missing_or_garbled_landing_file_is_refused_in_one_line(tmp_path, monkeypatch,
                                                                  content, refusal):
    from miro_ball.bench import baseline

    landed = tmp_path / 'landed'
    if content is not None:
        landed.write_bytes(content)
    monkeypatch.setattr(baseline, 'LANDED', landed)
    with pytest.raises(baseline.BaselineError, match=re.escape(f'{landed} {refusal}')):
        baseline.checkout('landed')
