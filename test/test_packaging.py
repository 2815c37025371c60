"""The package installs the ROS way: console scripts, ament index marker, worlds as data."""
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
BUNDLED = ['cube', 'empty', 'football', 'football_pitch', 'miro', 'petshop', 'tables']


def test_installed_copy_finds_its_worlds_without_the_source_tree(tmp_path):
    target = tmp_path / 'site'
    subprocess.run([sys.executable, '-m', 'pip', 'install', '-q', '--no-deps',
                    '--target', str(target), str(ROOT)],
                   check=True, capture_output=True)
    # -S: no site-packages, so neither the editable install nor the source tree is seen.
    probe = ('import miro_sim_bullet.scene.world_file as w; print(w.__file__); '
             'print(sorted(w.bundled_worlds())); print(len(w.load_world("miro").shapes))')
    out = subprocess.run([sys.executable, '-S', '-c', probe], cwd=tmp_path, check=True,
                         capture_output=True, text=True, env={'PYTHONPATH': str(target)})
    path, worlds, shapes = out.stdout.splitlines()
    assert path.startswith(str(target))
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
                   "'kick_blue_ball = miro_ball.controller.node:main'",
                   "'ball_mover = miro_ball.examples.ball_mover:main'"):
        assert script in setup_py
