"""What a run does when one of its processes ends on its own, as ROS 2's launch does: end
the run if its launch file says on_exit="shutdown"; else restart it if the file says
respawn (after respawn_delay); else let the others go on. Said in one line. Pure: time
passed in."""
import signal
from dataclasses import dataclass


@dataclass(frozen=True)
class Restart:
    at: float  # monotonic time
    line: str


@dataclass(frozen=True)
class Stop:
    """The run ends: the others are stopped."""
    line: str


@dataclass(frozen=True)
class GoOn:
    """The others run on; the run ends when none is left."""
    line: str


def how_it_ended(code):
    """'exited with code 3', 'was killed by SIGKILL' (Popen's negative codes)."""
    if code is not None and code < 0:
        try:
            return f'was killed by {signal.Signals(-code).name}'
        except ValueError:
            return f'was killed by signal {-code}'
    return f'exited with code {code}'


def after_exit(process, code, now, others=True):
    """Stop, Restart or GoOn, for process (plan.Process) that ended with code at time now
    (others: whether other processes of the run are still there). on_exit="shutdown" wins
    over respawn, as in ROS 2's launch (its shutdown cancels the respawn)."""
    ended = f'{process.label} {how_it_ended(code)}'
    if process.shutdown_on_exit:
        return Stop(f'{ended}; stopping the others')
    if process.respawn:
        delay = process.respawn_delay
        return Restart(now + delay, f'{ended}; respawning' + (f' in {delay:g} s' if delay else ''))
    return GoOn(f'{ended}; the others go on (its file does not say on_exit="shutdown")'
                if others else ended)
