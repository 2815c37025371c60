"""What a run does when one of its processes ends on its own: restart it if its launch file
says respawn (after respawn_delay), else end the run, said in one line. Pure: time passed
in."""
import signal
from dataclasses import dataclass


@dataclass(frozen=True)
class Restart:
    at: float  # monotonic time
    line: str


@dataclass(frozen=True)
class Stop:
    line: str


def how_it_ended(code):
    """'exited with code 3', 'was killed by SIGKILL' (Popen's negative codes)."""
    if code is not None and code < 0:
        try:
            return f'was killed by {signal.Signals(-code).name}'
        except ValueError:
            return f'was killed by signal {-code}'
    return f'exited with code {code}'


def after_exit(process, code, now):
    """Restart or Stop, for process (plan.Process) that ended with code at time now."""
    ended = f'{process.label} {how_it_ended(code)}'
    if process.respawn:
        delay = process.respawn_delay
        return Restart(now + delay, f'{ended}; respawning' + (f' in {delay:g} s' if delay else ''))
    return Stop(f'{ended}; stopping the others')
