"""The processes a process started (children, theirs, ...), by psutil."""
import os
import time

import psutil


def descendants(pid):
    """Pids of every live process under pid, nearest first; [] when pid is gone."""
    try:
        return [child.pid for child in psutil.Process(pid).children(recursive=True)]
    except psutil.Error:
        return []


def in_my_group(pids):
    """Those of pids in this process's group: what a Ctrl+C in its terminal reaches too
    (a child started in a session of its own is its parent's to stop)."""
    mine = os.getpgrp()
    found = []
    for pid in pids:
        try:
            if os.getpgid(pid) == mine:
                found.append(pid)
        except ProcessLookupError:
            pass
    return found


def send(pids, signum):
    """Send signum to each of pids that still runs (one gone meanwhile is skipped)."""
    for pid in pids:
        try:
            psutil.Process(pid).send_signal(signum)
        except psutil.Error:
            pass


def _alive(proc):
    """Running (a zombie has released all but its exit status)."""
    try:
        return proc.status() != psutil.STATUS_ZOMBIE
    except psutil.Error:
        return False


def wait_gone(pids, timeout_s, poll_s=0.02):
    """Wait until none of pids is alive (gone or a zombie), at most timeout_s of wall time;
    the pids still alive then."""
    procs = []
    for pid in pids:
        try:
            procs.append(psutil.Process(pid))
        except psutil.Error:
            pass
    deadline = time.monotonic() + timeout_s
    while True:
        procs = [p for p in procs if _alive(p)]
        if not procs or time.monotonic() >= deadline:
            return [p.pid for p in procs]
        time.sleep(poll_s)
