"""python -m miro_ball.grading.host: runs graded episodes one after another for a grader.

The grader starts one host per worker, in a network namespace of its own (netns.py), and
sends it one JSON request per line on stdin; the host answers each with one JSON line
on stdout (its log lines go to stderr). It keeps one simulator for all its episodes and
resets it between them: the same world, placement and commands give the same episode as
a fresh simulator (test_grade_host).

The simulator is unprivileged (SimNode(privileged=False)): on the ROS graph it is MiRo's
interface and /clock, nothing else. The host places robot and ball, runs and pauses the
clock and has the episode judged in-process, after every physics step, from the world
itself (by the one judge, run/judge.py, fed as the lab run's is over ROS). The command under
test runs in its sandbox (sandbox.py) beside it and is watched on the graph (watch.py): a
breach of MiRo's interface ends the episode as cheated.

A request: {"episode": {index, command, workdir, robot: [x, y, yaw], ball: [x, y],
limit_s, grace_s, command_wait_s, out (a folder for command.log and video.mp4), video,
hidden (folders the command must not see), settle_s}}. The answer: {"result": {...}}, the
episode's facts (grading/episode_facts.py completes them for the report), or
{"error": "..."}.
Stdin closing ends the host; so does the grader's end (its pipe closes).
"""
import argparse
import json
import os
import shutil
import sys
import tempfile
import time
from pathlib import Path

from miro_ball.grading import dds_profiles, sandbox
from miro_ball.grading.command import Command
from miro_ball.grading.warm_start import python_args
from miro_ball.grading.watch import GraphWatch, verdict
from miro_ball.miro.interface import RobotTopics
from miro_ball.miro.rotations import yaw_quaternion
from miro_ball.run.judge import Judge, observe, SETTLE_S

SCRATCH = 'scratch'  # a command's $HOME, in the host's folder: made anew for each command
WARM_START = 'miro_ball.grading.warm_start'
WATCH_EVERY_S = 0.25  # wall: how often the graph is looked at while the clock runs
SPIN_S = 0.02
# Against a hang only: an episode may run at a quarter of its real-time factor (or of real
# time, free-running), after GUARD_START_S.
WALL_GUARD_SLOWEST = 0.25
GUARD_START_S = 10.0


def parse_args(argv):
    p = argparse.ArgumentParser(prog='python -m miro_ball.grading.host',
                                description='Runs graded episodes for the grader (not for '
                                            'use by hand): JSON lines in, JSON lines out.')
    p.add_argument('--world', required=True)
    p.add_argument('--robot', required=True)
    p.add_argument('--renderer', default='auto')
    p.add_argument('--real-time-factor', type=float, default=1.0)
    p.add_argument('--domain', type=int, default=0)
    p.add_argument('--sandbox', choices=('bwrap', 'none'), default='bwrap')
    p.add_argument('--loopback', action='store_true',
                   help='bring up the loopback first (a fresh network namespace)')
    return p.parse_args(argv)


def place(sim, name, robot, ball):
    """Robot ``name`` at robot (x, y, yaw) on its floor, the ball at rest at ball (x, y)."""
    x, y, yaw = robot
    sim.set_object_pose(name, (x, y, sim.description.robots[0].floor),
                        yaw_quaternion(yaw))
    sim.place_ball(*ball)


def _key(spec):
    """What makes two requests the same episode (a prepared command is only used for its
    own)."""
    return json.dumps([spec.get(k) for k in ('student', 'index', 'command', 'workdir',
                                             'hidden', 'out')])


class Laps:
    """Wall seconds of an episode's stages: call it with a stage's name as the stage ends."""

    def __init__(self):
        self.started = self.last = time.monotonic()
        self.laps = {}

    def __call__(self, name):
        now = time.monotonic()
        self.laps[name] = now - self.last
        self.last = now

    @property
    def total(self):
        return self.last - self.started


