"""The wheel command a script holds: MiRo's platform stops the wheels when no command came
for half a second, so drive() is re-sent every tick until stop().

The re-send runs on the ROS executor's thread and stop() on the script's. Unlocked, a re-send
could read the old command, lose the race to stop(), and send it after the stop: MiRo then
holds it for half a second (a turn that had stopped at its goal heading turned on by about
6 degrees, seen in CI). Both go through one lock, so the last command sent is the last one set.
"""
import threading


class HeldCommand:
    """``send(forward, turn)`` publishes; ``hold``, ``release`` and ``repeat`` call it."""

    def __init__(self, send):
        self._send = send
        self._command = None  # (forward, turn) while held
        self._lock = threading.Lock()

    def hold(self, forward, turn):
        """Send (forward, turn) now and on every repeat() until release()."""
        with self._lock:
            self._command = (forward, turn)
            self._send(forward, turn)

    def release(self):
        """Send a stop; repeat() sends nothing more."""
        with self._lock:
            self._command = None
            self._send(0.0, 0.0)

    def repeat(self):
        """Send the held command again, if any (each platform tick)."""
        with self._lock:
            if self._command is not None:
                self._send(*self._command)
