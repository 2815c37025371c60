"""The page works offline from an installed copy: every file it loads is package data."""
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_an_installed_copy_has_every_file_the_page_loads_and_nothing_from_elsewhere(tmp_path):
    target = tmp_path / 'site'
    subprocess.run([sys.executable, '-m', 'pip', 'install', '-q', '--no-deps',
                    '--target', str(target), str(ROOT)], check=True, capture_output=True)
    probe = 'import miro_ball.gui as g; print(g.__file__)'  # imports no web framework
    out = subprocess.run([sys.executable, '-S', '-c', probe], cwd=tmp_path, check=True,
                         capture_output=True, text=True, env={'PYTHONPATH': str(target)})
    static = Path(out.stdout.strip()).parent / 'static'
    assert static.is_relative_to(target)
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