class Host:
    """The simulator and its judge for one episode after another; scratch_root: a folder
    of its own (each command's scratch folder goes in it)."""

    def __init__(self, args, scratch_root):
        import rclpy
        from rclpy.context import Context
        from rclpy.parameter import Parameter

        from miro_sim_bullet.render.overhead import overhead_camera
        from miro_sim_bullet.ros.node import make_executor, SimNode

        self.args = args
        self.context = Context()
        rclpy.init(context=self.context, domain_id=args.domain)
        self.node = SimNode(context=self.context, robot=args.robot, privileged=False,
                            parameter_overrides=[
                                Parameter('world', value=args.world),
                                Parameter('renderer', value=args.renderer),
                                Parameter('real_time_factor', value=args.real_time_factor),
                                Parameter('paused', value=True)])
        self.executor = make_executor(self.context)
        self.executor.add_node(self.node)
        self.watch = GraphWatch(self.node)
        self.overhead = overhead_camera(self.node.sim.description)
        self.uid = sandbox.sandbox_uid() if args.sandbox == 'bwrap' else None
        self.bwrap = sandbox.bwrap() if args.sandbox == 'bwrap' else None
        self.scratch_root = scratch_root
        self.node.step_observers.append(self._observe)
        self.judge = self.video = None
        self.cheats = []  # of the episode running
        self.warm = None  # (its spec's key, Command, scratch): the next episode's, waiting
        self.scratch = None  # the running command's scratch folder
        self.launched = 0

    def close(self):
        if self.warm is not None:
            self.warm[1].stop(0.0)
        self.executor.shutdown(timeout_sec=1.0)
        self.node.destroy_node()
        self.context.try_shutdown()
        shutil.rmtree(self.scratch_root, ignore_errors=True)

    # -- the world, each physics step -----------------------------------------------------
    def _observe(self, sim):
        judge = self.judge
        if judge is None:
            return
        observe(judge, sim, self.args.robot)
        if self.video is not None and sim.time >= self.next_frame:
            from miro_ball.run.video import VIDEO_FPS

            rgb = self.node.cameras.render_view(*self.overhead)
            self.video.overhead(rgb[:, :, ::-1], judge.elapsed,
                                'KICKED' if judge.kicked else '')
            self.next_frame += 1.0 / VIDEO_FPS

    def _spin_until(self, predicate, timeout_s):
        deadline = time.monotonic() + timeout_s
        while not predicate() and time.monotonic() < deadline:
            self.executor.spin_once(timeout_sec=SPIN_S)
        return predicate()

    # -- one episode ----------------------------------------------------------------------
    def run(self, spec):
        from geometry_msgs.msg import TwistStamped

        from miro_ball.run.video import Video

        lap = Laps()
        self.cheats = []
        out = Path(spec['out'])
        out.mkdir(parents=True, exist_ok=True)
        node, sim = self.node, self.node.sim
        node.pause(True)
        node.reset(0)  # the whole world as loaded (ResetSimulation.SCOPE_DEFAULT)
        place(sim, self.args.robot, spec['robot'], spec['ball'])
        node.advance(1)  # the placed world's first readings go out before anyone listens
        self.judge = None  # until the clock starts
        self.video = Video(out / 'video.mp4', []) if spec.get('video') else None
        self.next_frame = sim.time
        result = dict(ended='', cheated=None, exit_code=None, killed=False, commands=0)

        def count(_):
            result['commands'] += 1
        # raw: a flooding command costs no deserialising
        counted = node.create_subscription(TwistStamped, RobotTopics(self.args.robot).cmd_vel,
                                           count, 10, raw=True)
        self.watch.mark_own()
        lap('reset and place')
        command = self._start(spec)
        try:
            self._spin_until(lambda: command.exited() is not None
                             or counted.get_publisher_count() > 0, spec['command_wait_s'])
            lap('command start')
            self.judge = judge = Judge(sim.time)
            node.pause(False)
            self._prepare(spec.get('next'))
            result['ended'] = self._run_clock(spec, command)
        finally:
            node.pause(True)
            lap('clock')
            # Before it stops: what it did on the graph is still there to see.
            self.cheats = self.cheats or verdict(self.watch, self.args.robot)
            if result['ended'] == 'command exited':
                result['exit_code'] = command.exited()
            result['killed'] = command.stop(spec['grace_s'])
            node.destroy_subscription(counted)
            shutil.rmtree(self.scratch, ignore_errors=True)
            if self.video is not None:
                self.video.close()
            lap('stop')
        result.update(
            cheated='; '.join(self.cheats) or None,
            kicked=judge.kicked, time_to_kick=None if not judge.kicked
            else round(judge.kick_time, 3), fell=judge.fell,
            distance_m=round(judge.distance, 3), sim_time=round(judge.elapsed, 3),
            clock_wall_time=round(lap.laps['clock'], 3), wall_time=round(lap.total, 3),
            stages={name: round(seconds, 3) for name, seconds in lap.laps.items()},
            output_tail=command.output_tail(), log_bytes=command.total,
            video='video.mp4' if self.video is not None and self.video.frames else None)
        if result['cheated']:
            result['ended'] = 'cheated'
        return result

    def _start(self, spec):
        """The episode's command, running: the one prepared for it if there is one."""
        warm, self.warm = self.warm, None
        if warm is not None and warm[0] == _key(spec):
            _, command, self.scratch = warm
            command.go()
            return command
        if warm is not None:
            warm[1].stop(0.0)
            shutil.rmtree(warm[2], ignore_errors=True)
        command, self.scratch = self._launch(spec, spec['command'])
        return command

    def _prepare(self, spec):
        """Start the sandbox of the next episode's Python command, waiting (warm_start.py)."""
        if spec is None or python_args(spec['command']) is None:
            return
        Path(spec['out']).mkdir(parents=True, exist_ok=True)
        command, scratch = self._launch(spec, [sys.executable, '-m', WARM_START, '--',
                                               *spec['command']], waits=True)
        self.warm = (_key(spec), command, scratch)

    def _launch(self, spec, argv, waits=False):
        """(Command, its scratch folder): argv in spec's sandbox, its output in spec's log."""
        self.launched += 1
        scratch = self.scratch_root / f'{SCRATCH}_{self.launched}'
        scratch.mkdir()
        env = dict(sandbox.environment(scratch, self.args.domain, self.args.robot),
                   **dds_profiles.write_profile(scratch))
        log = Path(spec['out']) / 'command.log'
        if self.bwrap is None:
            return Command(argv, env=dict(os.environ, **env), cwd=spec['workdir'],
                           log_path=log, sandboxed=False, waits=waits), scratch
        if self.uid is not None:
            os.chown(scratch, self.uid, self.uid)
        argv = sandbox.command_line(argv, workdir=spec['workdir'], scratch=scratch, env=env,
                                    uid=self.uid, hidden=spec.get('hidden', ()),
                                    bwrap_path=self.bwrap)
        return Command(argv, env={}, cwd='/', log_path=log, sandboxed=True, waits=waits,
                       preexec_fn=lambda: sandbox.limit_resources(self.uid is not None)), \
            scratch

    def _run_clock(self, spec, command):
        limit_s, settle_s = spec['limit_s'], spec.get('settle_s', SETTLE_S)
        rtf = self.args.real_time_factor
        guard_s = GUARD_START_S + limit_s / ((rtf or 1.0) * WALL_GUARD_SLOWEST)
        guard = time.monotonic() + guard_s
        next_watch = time.monotonic() + WATCH_EVERY_S
        while True:
            self.executor.spin_once(timeout_sec=SPIN_S)
            ended = self.judge.over(limit_s, settle_s)
            if ended:
                return ended
            if command.exited() is not None:
                return 'command exited'
            now = time.monotonic()
            if now >= next_watch:
                next_watch = now + WATCH_EVERY_S
                self.cheats = verdict(self.watch, self.args.robot)
                if self.cheats:
                    return 'cheated'
            if now > guard:
                return (f'the simulator was too slow: {self.judge.elapsed:.1f} s simulated '
                        f'in {guard_s:.0f} s')


def main(argv=None):
    args = parse_args(sys.argv[1:] if argv is None else argv)
    if args.loopback:
        from miro_ball.grading.netns import loopback_up

        loopback_up()
    scratch_root = Path(tempfile.mkdtemp(prefix='miro_grade_host_'))
    dds_profiles.use_in_this_process(scratch_root)
    host = Host(args, scratch_root)
    out = sys.stdout
    print(json.dumps({'ready': {'pid': os.getpid(), 'uid': host.uid}}), file=out, flush=True)
    try:
        for line in sys.stdin:
            try:
                spec = json.loads(line)['episode']
                answer = {'result': host.run(spec)}
            except (KeyError, TypeError, ValueError, OSError) as err:
                answer = {'error': f'{type(err).__name__}: {err}'}
            print(json.dumps(answer), file=out, flush=True)
    finally:
        host.close()


if __name__ == '__main__':
    main()
