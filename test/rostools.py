"""Helpers for ROS tests: collect messages, spin until something holds, step the world."""
import inspect
import os
import signal
import subprocess
import time

import rclpy
from rclpy.executors import ShutdownException, TimeoutException

from miro_ball.miro.constants import PLATFORM_TICK_S

IDLE_LOOKS = 3  # drain: looks in a row that find nothing before it stops looking


def spin_until(executor, predicate, timeout_s=10.0, what=None):
    """Spin until predicate() holds, and say so (True); a wait that runs out fails the test
    (AssertionError naming ``what``), so no wait goes unchecked. The wall-clock limit only
    guards against a hang; poll() is for a wait whose answer may be no."""
    assert poll(executor, predicate, timeout_s), \
        f'timed out after {timeout_s:g} s waiting for {what or _source(predicate)}'
    return True


def poll(executor, predicate, timeout_s):
    """Spin until predicate() holds (True) or timeout_s have passed (False)."""
    deadline = time.monotonic() + timeout_s
    while not predicate():
        if time.monotonic() > deadline:
            return False
        executor.spin_once(timeout_sec=0.01)
    return True


def _source(predicate):
    try:
        return inspect.getsource(predicate).strip()
    except (OSError, TypeError):
        return repr(predicate)


def drain(executor, rounds=50, idle=IDLE_LOOKS):
    """Deliver what is already queued (no waiting beyond a few empty looks), between the
    ticks of a world a test steps: at most ``rounds`` callbacks, ending after ``idle`` looks
    in a row that found nothing. It says nothing of what arrived: a test that relies on a
    message's arrival waits for it with spin_until.

    Each look builds a wait set of every entity of every node (the simulator has dozens):
    30 empty spin_once() a tick were most of a stepped test's time, and kept a core busy
    while a child process was still starting."""
    empty = 0
    for _ in range(rounds):
        try:
            handler, _, _ = executor.wait_for_ready_callbacks(timeout_sec=0)
        except TimeoutException:
            empty += 1
            if empty >= idle:
                return
            continue
        except ShutdownException:
            return
        empty = 0
        handler()
        if handler.exception() is not None:
            raise handler.exception()


def advance_ticks(sim_node, executor, count=1, rounds=30):
    """Step an in-process simulator `count` platform ticks (20 ms), delivering what each
    tick publishes before the next (rounds: callbacks a tick, more for more subscribers)."""
    for _ in range(count):
        sim_node.advance(sim_node.sim.ticks_per_platform_tick)
        drain(executor, rounds=rounds)


PACE_RTF = 2.0  # advance_until's world runs at most this many times faster than the wall


def advance_until(sim_node, executor, predicate, timeout_s=60.0):
    """Step an in-process simulator tick by tick until predicate() holds (e.g. a child
    process has done its job); the wall-clock limit only guards against a hang.

    At most PACE_RTF times real time, the rest of each tick's share spent handling what
    arrives: a child that is still starting (seconds of discovery) needs no simulated
    time, and a world raced meanwhile kept a core busy that the suite's other tests need."""
    start = time.monotonic()
    deadline = start + timeout_s
    ticks = 0
    while not predicate():
        assert time.monotonic() < deadline, 'timed out'
        advance_ticks(sim_node, executor)
        ticks += 1
        due = start + ticks * PLATFORM_TICK_S / PACE_RTF
        while (ahead := due - time.monotonic()) > 0:
            executor.spin_once(timeout_sec=ahead)


def run_command(cmd, timeout_s=300):
    """(exit code, output) of a command run in a session of its own, so that a hang
    kills its child processes too."""
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                            start_new_session=True)
    try:
        output, _ = proc.communicate(timeout=timeout_s)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
    return proc.returncode, output


def kill_if_running(proc):
    """A test's last word on a child process: killed if it still runs, its pipes drained."""
    if proc.poll() is None:
        proc.kill()
        proc.communicate()


class Probe:
    """A node that records every message on the topics it is asked to watch."""

    def __init__(self, context, executor, name='probe'):
        self.node = rclpy.create_node(name, context=context)
        executor.add_node(self.node)
        self.messages = {}

    def watch(self, msg_type, topic, qos=1000):
        self.messages[topic] = []
        self.node.create_subscription(msg_type, topic, self.messages[topic].append, qos)
        return self.messages[topic]

    def publisher(self, msg_type, topic):
        return self.node.create_publisher(msg_type, topic, 10)

    def call(self, executor, srv_type, name, request):
        client = self.node.create_client(srv_type, name)
        assert client.wait_for_service(timeout_sec=5.0), f'no service {name}'
        future = client.call_async(request)
        executor.spin_until_future_complete(future, timeout_sec=10.0)
        return future.result()


def message_class_without(package):
    """common.messages.message_class as on a machine where the interface package ``package``
    (miro2_msg, tf2_msgs) was not built: its types are not there, every other one is."""
    from miro_ball.common.messages import message_class

    def without(type_name):
        if type_name.startswith(package + '/'):
            raise ValueError(f'no ROS message type {type_name!r}')
        return message_class(type_name)

    return without
