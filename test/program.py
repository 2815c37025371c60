"""A program a test runs as a user would: `python -m MODULE ARGS` in a session of its own,
its output read line by line as it comes."""
import os
import queue
import signal
import subprocess
import sys
import threading
import time


class Program:
    """``guard_s``: how long line() and finish() wait (hang guards only)."""

    def __init__(self, module, *args, guard_s=120.0):
        self.guard_s = guard_s
        self.proc = subprocess.Popen([sys.executable, '-m', module, *args],
                                     stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                     text=True, start_new_session=True)
        self.lines, self.output = queue.Queue(), []
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self):
        for line in self.proc.stdout:
            self.lines.put(line)
        self.lines.put(None)

    def line(self, text):
        """The first line from now on that holds ``text``."""
        deadline = time.monotonic() + self.guard_s
        while time.monotonic() < deadline:
            try:
                line = self.lines.get(timeout=0.5)
            except queue.Empty:
                continue
            assert line is not None, 'the program ended:\n' + ''.join(self.output)
            self.output.append(line)
            if text in line:
                return line
        raise AssertionError(f'no {text!r}:\n' + ''.join(self.output))

    def finish(self):
        """(exit code, its whole output), once it ended (killed after guard_s)."""
        try:
            self.proc.wait(timeout=self.guard_s)
        finally:
            if self.proc.poll() is None:  # it and every process it started
                os.killpg(self.proc.pid, signal.SIGKILL)
                self.proc.wait()
        while (line := self.lines.get(timeout=self.guard_s)) is not None:
            self.output.append(line)
        return self.proc.returncode, ''.join(self.output)
