"""One episode of our controllers, the one way the scenario benchmark and the closed-loop
tests run one (the grader, which runs any program, has its own rig, miro_ball/grading/host.py, and the
same judge).

An episode: the nodes come up with the simulator paused; robot and ball are put at
the placement (or stay at the world's start); the clock starts once the controllers
are there, so a slow start costs no simulated time; it ends when the one judge
(run/judge.py, fed the simulator's ground truth by the rig's referee) says it is over, or
early (a node exited, Ctrl+C).

The rig says where the nodes run: SteppedRig (stepped_rig.py), the simulator and our
controllers in this process on one executor, stepped one platform tick at a time, each
tick waited for until every controller commanded: outcomes depend on simulated time
only, whatever the machine's load (the same with any --jobs).

A rig has: referee (after open), open(), place(placement), wait_for_controllers(),
start(), advance(), ended_early() (why it ended, or None) and close(result) (its own
facts into the result); the steps before start raise RunError when the episode can
not go on.
"""
import time
from dataclasses import dataclass

from miro_ball.run.judge import SETTLE_S
from miro_ball.run.referee import RunError

PROGRESS_EVERY_S = 10.0  # wall


@dataclass
class EpisodeResult:
    index: int  # 1-based
    robot: tuple | None  # placement: x, y (m), yaw (rad); None: the world's start
    ball: tuple | None  # placement: x, y (m)
    kicked: bool = False
    time_to_kick: float | None = None  # simulated s from the start of the episode's clock
    fell: bool = False  # any robot
    distance_m: float = 0.0  # driven over the floor, all robots
    sim_time: float = 0.0  # simulated s the episode's clock ran
    wall_time: float = 0.0  # s, from starting the nodes to stopping them
    clock_wall_time: float = 0.0  # s while the episode's clock ran
    ended: str = ''  # why it stopped: kicked, fell, limit, command exited, ...
    frames: int | None = None  # camera frames the controllers took in (if known)

    @property
    def success(self):
        return self.kicked and not self.fell

    @property
    def real_time_factor(self):
        return self.sim_time / self.clock_wall_time if self.clock_wall_time > 0 else 0.0


def run_episode(rig, placement=None, index=1, limit_s=60.0, settle_s=SETTLE_S,
                progress=None):
    """One episode on rig from placement (None: the world's own start); returns an
    EpisodeResult. progress(referee) is called every PROGRESS_EVERY_S of wall time while
    the clock runs."""
    result = EpisodeResult(index, placement and tuple(placement.robot),
                           placement and tuple(placement.ball))
    started = time.monotonic()
    clock = None
    try:
        rig.open()
        if placement is not None:
            rig.place(placement)
        rig.wait_for_controllers()
        rig.start()
        clock = time.monotonic()
        result.ended = _run(rig, limit_s, settle_s, progress)
    except RunError as err:
        result.ended = str(err)
    finally:
        if clock is not None:
            result.clock_wall_time = time.monotonic() - clock
            _judge(result, rig.referee)
        rig.close(result)
        result.wall_time = time.monotonic() - started
    return result


def _run(rig, limit_s, settle_s, progress):
    """Advance until the episode ends; returns why."""
    referee = rig.referee
    next_progress = time.monotonic() + PROGRESS_EVERY_S
    while True:
        rig.advance()
        ended = referee.judge.over(limit_s, settle_s)
        if ended:
            return ended
        early = rig.ended_early()
        if early:
            return early
        if progress and time.monotonic() >= next_progress:
            next_progress = time.monotonic() + PROGRESS_EVERY_S
            progress(referee)


def _judge(result, referee):
    judge = referee.judge
    result.kicked = judge.kicked
    if judge.kicked:
        result.time_to_kick = round(judge.kick_time, 3)
    result.fell = judge.fell
    result.distance_m = round(judge.distance, 3)
    result.sim_time = round(judge.elapsed, 3)
