"""A graded command as a process: started in its sandbox, its output kept within bounds,
stopped as a terminal stops a program, and nothing of it left afterwards.

Its output goes through a pipe to a thread here that keeps the first LOG_BYTES in the
episode's log and the last TAIL_BYTES besides: a command that floods gigabytes costs a
pipe's worth of reading, not the disk. Stopping: Ctrl+C (SIGINT) to every process of
the command, SIGKILL after the grace period; in the sandbox the end of its PID namespace
takes whatever is left, double-forked children included. Unsandboxed (trusted code), its
process group is stopped as the grader always did (run/processes.py).
"""
import collections
import os
import signal
import subprocess
import threading
import time

from miro_ball.common.proc_tree import descendants, wait_gone
from miro_ball.run.processes import stop_group

TAIL_LINES = 5
TAIL_WIDTH = 160
LOG_BYTES = 1 << 20  # kept from the start of the output
TAIL_BYTES = 1 << 16  # kept from its end
CHUNK = 1 << 16
GONE_S = 10.0  # wall: for the kernel to take a killed sandbox's last processes


def printable_tail(raw, lines=TAIL_LINES, width=TAIL_WIDTH):
    """The last non-empty lines of a program's output (bytes), safe to print: undecodable
    bytes and control characters become '?', long lines are cut."""
    text = raw.decode('utf-8', errors='replace')
    cleaned = [''.join(c if c.isprintable() and c != '\ufffd' else '?' for c in line).strip()
               for line in text.replace('\r', '\n').split('\n')]
    return [line[:width] + ('...' if len(line) > width else '')
            for line in cleaned if line][-lines:]


def _signal(pids, signum):
    for pid in pids:
        try:
            os.kill(pid, signum)
        except ProcessLookupError:
            pass


class Command:
    """argv started with env in cwd, its output logged to log_path; sandboxed: argv runs
    the command in bubblewrap (sandbox.command_line)."""

    def __init__(self, argv, *, env, cwd, log_path, sandboxed, preexec_fn=None, waits=False):
        """waits: argv is warm_start, which waits for go() before the command proper runs."""
        self.sandboxed = sandboxed
        self.log = open(log_path, 'wb')
        self.tail = collections.deque()
        self.tail_size = 0
        self.total = 0
        self.started = time.monotonic()
        def prepare():
            # Ctrl+C must reach it as from a terminal, though a Ray worker (whose host
            # started this) ignores and blocks SIGINT, which both outlast exec.
            signal.signal(signal.SIGINT, signal.SIG_DFL)
            signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})
            if preexec_fn is not None:
                preexec_fn()
        self.proc = subprocess.Popen(argv, env=env, cwd=cwd,
                                     stdin=subprocess.PIPE if waits else subprocess.DEVNULL,
                                     stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                     start_new_session=True, preexec_fn=prepare)
        self.reader = threading.Thread(target=self._read, daemon=True)
        self.reader.start()

    def _read(self):
        while True:
            chunk = self.proc.stdout.read1(CHUNK)
            if not chunk:
                return
            if self.total < LOG_BYTES:
                self.log.write(chunk[:LOG_BYTES - self.total])
            self.total += len(chunk)
            self.tail.append(chunk)
            self.tail_size += len(chunk)
            while self.tail_size - len(self.tail[0]) >= TAIL_BYTES:
                self.tail_size -= len(self.tail.popleft())

    def go(self):
        """Let a waiting command run (a broken pipe: it has ended, which exited() says)."""
        try:
            self.proc.stdin.write(b'go\n')
            self.proc.stdin.close()
        except OSError:
            pass

    def exited(self):
        """Its exit code once it ended by itself, else None."""
        return self.proc.poll()

    def stop(self, grace_s):
        """Ctrl+C, then SIGKILL after grace_s; True if it had to be killed."""
        if not self.sandboxed:
            killed = not stop_group(self.proc, grace_s)
        else:
            killed = self._stop_sandbox(grace_s)
        self.reader.join(timeout=grace_s)
        self._close_log()
        return killed

    def _stop_sandbox(self, grace_s):
        # What runs under the sandbox's first process gets Ctrl+C, as in a terminal
        # (bubblewrap passes no signal on); bubblewrap ends when the command does.
        # The tree is taken before anything ends: once bubblewrap has gone, what is left of
        # its processes is no longer found under it.
        tree = descendants(self.proc.pid)
        _signal(tree, signal.SIGINT)
        try:
            self.proc.wait(timeout=grace_s)
            killed = False
        except subprocess.TimeoutExpired:
            killed = True
        tree += descendants(self.proc.pid)  # what started since
        # Its PID namespace ends with bubblewrap: the kernel kills all that is left in it,
        # but after bubblewrap has gone. The next command of this host runs as the same user,
        # whose process limit a swarm of children not yet taken would fill (a measured
        # failure: the next command could not start a thread), so wait until they are gone.
        _signal([self.proc.pid, *tree], signal.SIGKILL)
        self.proc.wait()
        wait_gone(tree, GONE_S)
        return killed

    def _close_log(self):
        if self.total > LOG_BYTES:
            self.log.write(f'\n[... {self.total - LOG_BYTES} more bytes of output not kept; '
                           f'the last of them follow]\n'.encode())
            self.log.write(b''.join(self.tail)[-TAIL_BYTES:])
        self.log.close()

    def output_tail(self):
        return printable_tail(b''.join(self.tail)[-TAIL_BYTES:])
