"""Grading hosts as child processes (host.py), each in a network namespace of its own,
and a pool of them that runs a list of episodes, one episode per host at a time.

A host keeps its simulator from one episode to the next. When a host dies (the machine
killed it, a bug of ours), the episode it ran is tried once more on a fresh host; a
second loss is the episode's result ('the grading host died'), never the whole run's.
"""
import json
import os
import queue
import subprocess
import sys
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

from miro_ball.common.isolation import private_domain
from miro_ball.grading.netns import namespace_prefix

READY_S = 120.0  # wall s for a host's simulator to come up
HOST_LOST = 'the grading host died'
INTERRUPTED = 'interrupted'
ANSWER_POLL_S = 0.5  # how often a wait for a host looks at the grader's Ctrl+C


class HostLost(RuntimeError):
    """The host process ended or stopped answering; the message says how."""


class Interrupted(HostLost):
    """The grader was stopped (Ctrl+C) while the host ran an episode: it was killed."""


def _die_with_parent():
    """In the host before exec: SIGKILL when the thread that started it ends (the grader
    killed, a Ray worker lost): no host outlives its grader."""
    import ctypes
    import signal

    PR_SET_PDEATHSIG = 1
    ctypes.CDLL(None, use_errno=True).prctl(PR_SET_PDEATHSIG, signal.SIGKILL)


@dataclass(frozen=True)
class HostSettings:
    world: str  # a bundled name or a path
    robot: str
    renderer: str = 'auto'
    real_time_factor: float = 1.0
    sandboxed: bool = True


class HostProcess:
    """One host: started at once, its simulator up when this returns (HostLost if not)."""

    def __init__(self, settings, log_path, stop=None):
        prefix, _ = namespace_prefix()
        domain = 0 if prefix else private_domain(salt=83)
        argv = prefix + [sys.executable, '-m', 'miro_ball.grading.host',
                         '--world', settings.world, '--robot', settings.robot,
                         '--renderer', settings.renderer,
                         '--real-time-factor', str(settings.real_time_factor),
                         '--domain', str(domain),
                         '--sandbox', 'bwrap' if settings.sandboxed else 'none']
        if prefix:
            argv.append('--loopback')
        self.log = open(log_path, 'ab')
        env = dict(os.environ, PYTHONUNBUFFERED='1')
        self.stop = stop
        self.proc = subprocess.Popen(argv, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                     stderr=self.log, env=env, start_new_session=True,
                                     preexec_fn=_die_with_parent)
        self.answers = queue.Queue()
        threading.Thread(target=self._read, daemon=True).start()
        ready = self._answer(READY_S)
        if 'ready' not in ready:
            raise HostLost(f'the grading host did not start: {ready}')

    def _read(self):
        for line in self.proc.stdout:
            try:
                self.answers.put(json.loads(line))
            except ValueError:
                continue
        self.answers.put(None)

    def _answer(self, timeout_s):
        deadline = time.monotonic() + timeout_s
        answer = None
        while time.monotonic() < deadline:
            if self.stop is not None and self.stop.requested:
                self.proc.kill()  # its sandbox dies with it
                self.close()
                raise Interrupted(INTERRUPTED)
            try:
                answer = self.answers.get(timeout=ANSWER_POLL_S)
                break
            except queue.Empty:
                continue
        if answer is None:
            self.close()
            raise HostLost(f'{HOST_LOST} (exit code {self.proc.poll()}; see {self.log.name})')
        return answer

    def run(self, spec, timeout_s):
        """The result dict of one episode (host.py's request); HostLost if it died."""
        try:
            self.proc.stdin.write((json.dumps({'episode': spec}) + '\n').encode())
            self.proc.stdin.flush()
        except OSError:
            self.close()
            raise HostLost(f'{HOST_LOST} (see {self.log.name})') from None
        answer = self._answer(timeout_s)
        if 'error' in answer:
            raise HostLost(f'the grading host refused the episode: {answer["error"]}')
        return answer['result']

    def close(self):
        """Closing its stdin ends it; it is killed if it does not end in time."""
        if self.proc.poll() is None:
            try:
                self.proc.stdin.close()
                self.proc.wait(timeout=15)
            except (OSError, subprocess.TimeoutExpired):
                self.proc.kill()
                self.proc.wait()
        self.log.close()


def episode_timeout_s(spec, settings):
    """Wall s an episode may take in its host, start-up and stopping included."""
    rtf = settings.real_time_factor or 1.0
    return 60.0 + spec['command_wait_s'] + spec['grace_s'] + 4.0 * spec['limit_s'] / rtf


class LocalPool:
    """``workers`` hosts on this machine; ``run(specs, done, log_dir)`` calls done(spec,
    result) as each episode ends (from worker threads) and returns when all have; the
    hosts' logs go in log_dir."""

    def __init__(self, settings, workers, stop=None):
        self.settings, self.workers, self.stop = settings, workers, stop

    def run(self, specs, done, log_dir):
        todo = queue.Queue()
        for spec in specs:
            todo.put(spec)

        def take():
            try:
                return todo.get_nowait()
            except queue.Empty:
                return None

        def work(slot):
            # Each worker holds its next episode too, so that its host can start that
            # episode's command ahead (warm_start.py) while this one runs.
            host, spec = None, take()
            try:
                while spec is not None and not (self.stop and self.stop.requested):
                    upcoming = take()
                    result, host = run_on(host, dict(spec, next=upcoming), self.settings,
                                          log_dir / f'host_{slot}.log', self.stop)
                    if result['ended'] != INTERRUPTED:
                        done(spec, result)
                    spec = upcoming
            finally:
                if host is not None:
                    host.close()

        with ThreadPoolExecutor(self.workers) as pool:
            for future in [pool.submit(work, slot) for slot in range(self.workers)]:
                future.result()


def run_on(host, spec, settings, log_path, stop=None, tries=2):
    """(result, host): spec run on host (started if None); a lost host is replaced and
    the episode tried again, up to ``tries`` times in all; none after a Ctrl+C (stop)."""
    why = HOST_LOST
    for _ in range(tries):
        try:
            if host is None:
                host = HostProcess(settings, log_path, stop)
            return host.run(spec, episode_timeout_s(spec, settings)), host
        except Interrupted:
            return lost(INTERRUPTED), None
        except HostLost as err:
            host, why = None, str(err)
    return lost(why), None


def lost(why):
    """The result of an episode whose host died twice."""
    return {'ended': why, 'cheated': None, 'exit_code': None, 'killed': False,
            'commands': 0, 'kicked': False, 'time_to_kick': None, 'fell': False,
            'distance_m': 0.0, 'sim_time': 0.0, 'clock_wall_time': 0.0, 'wall_time': 0.0,
            'stages': {}, 'output_tail': [], 'log_bytes': 0, 'video': None}
