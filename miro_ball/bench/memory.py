"""Memory of a process and everything it started, read from /proc while it runs.

Proportional set size (PSS) shares each shared page among the processes that map it, so
a helper process that maps the same libraries as the simulator adds what it really costs;
summed resident sizes would count libLLVM (~100 MB, mapped by every EGL process) twice.
"""
from pathlib import Path

from miro_ball.common.proc_tree import descendants


def tree_memory_mb(pid):
    """(PSS, RSS) in MB of process pid and its descendants now; (0, 0) if it is gone."""
    pss = rss = 0
    for process in [pid] + descendants(pid):
        try:
            for line in Path(f'/proc/{process}/smaps_rollup').read_text().splitlines():
                if line.startswith('Pss:'):
                    pss += int(line.split()[1])
                elif line.startswith('Rss:'):
                    rss += int(line.split()[1])
        except (OSError, ValueError):
            pass  # ended between the listing and the reading
    return pss / 1024, rss / 1024
