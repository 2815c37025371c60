"""The nodes of a run as child processes: started by name with a log file each, stopped
as a user stops them (Ctrl+C), killed if they do not, and nothing of theirs left behind.

Each child leads a process group (and session) of its own, so a Ctrl+C in the
terminal reaches only the program that started them, which stops them all at once:
side by side, the slowest sets the time, not their sum (every node stops within a
second of its Ctrl+C, with or without the simulator's /clock). Stopping one is what a
terminal does to a foreground job: SIGINT to its whole group (a shell script passes
nothing on to the program it waits for); after the grace period SIGKILL to the group;
and once the grace is over, SIGKILL to whatever of the group is still there (the
simulator's eye workers, a student's helpers).
"""
import os
import signal
import subprocess
import time
from dataclasses import dataclass

import psutil

GROUP_POLL_S = 0.05
KILL_WAIT_S = 1.0  # at most, for a killed group to be gone


@dataclass
class Child:
    name: str
    proc: subprocess.Popen
    log: object  # its open log file


class Processes:
    """Children started in a run: ``start`` them, ask which one ``dead``, ``stop`` them all.
    As a context manager, they are stopped at the end of the block."""

    def __init__(self, log_dir, env=None):
        """log_dir: where each child's <name>.log goes; env: their environment (default
        this process's)."""
        self.log_dir = log_dir
        self.env = env
        self.children = []
        log_dir.mkdir(parents=True, exist_ok=True)

    def start(self, name, command, env=None):
        """Start command as child ``name`` (its output in <name>.log); returns its Popen.
        OSError if it can not be started."""
        log = open(self.log_dir / f'{name}.log', 'w')
        try:
            proc = subprocess.Popen(command, env=self.env if env is None else env, stdout=log,
                                    stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL,
                                    start_new_session=True)
        except OSError:
            log.close()
            raise
        self.children.append(Child(name, proc, log))
        return proc

    def dead(self):
        """Name and exit code of a child that stopped on its own, or None."""
        for child in self.children:
            if child.proc.poll() is not None:
                return child.name, child.proc.returncode
        return None

    def pids(self):
        """{name: pid} of the children still running."""
        return {child.name: child.proc.pid for child in self.children
                if child.proc.poll() is None}

    def stop(self, grace_s=10.0):
        """Stop every child, all told at once; returns the names of those that had to be
        killed (they ignored Ctrl+C for grace_s)."""
        stopped = stop_all([child.proc for child in self.children], grace_s)
        for child in self.children:
            child.log.close()
        killed = [child.name for child, ok in zip(self.children, stopped) if not ok]
        self.children = []
        return killed

    def __enter__(self):
        return self

    def __exit__(self, *_):
        self.stop()


def stop_all(procs, grace_s):
    """Stop every one of procs (Popen, each leading a group) as stop_group does, all told at
    once: side by side, the slowest sets the time. Whether each stopped in time, in order."""
    for proc in procs:
        if proc.poll() is None:
            _signal_group(proc.pid, signal.SIGINT)
    deadline = time.monotonic() + grace_s
    return [stop_group(proc, max(0.0, deadline - time.monotonic()), interrupted=True)
            for proc in procs]


def stop_group(proc, grace_s, interrupted=False):
    """Ctrl+C to proc's process group (unless already ``interrupted``: a second one could cut
    a student's clean-up short); SIGKILL to the group once grace_s have passed or, if
    proc stopped in time, once the rest of the group has stopped too or the grace is over
    (a shell dies at Ctrl+C at once, while the program it ran still cleans up). False if
    proc itself had to be killed."""
    deadline = time.monotonic() + grace_s
    stopped = True
    if proc.poll() is None:
        if not interrupted:
            _signal_group(proc.pid, signal.SIGINT)
        try:
            proc.wait(timeout=grace_s)
        except subprocess.TimeoutExpired:
            stopped = False
            _signal_group(proc.pid, signal.SIGKILL)
            proc.wait()
    # The group's id can not be taken by another process while any member is alive.
    while _group_alive(proc.pid) and time.monotonic() < deadline:
        time.sleep(GROUP_POLL_S)
    # SIGKILL takes effect when the kernel next schedules each member: wait (a little) for
    # them to be gone, so that nothing of the group still runs once this returns.
    killed_by = time.monotonic() + KILL_WAIT_S
    while _signal_group(proc.pid, signal.SIGKILL) and _group_alive(proc.pid) \
            and time.monotonic() < killed_by:
        time.sleep(GROUP_POLL_S)
    return stopped


def _group_alive(pgid):
    """Whether a member of the process group still runs. Zombies do not count: whoever
    adopts a dead shell's children may take its time to reap them (the container's first
    process here does), and a zombie still answers kill(0)."""
    for process in psutil.process_iter(['status']):
        try:
            if process.info['status'] != psutil.STATUS_ZOMBIE and \
                    os.getpgid(process.pid) == pgid:
                return True
        except (ProcessLookupError, psutil.Error):  # gone meanwhile
            continue
    return False


def _signal_group(pgid, signum):
    """Send signum to the group; False if nobody is left in it."""
    try:
        os.killpg(pgid, signum)
    except ProcessLookupError:
        return False
    return True
