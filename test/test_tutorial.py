"""docs/tutorial.md and docs/sim_control.md run as written, so they cannot rot.

A page marks what the test runs, in the fence's info string:

    ```sh run              a command the reader types and waits for: must exit 0
    ```sh shell1           a command left running in a shell of its own (shell1, shell2,
                           ...): started in the background, must still be running when
                           later blocks run, and must stop cleanly (exit 0) on Ctrl+C
    ```python run          a script the reader runs: must exit 0 (asserts inside count)
    ```python file=NAME    a file the reader saves as NAME, for later blocks

and HTML comments on lines of their own, invisible on the rendered page, where the reader
presses Ctrl+C, and where they wait until a shell has printed some text before going on:

    <!-- test: ctrl-c shell1 shell2 -->
    <!-- test: wait shell3 s simulated: -->

Fences with any other info string are shown, not run. Everything runs in a
temporary folder, on this test process's private ROS domain, with this Python's
bin folder first on PATH (what `. .venv/bin/activate` does).
"""
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from miro_ball.common.isolation import isolated_env

DOCS = Path(__file__).resolve().parent.parent / 'docs'
TUTORIAL = DOCS / 'tutorial.md'
PAGES = (TUTORIAL, DOCS / 'sim_control.md')  # the pages that run
FENCE = re.compile(r'^```(?P<info>[^\n]*)\n(?P<body>.*?)^```\s*$', re.M | re.S)
CTRL_C = re.compile(r'^<!--\s*test:\s*ctrl-c\s+(?P<shells>[\w ]+?)\s*-->\s*$', re.M)
WAIT = re.compile(r'^<!--\s*test:\s*wait\s+(?P<shell>shell\d+)\s+(?P<text>.+?)\s*-->\s*$', re.M)
SHELL = re.compile(r'shell\d+\Z')
RUN_TIMEOUT_S = 120  # guards against a hang only
STOP_TIMEOUT_S = 15


def steps(text):
    """('run' | 'python' | 'file' | 'background' | 'ctrl-c' | 'wait', argument, body) in page
    order."""
    found = []
    for match in FENCE.finditer(text):
        words = match['info'].split()
        language, marks = (words[0], words[1:]) if words else ('', [])
        body = match['body']
        if language == 'sh' and marks == ['run']:
            found.append((match.start(), ('run', None, body)))
        elif language == 'sh' and len(marks) == 1 and SHELL.match(marks[0]):
            found.append((match.start(), ('background', marks[0], body)))
        elif language == 'python' and marks == ['run']:
            found.append((match.start(), ('python', None, body)))
        elif language == 'python' and len(marks) == 1 and marks[0].startswith('file='):
            found.append((match.start(), ('file', marks[0][len('file='):], body)))
    for match in CTRL_C.finditer(text):
        found.append((match.start(), ('ctrl-c', match['shells'].split(), '')))
    for match in WAIT.finditer(text):
        found.append((match.start(), ('wait', match['shell'], match['text'])))
    return [step for _, step in sorted(found, key=lambda item: item[0])]


class Reader:
    """Types the tutorial's commands in its shells."""

    def __init__(self, folder):
        self.folder = folder
        self.env = dict(isolated_env(int(os.environ['ROS_DOMAIN_ID'])),
                        PATH=os.path.dirname(sys.executable) + os.pathsep + os.environ['PATH'])
        self.shells = {}  # name: (Popen, its output file, its command)
        self.count = 0

    def _log(self):
        self.count += 1
        return self.folder / f'step{self.count:02d}.log'

    def run(self, argv, what):
        """Run a command to its end; a shell that dies meanwhile fails the test at once."""
        log = self._log()
        with open(log, 'wb') as out:
            proc = subprocess.Popen(argv, cwd=self.folder, env=self.env, stdout=out,
                                    stderr=subprocess.STDOUT)
        deadline = time.monotonic() + RUN_TIMEOUT_S
        try:
            while proc.poll() is None:
                self.check_shells(what)
                assert time.monotonic() < deadline, f'{what}\nstill running after ' \
                    f'{RUN_TIMEOUT_S} s:\n{log.read_text(errors="replace")}'
                try:
                    proc.wait(timeout=0.2)
                except subprocess.TimeoutExpired:
                    pass
        finally:
            if proc.poll() is None:
                proc.kill()
                proc.wait()
        assert proc.returncode == 0, f'{what}\nexited with {proc.returncode}:\n' \
                                     f'{log.read_text(errors="replace")}'
        self.check_shells(what)

    def start(self, shell, body):
        assert shell not in self.shells, f'{shell} is still busy'
        log = self._log()
        out = open(log, 'wb')
        proc = subprocess.Popen(['bash', '-e', '-c', body], cwd=self.folder, env=self.env,
                                stdout=out, stderr=subprocess.STDOUT, start_new_session=True)
        out.close()
        self.shells[shell] = (proc, log, body)

    def check_shells(self, after):
        for shell, (proc, log, body) in self.shells.items():
            assert proc.poll() is None, f'{shell} ({body.strip()}) ended (code ' \
                f'{proc.returncode}) while: {after}\n{log.read_text(errors="replace")}'

    def wait_for(self, shell, text):
        """Wait until the shell has printed text (as a reader watches for a line before typing
        the next command); the shell must keep running meanwhile."""
        log = self.shells[shell][1]
        deadline = time.monotonic() + RUN_TIMEOUT_S
        while text not in log.read_text(errors='replace'):
            self.check_shells(f'waiting for {text!r} from {shell}')
            assert time.monotonic() < deadline, f'{shell} did not print {text!r} in ' \
                f'{RUN_TIMEOUT_S} s:\n{log.read_text(errors="replace")}'
            time.sleep(0.2)

    def ctrl_c(self, shell):
        proc, log, body = self.shells.pop(shell)
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGINT)  # what Ctrl+C in a terminal does
        try:
            code = proc.wait(timeout=STOP_TIMEOUT_S)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
            code = 'nothing: killed'
        assert code == 0, f'{shell} ({body.strip()}) on Ctrl+C exited with {code}:\n' \
                          f'{log.read_text(errors="replace")}'

    def close(self):
        for shell in list(self.shells):
            proc = self.shells[shell][0]
            if proc.poll() is None:
                os.killpg(proc.pid, signal.SIGKILL)
                proc.wait()
            del self.shells[shell]


def test_the_page_has_steps_of_every_kind():
    kinds = {kind for kind, _, _ in steps(TUTORIAL.read_text())}
    assert kinds == {'run', 'python', 'file', 'background', 'ctrl-c', 'wait'}


@pytest.mark.parametrize('page', PAGES, ids=[page.stem for page in PAGES])
def test_the_page_runs_as_written(page, tmp_path):
    reader = Reader(tmp_path)
    started = time.monotonic()
    try:
        for kind, argument, body in steps(page.read_text()):
            if kind == 'run':
                reader.run(['bash', '-e', '-c', body], body.strip())
            elif kind == 'python':
                script = tmp_path / f'snippet{reader.count + 1:02d}.py'
                script.write_text(body)
                reader.run([sys.executable, str(script)], body.strip())
            elif kind == 'file':
                (tmp_path / argument).write_text(body)
            elif kind == 'background':
                reader.start(argument, body)
            elif kind == 'wait':
                reader.wait_for(argument, body)
            else:
                for shell in argument:
                    reader.ctrl_c(shell)
        # Whatever the page leaves running, the reader stops with Ctrl+C at the end.
        for shell in list(reader.shells):
            reader.ctrl_c(shell)
    finally:
        reader.close()
    print(f'{page.name} ran in {time.monotonic() - started:.0f} s')
