"""Every entry point refuses an unknown parameter and a value of the wrong type on its
command line: exit status 2 and one line that names it, before anything starts."""
import subprocess
import sys

import pytest

# (module, a real parameter of it with a value of the wrong type, or None: it has none)
ENTRY_POINTS = [
    ('miro_sim_bullet', 'real_time_factor:=fast', "parameter 'real_time_factor' must be a number"),
    ('miro_ball', 'tick:=often', "parameter 'tick' must be a number"),
    ('miro_ball.gui', 'use_sim_time:=maybe', "parameter 'use_sim_time' must be true or false"),
    ('miro_ball.record', 'use_sim_time:=2', "parameter 'use_sim_time' must be true or false"),
    ('miro_ball.examples.client_minimal', 'use_sim_time:=x',
     "parameter 'use_sim_time' must be true or false"),
]


def run(module, rule):
    return subprocess.run([sys.executable, '-m', module, '--ros-args', '-p', rule],
                          capture_output=True, text=True, timeout=60)


@pytest.mark.parametrize('module', [m for m, _, _ in ENTRY_POINTS])
def test_an_unknown_parameter_is_refused_in_one_line(module):
    out = run(module, 'not_a_param:=1')
    lines = out.stderr.splitlines()
    assert out.returncode == 2 and len(lines) == 1, out.stderr
    assert "error: unknown parameter 'not_a_param'" in lines[0]


@pytest.mark.parametrize('module, rule, message', ENTRY_POINTS)
def test_a_wrong_type_is_refused_in_one_line(module, rule, message):
    out = run(module, rule)
    lines = out.stderr.splitlines()
    assert out.returncode == 2 and len(lines) == 1 and message in lines[0], out.stderr


def test_a_near_miss_names_the_nearest_parameter():
    out = run('miro_sim_bullet', 'real_time_factr:=2')
    assert out.returncode == 2
    assert out.stderr.strip() == ("miro_sim: error: unknown parameter 'real_time_factr' "
                                  '(did you mean real_time_factor?)')
