"""Episodes with any command under test: it and the simulator are processes of their own
on a ROS domain of their own, watched by a referee node in this process (see episode.py).

The simulator starts paused; robot and ball are placed through set_pose; the clock
starts once the command has matched our subscription to control/cmd_vel (or after a
wait for it), so a slow start costs no simulated time. The simulator then runs at
a fixed real-time factor, so a command that keeps wall time is judged as fairly
as one on /clock. At the end the command gets Ctrl+C, then the simulator, each
killed after a grace period. A command that crashes, stays silent or floods the bus
is judged like any other, and what it did is noted in the result.
"""
import time
from contextlib import ExitStack
from dataclasses import dataclass
from pathlib import Path

from miro_ball.common.isolation import isolated_env
from miro_ball.miro.interface import ROBOT_NAME_ENV, RobotTopics
from miro_ball.run.nodes import sim_command
from miro_ball.run.processes import Processes
from miro_ball.run.referee import Referee, ros_domain, RunError
from miro_ball.run.video import VIDEO_FPS

TAIL_BYTES = 65536  # of the command's output, for its last lines
TAIL_LINES = 5
TAIL_WIDTH = 160
COMMAND = 'command'  # its log name


@dataclass
class Options:
    command: list  # the program under test and its arguments
    world: object  # the loaded world (miro_sim_bullet.scene.world_file.World)
    world_arg: str  # as given: a bundled name or a path
    robot: str  # its one robot's name
    limit_s: float = 60.0  # simulated
    real_time_factor: float = 1.0
    renderer: str = 'auto'
    grace_s: float = 5.0  # after Ctrl+C, before SIGKILL
    startup_s: float = 60.0  # wall s for the simulator to come up
    command_wait_s: float = 10.0  # wall s for the command to advertise control/cmd_vel
    out: Path = Path('out/grade')  # logs, one folder per episode
    video: Path | None = None  # folder for a video per episode


def wall_guard_s(options):
    """Longest wall time an episode may take once its clock runs (a hang guard only)."""
    slowest = options.real_time_factor / 4 if options.real_time_factor > 0 else 0.25
    return options.startup_s + options.limit_s / slowest


def last_bytes(path, size=TAIL_BYTES):
    """The end of a file: a command may have written gigabytes of garbage."""
    with open(path, 'rb') as log:
        log.seek(max(0, log.seek(0, 2) - size))
        return log.read()


def printable_tail(raw, lines=TAIL_LINES, width=TAIL_WIDTH):
    """The last non-empty lines of a program's output (bytes), safe to print: undecodable
    bytes and control characters become '?', long lines are cut."""
    text = raw.decode('utf-8', errors='replace')
    cleaned = [''.join(c if c.isprintable() and c != '\ufffd' else '?' for c in line).strip()
               for line in text.replace('\r', '\n').split('\n')]
    return [line[:width] + ('...' if len(line) > width else '')
            for line in cleaned if line][-lines:]


class ProcessRig:
    """Episode ``index`` of options.command on ROS domain ``domain``; stop: a StopRequest
    (Ctrl+C of the program running the episodes)."""

    def __init__(self, options, index, domain, stop):
        from miro_ball.run.video import Video

        self.options, self.domain, self.stop = options, domain, stop
        self.folder = options.out / f'episode_{index:02d}'
        self.video = Video(options.video / f'episode_{index:02d}.mp4', [options.robot]) \
            if options.video else None
        self.referee = self.procs = self.command = None
        self.counted = None  # our subscription to the command's control/cmd_vel
        self.commands = 0
        self.deadline = None
        self.started = time.monotonic()
        self.cleanup = ExitStack()

    def open(self):
        from geometry_msgs.msg import TwistStamped

        options = self.options
        env = dict(isolated_env(self.domain), **{ROBOT_NAME_ENV: options.robot})
        self.procs = self.cleanup.enter_context(Processes(self.folder, env))
        try:
            self.command = self.procs.start(COMMAND, options.command)
        except OSError as err:
            raise RunError(f'could not start the command: {err}') from None
        self.procs.start('miro_sim', sim_command(
            options.world_arg, options.renderer, options.real_time_factor,
            VIDEO_FPS if self.video else 0.0, paused=True))
        context = self.cleanup.enter_context(ros_domain(self.domain))
        self.referee = Referee(context, [options.robot], 'miro_grader', video=self.video)
        self.cleanup.callback(self.referee.close)
        # raw: a flooding command costs us no deserialising
        self.counted = self.referee.node.create_subscription(
            TwistStamped, RobotTopics(options.robot).cmd_vel, self._on_command, 10, raw=True)
        if not self._wait(self.referee.simulator_ready, options.startup_s):
            raise RunError(f'the simulator did not come up within {options.startup_s:g} s')

    def _on_command(self, _):
        self.commands += 1

    def _wait(self, predicate, timeout_s):
        """Spin until predicate() holds (True) or timeout_s pass (False); RunError if the
        episode ended meanwhile."""
        held = self.referee.spin_until(lambda: self.ended_early() or predicate(), timeout_s)
        early = self.ended_early()
        if early:
            raise RunError(early)
        return held

    def place(self, placement):
        self.referee.place(self.options.world, placement.robot, placement.ball)

    def wait_for_controllers(self):
        """Until the command's control/cmd_vel matched ours, or the wait is over: a command
        that never publishes is judged too."""
        self._wait(lambda: self.counted.get_publisher_count() > 0, self.options.command_wait_s)

    def start(self):
        self.referee.start_clock()
        self.deadline = time.monotonic() + wall_guard_s(self.options)

    def advance(self):
        self.referee.spin_once(0.05)

    def ended_early(self):
        if self.stop.requested:  # before the children's exits: they may be Ctrl+C'd too
            return 'interrupted'
        dead = self.procs.dead()
        if dead and dead[0] == COMMAND:
            return 'command exited'
        if dead:
            return f'the simulator exited with code {dead[1]} (see its log)'
        if self.deadline is not None and time.monotonic() > self.deadline:
            return f'the simulator was too slow: {self.referee.elapsed:.1f} s simulated in ' \
                   f'{wall_guard_s(self.options):.0f} s'
        return None

    def close(self, result):
        if result.ended == 'command exited':
            result.exit_code = self.command.returncode
            result.exited_after_s = round(time.monotonic() - self.started, 1)
        result.commands = self.commands
        if self.video:
            result.frames = self.referee.monitor.frames if self.referee else None
        # The command first: it may be waiting on the simulator's /clock.
        killed = self.procs.stop(self.options.grace_s) if self.procs else []
        result.killed = COMMAND in killed
        self.cleanup.close()
        if self.video:
            self.video.close()
        if self.command is not None and (result.exit_code is not None or result.commands == 0
                                         or result.killed):
            result.output_tail = printable_tail(last_bytes(self.folder / f'{COMMAND}.log'))
