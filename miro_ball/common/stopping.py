"""Running a node until Ctrl+C or SIGTERM, whatever the ROS graph is doing.

Python runs a signal handler only between bytecodes. A plain ``executor.spin()``
sits inside rcl's wait for as long as nothing arrives (no /clock, a paused
simulator), so the handler never ran; and when it did run inside rclpy's C++
``take_message``, its KeyboardInterrupt came out as pybind11's RuntimeError
"Unable to convert call argument". So the handlers here only note the signal,
and the spin wakes at least every WAKE_PERIOD_S to look at that note.
"""
import signal
import traceback

from rclpy.exceptions import InvalidHandle
from rclpy.executors import ExternalShutdownException

from miro_ball.common.throttle import Throttled

WAKE_PERIOD_S = 0.1
FAULT_PERIOD_S = 10.0
FAULT_CHARS = 4000  # a traceback is worth its lines, but not a megabyte of repr
# What no node can go on from: its memory, or its handles into ROS, are gone.
FATAL = (MemoryError, InvalidHandle)
STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM)


class StopRequest:
    """Notes SIGINT and SIGTERM instead of raising; a second Ctrl+C is noted again, quietly.

    The handlers stay for the rest of the process, so a signal during clean-up
    can not interrupt the clean-up with a traceback.
    """

    def __init__(self):
        self.signum = None
        for signum in STOP_SIGNALS:
            signal.signal(signum, self._note)

    def _note(self, signum, frame):
        self.signum = signum

    def request(self):
        """Stop as if signalled: the program itself is ending (its server failed)."""
        self.signum = self.signum or 0

    @property
    def requested(self):
        return self.signum is not None


def spin_until_stopped(executor, stop, context=None, fatal=()):
    """Spin until a stop signal, or until the context is shut down from elsewhere.

    A callback that raises costs its own message, not the node: its traceback is logged
    once for each place it comes from (then counted, at most a line every FAULT_PERIOD_S)
    and the node serves on. What the node can not go on from (no memory, its ROS handles
    gone, and the caller's ``fatal`` exception classes) ends the spin with its traceback.
    """
    context = context or executor.context
    faults = None
    while True:
        try:
            while not stop.requested and context.ok():
                executor.spin_once(timeout_sec=WAKE_PERIOD_S)
            return
        except ExternalShutdownException:
            return
        except FATAL + tuple(fatal):
            raise
        except Exception as err:  # noqa: BLE001 -- a bug in one callback must not end the node
            faults = faults or _fault_log(executor)
            faults(err)


def _fault_log(executor):
    nodes = executor.get_nodes()
    log = nodes[0].get_logger().error if nodes else print
    throttled = Throttled(log, period_s=FAULT_PERIOD_S, max_chars=FAULT_CHARS)

    def fault(err):
        where = traceback.extract_tb(err.__traceback__)[-1:]
        key = (type(err), *((where[0].filename, where[0].lineno) if where else ()))
        throttled(key, 'a callback failed; its message is dropped and the node goes on:\n'
                  + ''.join(traceback.format_exception(err)).rstrip(), cause=key)
    return fault
