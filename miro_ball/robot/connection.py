"""The ROS side of a Robot: a node of its own, spun in the background, on simulated time.

A script's main thread calls Robot's methods and may block in them (``sleep``,
``drive_to``); meanwhile a daemon thread spins the node, so messages keep arriving. The
node lives on an rclpy Context of its own (so a script may have other ROS code, or two
robots) in the robot's namespace, and leaves Ctrl+C to the script (a KeyboardInterrupt in
the main thread, as in any Python program).
"""
import os
import threading
import time

import rclpy
from rclpy.context import Context
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
from rclpy.node import Node
from rclpy.signals import SignalHandlerOptions

from miro_ball.common.clock_guard import guard_clock
from miro_ball.common.sim_time import sim_time_overrides
from miro_ball.common.qos import profile
from miro_ball.common.throttle import Throttled
from miro_ball.miro.interface import CONTROL_QOS

SPIN_PERIOD_S = 0.1  # the background thread looks at whether to stop this often
WAIT_PERIOD_S = 0.1  # a waiting main thread wakes this often (so Ctrl+C gets through)
STALL_NOTICE_S = 5.0  # wall seconds without /clock before a wait says what it waits for


class Connection:
    """A node ``node_name`` in /``robot``, on simulated time, spun by a daemon thread.

    ``changed()`` wakes whoever waits in ``wait_until``; callbacks call it when they have
    stored something new.
    """

    def __init__(self, robot, node_name):
        self.robot = robot
        self.context = Context()
        rclpy.init(context=self.context, signal_handler_options=SignalHandlerOptions.NO)
        self.node = Node(node_name, context=self.context, namespace='/' + robot,
                         parameter_overrides=sim_time_overrides())
        self.warn = Throttled(self.node.get_logger().warning)
        guard_clock(self.node, self.warn)
        self._changed = threading.Condition()
        self._failure = None
        self._closing = threading.Event()
        self._executor = SingleThreadedExecutor(context=self.context)
        self._executor.add_node(self.node)
        self._thread = threading.Thread(target=self._spin, name=f'{robot} ROS', daemon=True)
        self._thread.start()

    @property
    def domain(self):
        return self.context.get_domain_id()

    def now(self):
        """Simulated seconds (0 until the first /clock)."""
        return self.node.get_clock().now().nanoseconds * 1e-9

    def stopwatch(self):
        """A function giving the simulated seconds since now; time that goes back (the
        world was reset) counts from where it went back to."""
        last, elapsed = self.now(), 0.0

        def elapsed_s():
            nonlocal last, elapsed
            now = self.now()
            elapsed += max(0.0, now - last)
            last = now
            return elapsed
        return elapsed_s

    def subscribe(self, msg_type, topic, qos, callback):
        """A subscription whose messages go to ``callback`` and then wake the waiters."""
        def arrived(msg):
            callback(msg)
            self.changed()
        return self.node.create_subscription(msg_type, topic, arrived, profile(qos))

    def publisher(self, msg_type, topic, qos=CONTROL_QOS):
        return self.node.create_publisher(msg_type, topic, profile(qos))

    def changed(self):
        with self._changed:
            self._changed.notify_all()

    def wait_until(self, done, what, wall_timeout=None):
        """Block until ``done()`` holds. With ``wall_timeout`` (s) give up after it: False.
        Without, wait as long as it takes, saying once (after a few seconds without /clock)
        that the simulator seems paused or stopped."""
        started = last_tick = time.monotonic()
        clock = self.now()
        said = False
        with self._changed:
            while not done():
                if self._failure is not None:
                    raise RuntimeError(f'the ROS thread of robot {self.robot!r} failed: '
                                       f'{self._failure!r}') from self._failure
                now = time.monotonic()
                if wall_timeout is not None and now - started > wall_timeout:
                    return False
                if self.now() != clock:
                    clock, last_tick = self.now(), now
                elif not said and now - last_tick > STALL_NOTICE_S:
                    said = True
                    self.node.get_logger().warning(
                        f'waiting for {what}: no /clock for {STALL_NOTICE_S:g} s on ROS domain '
                        f'{self.domain} (is the simulator paused, or stopped?)')
                self._changed.wait(WAIT_PERIOD_S)
        return True

    def _spin(self):
        try:
            while not self._closing.is_set() and self.context.ok():
                self._executor.spin_once(timeout_sec=SPIN_PERIOD_S)
        except ExternalShutdownException:
            pass
        except Exception as err:  # a bug in a callback: the main thread raises it
            self._failure = err
            self.changed()

    def close(self):
        """Stop the thread and leave ROS (the robot's last commands must be sent before)."""
        if self._closing.is_set():
            return
        self._closing.set()
        if self._thread is not threading.current_thread():
            self._thread.join()
        self._executor.shutdown()
        self.node.destroy_node()
        rclpy.try_shutdown(context=self.context)


def node_name():
    """A node name of its own for each script (two scripts may drive one robot)."""
    return f'robot_script_{os.getpid()}'
