"""Grading any controller: each episode a fresh simulator and the command under test,
as processes of their own on a ROS domain of their own.

An episode: the simulator starts paused; the robot and the ball are put at the
episode's placement through set_pose; the clock starts once the command has a
publisher on control/cmd_vel (or after a wait for it), so a slow start costs no
simulated time. It stops when the ball has moved KICK_DISTANCE_M, the robot fell,
the limit of simulated time passed or the command exited; the command gets
Ctrl+C (SIGINT) first, then the simulator, each killed after a grace period.
The simulator runs at a fixed real-time factor, so a controller that keeps wall
time is judged as fairly as one on /clock. A command that crashes, stays
silent or floods the bus is scored like any other, and what it did is noted.
"""
import queue
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path

from miro_ball.common.isolation import isolated_env, private_domains
from miro_ball.demo import Processes, Video, VIDEO_FPS
from miro_ball.grading.scores import EpisodeResult, placement_text, printable_tail
from miro_ball.miro.interface import RobotTopics, ROBOT_NAME_ENV, SimTopics

PLACED_WITHIN_M = 0.02  # ground truth this close to the placement: it took
PLACE_TRIES = 20
SERVICE_TIMEOUT_S = 10.0
PROGRESS_EVERY_S = 10.0
TAIL_BYTES = 65536  # of the command's output, for its last lines


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
    video: Path | None = None


class EpisodeError(RuntimeError):
    """The simulator did not come up or took no placement: not the command's fault."""


class Session:
    """The grader's side of one episode: a node on the episode's domain that watches the
    run (Monitor), places robot and ball, counts commands and pauses the simulator."""

    def __init__(self, options, domain, video):
        import rclpy
        from geometry_msgs.msg import PoseStamped, TwistStamped
        from rclpy.context import Context
        from rclpy.executors import SingleThreadedExecutor
        from rclpy.parameter import Parameter
        from std_srvs.srv import SetBool, Trigger

        from miro_ball.run.monitor import Monitor

        self.context = Context()
        rclpy.init(context=self.context, domain_id=domain)
        self.node = rclpy.create_node('miro_grader', context=self.context,
                                      parameter_overrides=[Parameter('use_sim_time', value=True)])
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)
        self.robot = options.robot
        self.topics, sim = RobotTopics(options.robot), SimTopics()
        self.monitor = Monitor(self.node, [options.robot], debug_frames=video is not None,
                               on_eye=video.eye if video else None,
                               on_overhead=self._on_overhead if video else None)
        self.video = video
        self.set_pose = self.node.create_publisher(PoseStamped, sim.set_pose, 10)
        self.pause = self.node.create_client(SetBool, sim.pause)
        self.step = self.node.create_client(Trigger, sim.step)
        self.commands = 0
        # raw: a flooding command costs us no deserialising
        self.node.create_subscription(TwistStamped, self.topics.cmd_vel, self._on_command, 10,
                                      raw=True)
        self.start_time = 0.0  # simulated time when the episode's clock started

    def _on_command(self, _):
        self.commands += 1

    def _on_overhead(self, bgr):
        status = 'KICKED' if self.monitor.kicked else ''
        self.video.overhead(bgr, f't = {self.elapsed:5.1f} s   {status}')

    @property
    def elapsed(self):
        return max(0.0, self.monitor.sim_time - self.start_time)

    @property
    def watch(self):
        return self.monitor.robots[self.robot]

    def spin_until(self, predicate, timeout_s):
        deadline = time.monotonic() + timeout_s
        while not predicate():
            if time.monotonic() > deadline:
                return False
            self.executor.spin_once(timeout_sec=0.02)
        return True

    def call(self, client, request):
        future = client.call_async(request)
        if not self.spin_until(future.done, SERVICE_TIMEOUT_S):
            raise EpisodeError(f'the simulator did not answer {client.srv_name}')
        return future.result()

    def place(self, world, robot, ball):
        """Robot and ball at the placement, checked on the ground truth (the set_pose
        topic and the step service are not ordered, so it is tried until it took)."""
        from std_srvs.srv import Trigger

        from miro_sim_bullet.ros import convert

        spec = world.robots[0]
        when = self.node.get_clock().now().to_msg()
        robot_msg = convert.robot_pose(*robot[:2], spec.floor, robot[2], when)
        ball_msg = convert.pose((*ball, world.ball.floor + world.ball.radius),
                                (0.0, 0.0, 0.0, 1.0), when)
        robot_msg.header.frame_id, ball_msg.header.frame_id = self.robot, 'ball'

        def took():
            at = self.watch.position
            return (self.monitor.ball is not None and at is not None
                    and max(abs(at[0] - robot[0]), abs(at[1] - robot[1]),
                            abs(self.monitor.ball[0] - ball[0]),
                            abs(self.monitor.ball[1] - ball[1])) < PLACED_WITHIN_M)
        for _ in range(PLACE_TRIES):
            self.set_pose.publish(robot_msg)
            self.set_pose.publish(ball_msg)
            self.call(self.step, Trigger.Request())
            if self.spin_until(took, 0.2):
                return
        raise EpisodeError('the simulator did not take the placement')

    def start_clock(self):
        from std_srvs.srv import SetBool

        self.monitor.restart()
        self.start_time = self.monitor.sim_time
        self.call(self.pause, SetBool.Request(data=False))

    def close(self):
        import rclpy

        self.executor.shutdown(timeout_sec=1.0)
        self.node.destroy_node()
        rclpy.try_shutdown(context=self.context)


