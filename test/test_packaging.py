"""The package installs the ROS way (console scripts, ament index marker, worlds as data) and
an installed copy works without the source tree: its worlds, and every file the GUI's page
loads. One installed copy for the file."""
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
BUNDLED = ['cube', 'den', 'empty', 'football', 'football_pitch', 'miro', 'petshop', 't_maze',
           'tables']


@pytest.fixture(scope='module')
def installed(tmp_path_factory):
    """The project installed (pip, no dependencies) into a folder of its own."""
    target = tmp_path_factory.mktemp('installed') / 'site'
    subprocess.run([sys.executable, '-m', 'pip', 'install', '-q', '--no-deps',
                    '--target', str(target), str(ROOT)],
                   check=True, capture_output=True)
    return target


def run_installed(target, probe, cwd):
    """probe's output, run by Python with -S (no site-packages, so neither the editable
    install nor the source tree is seen) on the installed copy only."""
    return subprocess.run([sys.executable, '-S', '-c', probe], cwd=cwd, check=True,
                          capture_output=True, text=True, env={'PYTHONPATH': str(target)}).stdout


def test_installed_copy_finds_its_worlds_without_the_source_tree(installed, tmp_path):
    probe = ('import miro_sim_bullet.scene.world_file as w; print(w.__file__); '
             'print(sorted(w.bundled_worlds())); print(len(w.load_world("miro").shapes))')
    path, worlds, shapes = run_installed(installed, probe, tmp_path).splitlines()
    assert path.startswith(str(installed))
    assert worlds == str(BUNDLED) and shapes == '13'


def test_ament_layout():
    setup_cfg = (ROOT / 'setup.cfg').read_text()
    assert 'install_scripts=$base/lib/miro_ball' in setup_cfg
    assert (ROOT / 'resource' / 'miro_ball').is_file()
    package_xml = (ROOT / 'package.xml').read_text()
    assert '<package format="3">' in package_xml and '<name>miro_ball</name>' in package_xml
    assert '<build_type>ament_python</build_type>' in package_xml
    setup_py = (ROOT / 'setup.py').read_text()
    for script in ("'miro_sim = miro_sim_bullet.ros.node:main'",
                   "'kick_blue_ball = miro_ball.controller.kick_blue_ball:main'",
                   "'ball_mover = miro_ball.examples.ball_mover:main'"):
        assert script in setup_py


def test_an_installed_copy_has_every_file_the_page_loads_and_nothing_from_elsewhere(
        installed, tmp_path):
    probe = 'import miro_ball.gui as g; print(g.__file__)'  # imports no web framework
    static = Path(run_installed(installed, probe, tmp_path).strip()).parent / 'static'
    assert static.is_relative_to(installed)
    html = (static / 'index.html').read_text()
    loaded = re.findall(r'(?:src|href)="([^"]+)"', html)
    assert '/static/app.js' in loaded and '/static/style.css' in loaded
    for url in loaded:
        assert url.startswith(('/static/', 'data:')), f'{url} is not served by miro_gui'
        if url.startswith('/static/'):
            assert (static / url.removeprefix('/static/')).is_file(), url
    for name in ('index.html', 'app.js', 'style.css'):
        text = (static / name).read_text()
        assert not re.search(r'https?://(?!\$\{)', text), f'{name} loads from another host'
