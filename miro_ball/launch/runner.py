"""The processes of a launch file, run: each in a process group (and session) of its own,
its output printed line by line after its label; one that ends ends the run, is restarted
or leaves the others running, as its file says (``exits``); on Ctrl+C or SIGTERM, all
told to stop at once as a terminal tells one, and killed if they have not after
STOP_GRACE_S (``run.processes.stop_all``).

The children's own sessions keep a terminal's Ctrl+C from reaching them straight: the
launcher tells each one itself, so that it knows which it told and waits for them all. What
one that ended leaves running in its group (its helpers) is killed there and then: a
process restarted leaves nothing of its earlier runs behind.
"""
import subprocess
import sys
import threading
import time

from miro_ball.launch.exits import after_exit, Restart, Stop
from miro_ball.run.processes import stop_all, stop_group

POLL_S = 0.05
STOP_GRACE_S = 5.0  # our nodes stop within a second of their Ctrl+C
READER_WAIT_S = 1.0  # for the last lines of a process that ended
# A line longer is cut there, the rest of it skipped: 250 MB with no newline took the
# launcher to 1 GB. A log line is under a kilobyte; a traceback's longest, a few.
MAX_LINE_BYTES = 16384


class Output:
    """Lines of every process, each whole, after its label."""

    def __init__(self, stream=None):
        self.stream = stream or sys.stdout
        self.lock = threading.Lock()

    def say(self, label, line):
        with self.lock:
            try:
                self.stream.write(f'[{label}] {line}\n')
                self.stream.flush()
            except (OSError, ValueError):  # nobody reads our output any more: go on
                pass

    def follow(self, label, pipe):
        """A thread that prints what pipe brings, line by line, until it closes."""
        def read():
            with pipe:
                for raw in bounded_lines(pipe, MAX_LINE_BYTES):
                    self.say(label, raw.decode(errors='replace').rstrip('\r\n'))
        thread = threading.Thread(target=read, daemon=True)
        thread.start()
        return thread


def bounded_lines(pipe, limit):
    """The lines of a binary pipe, each at most limit bytes: a longer one is cut, said at
    its end, and the rest of it read and dropped."""
    while line := pipe.readline(limit):
        if len(line) == limit and not line.endswith(b'\n'):
            while (rest := pipe.readline(limit)) and not rest.endswith(b'\n'):
                pass
            line += f' [cut at {limit} bytes]'.encode()
        yield line


class Running:
    """A process of the plan: started (proc, its output's reader), waiting to restart, or
    ended for good."""

    def __init__(self, process, command):
        self.process, self.command = process, command
        self.proc = self.reader = None
        self.restart_at = None
        self.failed = False  # it ended on its own with a code other than 0 (or by a signal)

    @property
    def over(self):
        return self.proc is None and self.restart_at is None


def run(processes, commands, env, stop, output=None, clock=time.monotonic):
    """Run processes (plan.Process) with their commands until stop.requested (a
    common.stopping.StopRequest), one whose file says on_exit="shutdown" ends, or none is
    left; every one still running is stopped on the way out. The exit code: 1 if one
    ended on its own with a code other than 0 (or by a signal), or had to be killed; else
    0."""
    output = output or Output()
    running = [Running(process, command) for process, command in zip(processes, commands)]
    killed = False
    try:
        for one in running:
            _start(one, env, output)
        while not stop.requested and _look(running, env, output, clock()):
            time.sleep(POLL_S)
    finally:
        started = [one for one in running if one.proc is not None]
        stopped = stop_all([one.proc for one in started], STOP_GRACE_S)
        for one, ok in zip(started, stopped):
            if not ok:
                output.say('launch', f'{one.process.label} ignored Ctrl+C for '
                                     f'{STOP_GRACE_S:g} s: killed')
                killed = True
            one.reader.join(READER_WAIT_S)
    return int(killed or any(one.failed for one in running))


def _start(one, env, output):
    try:
        one.proc = subprocess.Popen(one.command, env=env, stdout=subprocess.PIPE,
                                    stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL,
                                    start_new_session=True)
    except OSError as err:
        one.proc = None
        raise SystemExit(f'python -m miro_ball.launch: error: {one.process.label} can not be '
                         f'started: {err}') from None
    one.reader = output.follow(one.process.label, one.proc.stdout)
    one.restart_at = None


def _look(running, env, output, now):
    """One look at every process: restart those due, deal with those that ended; whether
    the run goes on."""
    for one in running:
        if one.restart_at is not None:
            if now >= one.restart_at:
                _start(one, env, output)
            continue
        code = None if one.proc is None else one.proc.poll()
        if code is None:
            continue
        stop_group(one.proc, 0)  # what it left running; they hold its output open too
        one.reader.join(READER_WAIT_S)  # its last words before ours
        one.failed = one.failed or code != 0
        one.proc = None
        others = not all(other.over for other in running)
        decision = after_exit(one.process, code, now, others)
        output.say('launch', decision.line)
        if isinstance(decision, Stop):
            return False
        if isinstance(decision, Restart):
            one.restart_at = decision.at
    return not all(one.over for one in running)