def sim_command(options):
    return [sys.executable, '-m', 'miro_sim_bullet', '--ros-args',
            '-p', f'world:={options.world_arg}', '-p', 'paused:=true',
            '-p', f'robot_name:={options.robot}', '-p', f'renderer:={options.renderer}',
            '-p', f'real_time_factor:={options.real_time_factor}',
            '-p', f'overhead_rate:={VIDEO_FPS if options.video else 0.0}']


def wall_guard_s(options):
    """Longest wall time an episode may take once its clock runs (a hang guard only)."""
    slowest = options.real_time_factor / 4 if options.real_time_factor > 0 else 0.25
    return options.startup_s + options.limit_s / slowest


def run_episode(index, placement, options, domain, stop, log=print):
    """One episode; returns an EpisodeResult. stop: a StopRequest (Ctrl+C of the grader)."""
    result = EpisodeResult(index, tuple(placement.robot), tuple(placement.ball))
    folder = options.out / f'episode_{index:02d}'
    env = dict(isolated_env(domain), **{ROBOT_NAME_ENV: options.robot})
    video = Video(options.video / f'episode_{index:02d}.mp4', [options.robot]) \
        if options.video else None
    started = time.monotonic()
    try:
        procs = Processes([('command', options.command), ('miro_sim', sim_command(options))],
                          env, folder)
    except OSError as err:
        result.ended = f'could not start the command: {err}'
        return result
    command = procs.procs[0][1]
    session = None
    try:
        session = Session(options, domain, video)
        result.ended = _play(session, procs, placement, options, stop, log, index)
    except EpisodeError as err:
        result.ended = str(err)
    finally:
        if result.ended == 'command exited':
            result.exit_code = command.returncode
            result.exited_after_s = round(time.monotonic() - started, 1)
        if session is not None:
            _collect(result, session)
            session.close()
        result.killed = 'command' in procs.stop(options.grace_s)
        result.wall_time = time.monotonic() - started
        if video:
            video.close()
    if result.exit_code is not None or result.commands == 0 or result.killed:
        result.output_tail = printable_tail(last_bytes(folder / 'command.log'))
    return result


def last_bytes(path, size=TAIL_BYTES):
    """The end of a file: a command may have written gigabytes of garbage."""
    with open(path, 'rb') as log:
        log.seek(max(0, log.seek(0, 2) - size))
        return log.read()


def _play(session, procs, placement, options, stop, log, index):
    """Start, place, wait for the command, run; returns why the episode ended."""
    def ended_early():
        if stop.requested:  # before the children's exits: Ctrl+C in a terminal reaches them too
            return 'interrupted'
        dead = procs.dead()
        if dead and dead[0] == 'command':
            return 'command exited'
        if dead:
            return f'the simulator exited with code {dead[1]} (see its log)'
        return None

    if not session.spin_until(lambda: ended_early() or (
            session.step.service_is_ready() and session.set_pose.get_subscription_count()),
            options.startup_s):
        raise EpisodeError(f'the simulator did not come up within {options.startup_s:g} s')
    if ended_early():
        return ended_early()
    session.place(options.world, placement.robot, placement.ball)
    session.spin_until(lambda: ended_early() or session.node.count_publishers(
        session.topics.cmd_vel) > 0, options.command_wait_s)
    if ended_early():
        return ended_early()
    session.start_clock()
    deadline = time.monotonic() + wall_guard_s(options)
    next_progress = time.monotonic() + PROGRESS_EVERY_S
    while True:
        session.executor.spin_once(timeout_sec=0.05)
        if session.monitor.kicked:
            return 'kicked'
        if session.watch.fell:
            return 'fell'
        if session.elapsed >= options.limit_s:
            return 'limit'
        if ended_early():
            return ended_early()
        now = time.monotonic()
        if now > deadline:
            return f'the simulator was too slow: {session.elapsed:.1f} s simulated in ' \
                   f'{wall_guard_s(options):.0f} s'
        if now >= next_progress:
            next_progress = now + PROGRESS_EVERY_S
            log(f'  episode {index}: t = {session.elapsed:5.1f} s simulated, ball moved '
                f'{session.monitor.moved:4.2f} m')


def _collect(result, session):
    monitor = session.monitor
    result.kicked = monitor.kicked
    if monitor.kicked:
        result.time_to_kick = round(monitor.kick_time - session.start_time, 3)
    result.fell = session.watch.fell
    result.distance_m = round(session.watch.distance, 3)
    result.sim_time = round(session.elapsed, 3)
    result.commands = session.commands


def grade(placements, options, jobs, stop, log=print):
    """EpisodeResults of the episodes run (all unless stop was requested), ``jobs`` at a
    time, each on a ROS domain of its own."""
    domains = queue.Queue()
    for domain in private_domains(jobs, salt=75):
        domains.put(domain)

    def work(index, placement):
        if stop.requested:
            return None
        domain = domains.get()
        try:
            log(f'  episode {index}/{len(placements)}: '
                f'{placement_text(placement.robot, placement.ball)}')
            return run_episode(index, placement, options, domain, stop, log)
        finally:
            domains.put(domain)

    results = []
    with ThreadPoolExecutor(jobs) as pool:
        futures = [pool.submit(work, index, placement)
                   for index, placement in enumerate(placements, 1)]
        for future in futures:
            result = future.result()
            if result is not None:
                results.append(result)
                mark = 'kicked in %.1f s' % result.time_to_kick if result.kicked else 'no kick'
                log(f'  episode {result.index}: {mark}, {result.ended} '
                    f'({result.wall_time:.0f} s wall)')
    return results
