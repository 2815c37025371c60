"""Running a node until Ctrl+C or SIGTERM, whatever the ROS graph is doing.

Python runs a signal handler only between bytecodes. A plain ``executor.spin()``
sits inside rcl's wait for as long as nothing arrives (no /clock, a paused
simulator), so the handler never ran; and when it did run inside rclpy's C++
``take_message``, its KeyboardInterrupt came out as pybind11's RuntimeError
"Unable to convert call argument". So the handlers here only note the signal,
and the spin wakes at least every WAKE_PERIOD_S to look at that note.
"""
import signal

from rclpy.executors import ExternalShutdownException

WAKE_PERIOD_S = 0.1
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

    @property
    def requested(self):
        return self.signum is not None


def spin_until_stopped(executor, stop, context=None):
    """Spin until a stop signal, or until the context is shut down from elsewhere."""
    context = context or executor.context
    try:
        while not stop.requested and context.ok():
            executor.spin_once(timeout_sec=WAKE_PERIOD_S)
    except ExternalShutdownException:
        pass
