"""The docs stand on their own and say what the code does: every relative link leads to a file
of the repository, nothing points at files a user of the repository does not have, and
docs/install.md's lists (the `ros2 run` executables, the set-up's extras) are setup.py's and
dev.sh's."""
import ast
import re
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DOCS = sorted((ROOT / 'docs').glob('*.md')) + [ROOT / 'README.md']
# Files of the development workspace outside the repository, which earlier docs cited.
OUTSIDE = re.compile(r'\.\./shared|shared/reference|miro_facts|miro_demo_mode\.md|'
                     r'tutorial_mdk_overview|mdk_gui_worlds_clients|miro_messages\.md')
LINK = re.compile(r'\[[^\]]*\]\(([^)\s]+)\)')


def tracked_files():
    listed = subprocess.run(['git', 'ls-files'], cwd=ROOT, capture_output=True, text=True,
                            check=True).stdout.split()
    return [ROOT / name for name in listed
            if name.endswith(('.md', '.py', '.js', '.html', '.toml', '.sh', '.cfg', '.xml'))
            and not name.startswith('test/test_docs.py')]


def test_no_file_refers_to_the_workspace_outside_the_repository():
    found = [f'{path.relative_to(ROOT)}:{number}: {line.strip()}'
             for path in tracked_files()
             for number, line in enumerate(path.read_text(errors='replace').splitlines(), 1)
             if OUTSIDE.search(line)]
    assert found == []


def test_every_relative_link_of_the_docs_leads_to_a_file_that_exists():
    broken = []
    for doc in DOCS:
        for target in LINK.findall(doc.read_text()):
            if re.match(r'[a-z]+:', target) or target.startswith('#'):
                continue  # a web address, or a place on the same page
            if not (doc.parent / target.split('#')[0]).exists():
                broken.append(f'{doc.relative_to(ROOT)}: {target}')
    assert broken == []


def console_scripts():
    tree = ast.parse((ROOT / 'setup.py').read_text())
    for node in ast.walk(tree):
        if isinstance(node, ast.Dict):
            for key, value in zip(node.keys, node.values):
                if isinstance(key, ast.Constant) and key.value == 'console_scripts':
                    return {entry.split('=')[0].strip() for entry in ast.literal_eval(value)}
    raise AssertionError('setup.py has no console_scripts')


def test_install_md_lists_every_ros2_run_executable_of_setup_py():
    text = (ROOT / 'docs' / 'install.md').read_text()
    listed = re.search(r'`ros2 run miro_ball \.\.\.` executable: (.*?)\n\(', text, re.S).group(1)
    assert set(re.findall(r'`(\w+)`', listed)) == console_scripts()


def test_install_md_names_the_extras_dev_sh_installs():
    dev_sh = (ROOT / 'dev.sh').read_text()
    setup_extras = set(re.search(r'local extras="([\w,]+)\$', dev_sh).group(1).split(','))
    test_extras = set(re.search(r'test\) setup ([\w,]+)', dev_sh).group(1).split(','))
    text = ' '.join((ROOT / 'docs' / 'install.md').read_text().split())
    said = re.search(r'editable, with the (.*?) extras', text).group(1)
    said_for_tests = re.search(r'`\./dev\.sh test` adds the (.*?) extras', text).group(1)
    assert set(re.findall(r'`(\w+)`', said)) == setup_extras
    assert set(re.findall(r'`(\w+)`', said_for_tests)) == test_extras
