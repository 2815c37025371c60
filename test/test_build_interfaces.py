"""python -m miro_ball.build_interfaces: what it builds, skips and says, without building
(./dev.sh setup has built the packages into this venv before the tests run)."""
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from miro_ball import build_interfaces as b


def said():
    lines = []
    return lines, lines.append


def test_packages_built_from_unchanged_sources_are_not_built_again():
    lines, say = said()
    assert b.build_all(Path(sys.prefix), say=say) == []
    assert lines == ['tf2_msgs: up to date', 'miro2_msg: up to date',
                     'simulation_interfaces: up to date']


def test_changed_sources_are_built_again(tmp_path, monkeypatch):
    copy = tmp_path / 'interfaces'
    shutil.copytree(b.sources(), copy)
    (copy / 'miro2_msg' / 'msg' / 'Affect.msg').write_text('float32 valence\n')
    monkeypatch.setattr(b, 'sources', lambda: copy)
    monkeypatch.setattr(b, 'missing_tools', lambda prefix: ['a compiler (test)'])
    lines, say = said()
    with pytest.raises(b.BuildError, match=r'cannot build miro2_msg: missing a compiler'):
        b.build_all(Path(sys.prefix), say=say)
    assert lines == ['tf2_msgs: up to date', 'simulation_interfaces: up to date']


def test_what_is_missing_is_named_with_what_does_not_work_without_it(tmp_path, monkeypatch):
    monkeypatch.setattr(b.shutil, 'which', lambda command: None)
    monkeypatch.setattr(b, 'provided_elsewhere', lambda name, prefix: None)
    with pytest.raises(b.BuildError) as error:
        b.build_all(tmp_path, say=lambda line: None)
    message = str(error.value)
    assert '\n' not in message
    for needed in ('cmake (Debian: cmake)', 'c++ (Debian: g++)', "pip install 'miro_ball[msgs]'",
                   '/tf and /tf_static', 'sensors/package', 'standard control services',
                   'the rest runs'):
        assert needed in message


def test_a_package_another_prefix_provides_is_used_not_built(tmp_path):
    lines, say = said()  # this venv provides them all, seen from another prefix
    assert b.build_all(tmp_path, say=say) == []
    assert all('provided by' in line and 'not built' in line for line in lines)


def test_the_command_has_help_and_refuses_bad_options():
    run = [sys.executable, '-m', 'miro_ball.build_interfaces']
    assert 'miro2_msg' in subprocess.run(run + ['--help'], capture_output=True, text=True,
                                         timeout=60).stdout
    bad = subprocess.run(run + ['--jobs', '0'], capture_output=True, text=True, timeout=60)
    assert bad.returncode == 2 and 'Traceback' not in bad.stderr


def test_no_comment_of_our_interfaces_opens_or_closes_a_c_comment():
    """rosidl copies a definition's comments into the C headers it generates, inside /* */:
    'sensors/* topics' in SensorsPackage.msg made gcc warn 13 times ('"/*" within comment'),
    which colcon reports as the build's stderr; a '*/' would end the comment early."""
    found = [f'{path.relative_to(b.sources())}:{number}'
             for path in sorted(b.sources().rglob('*'))
             if path.suffix in ('.msg', '.srv', '.action')
             for number, line in enumerate(path.read_text().splitlines(), 1)
             if '#' in line and any(mark in line.split('#', 1)[1] for mark in ('/*', '*/'))]
    assert found == []
