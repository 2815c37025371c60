"""Each benchmark rewrites only its own section of BENCHMARKS.md."""
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
