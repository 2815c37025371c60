"""The processes a process started (children, theirs, ...), by psutil."""
import psutil


def descendants(pid):
    """Pids of every live process under pid, nearest first; [] when pid is gone."""
    try:
        return [child.pid for child in psutil.Process(pid).children(recursive=True)]
    except psutil.Error:
        return []
