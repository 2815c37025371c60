"""A parameter set on the command line that no node declares, or set to a value of the wrong
type, is refused before anything starts: the pure part (common.ros_params)."""
import os
import subprocess
import sys
from dataclasses import dataclass, field

import pytest

from miro_ball.common.ros_params import (check_overrides, node_matches, PARAMS_FILE_MAX_BYTES,
                                         ros_overrides)


@dataclass(frozen=True)
class Speeds:
    real_time_factor: float = field(default=1.0, metadata={'help': 'x', 'range': (0.0, 100.0)})
    paused: bool = field(default=False, metadata={'help': 'y'})
    world: str = field(default='miro', metadata={'help': 'z'})


def test_p_rules_are_read_as_ros_reads_them_yaml_values_and_only_inside_ros_args():
    argv = ['prog', '--world', 'x', '--ros-args', '-p', 'paused:=true', '--param',
            'real_time_factor:=2', '-r', '__ns:=/a', '--', '-p', 'outside:=1']
    assert ros_overrides(argv, 'sim') == {'paused': True, 'real_time_factor': 2}


def test_a_params_file_gives_the_nodes_own_and_the_wildcards_parameters(tmp_path):
    path = tmp_path / 'p.yaml'
    path.write_text('/**:\n  ros__parameters:\n    paused: true\n'
                    'sim:\n  ros__parameters:\n    world: cube\n    qos_overrides:\n'
                    '      depth: 3\n'
                    'other:\n  ros__parameters:\n    typo: 1\n')
    assert ros_overrides(['p', '--ros-args', '--params-file', str(path)], 'sim') == {
        'paused': True, 'world': 'cube', 'qos_overrides.depth': 3}


@pytest.mark.parametrize('argv', [['p', '--ros-args', '-p', 'novalue'],
                                  ['p', '--ros-args', '--params-file', '/nowhere.yaml']])
def test_what_can_not_be_read_is_a_one_line_error(argv):
    with pytest.raises(ValueError) as err:
        ros_overrides(argv, 'sim')
    assert '\n' not in str(err.value)


def test_a_params_file_that_is_no_regular_file_or_too_big_is_refused_without_waiting(
        tmp_path):
    """A FIFO held a program for ever, at our read and at rcl's (which comes after ours:
    common.cli.user_args); a device was read as YAML, and YAML's error took three lines."""
    fifo = tmp_path / 'fifo'
    os.mkfifo(fifo)
    big = tmp_path / 'big.yaml'
    big.write_text('#' * (PARAMS_FILE_MAX_BYTES + 1))
    broken = tmp_path / 'broken.yaml'
    broken.write_text('a: [\n')
    ended = subprocess.run(
        [sys.executable, '-c', 'import sys; from miro_ball.common.cli import user_args; '
                               'user_args(sys.argv, "prog")', '--ros-args', '--params-file',
         str(fifo)], capture_output=True, text=True, timeout=60)  # a hang guard only
    assert ended.returncode == 2 and ended.stderr == (
        f"prog: error: --params-file '{fifo}': 'fifo' is not a regular file\n")
    for path, says in ((fifo, "'fifo' is not a regular file"), ('/dev/zero', 'not a regular'),
                       (tmp_path, 'is not a regular file'), (big, 'more than 1 MB'),
                       (broken, 'while parsing')):
        with pytest.raises(ValueError) as err:
            ros_overrides(['p', '--ros-args', '--params-file', str(path)], 'sim')
        assert says in str(err.value) and '\n' not in str(err.value), err.value


@pytest.mark.parametrize('overrides, message', [
    ({'real_time_factr': 2}, "unknown parameter 'real_time_factr' (did you mean real_time_factor?)"),
    ({'zzz': 1}, "unknown parameter 'zzz' (--help lists the parameters)"),
    ({'paused': 3}, "parameter 'paused' must be true or false, not 3"),
    ({'real_time_factor': 'fast'}, "parameter 'real_time_factor' must be a number"),
    ({'use_sim_time': 'maybe'}, "parameter 'use_sim_time' must be true or false"),
])
def test_a_typo_or_a_wrong_type_is_refused_naming_it(overrides, message):
    with pytest.raises(ValueError) as err:
        check_overrides(overrides, Speeds)
    assert message in str(err.value)


def test_a_node_without_parameters_of_its_own_says_so_and_names_rosss():
    with pytest.raises(ValueError) as err:
        check_overrides({'speed': 1})
    assert str(err.value) == ("unknown parameter 'speed' (this node has none of its own; "
                              "ROS's: use_sim_time, start_type_description_service)")


def test_good_overrides_and_ross_own_parameters_pass():
    check_overrides({'real_time_factor': 2, 'paused': True, 'world': 'cube',
                     'use_sim_time': True, 'qos_overrides./clock.depth': 5}, Speeds)


@pytest.mark.parametrize('key, fqn, applies', [
    ('/**', '/miro02/kick_blue_ball', True),
    ('kick_blue_ball', '/kick_blue_ball', True),
    ('kick_blue_ball', '/miro02/kick_blue_ball', False),  # a key is taken from the root
    ('/*/kick_blue_ball', '/miro02/kick_blue_ball', True),
    ('/*/kick_blue_ball', '/kick_blue_ball', False),
    ('/**/kick_blue_ball', '/kick_blue_ball', True),
    ('/**/**/kick_blue_ball', '/a/b/kick_blue_ball', True),
    ('/**/*/**/kick_blue_ball', '/kick_blue_ball', False),
    ('/' + '**/' * 100_000 + 'x', '/' + '/'.join('abcdefghijklmnop'), False),
    ('/' + '*/' * 100_000 + 'x', '/a', False),
], ids=['all', 'root', 'root-only', 'one', 'one-missing', 'any-none', 'any-twice',
        'one-needed', 'many-any', 'many-one'])
def test_a_params_file_key_applies_to_a_node_as_rcl_decides_in_a_moment_whatever_it_is(
        key, fqn, applies):
    """A key of thousands of '**' took time exponential in their number (a params file can
    be anything); and one of 100,000 parts was a RecursionError."""
    assert node_matches(key, fqn) is applies
