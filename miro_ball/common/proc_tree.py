"""The processes a process started (children, theirs, ...), by psutil."""
import time

import psutil


def descendants(pid):
    """Pids of every live process under pid, nearest first; [] when pid is gone."""
    try:
        return [child.pid for child in psutil.Process(pid).children(recursive=True)]
    except psutil.Error:
        return []


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
