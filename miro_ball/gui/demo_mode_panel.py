"""The GUI and demo mode: demo mode's topics made into what a page draws (checked: anything
on the graph can be garbage), and demo mode started and stopped for a robot.
"""
import base64
import collections
import math
import subprocess
import sys
import threading
import time

from miro_ball.animal.actions import ACTIONS

MAX_VIEW_PIXELS = 64 * 36 * 4  # an attention view larger than this is not passed on
STOP_TIMEOUT_S = 5.0


def _finite(*values):
    if not all(isinstance(v, float) and math.isfinite(v) for v in values):
        raise ValueError(f'not finite: {values}')
    return [round(v, 3) for v in values]


def animal_state(msg):
    """core/animal/state -> {emotion, mood: [valence, arousal], sleep: [wakefulness, pressure]}."""
    e, m, s = msg.emotion, msg.mood, msg.sleep
    return {'emotion': _finite(e.valence, e.arousal), 'mood': _finite(m.valence, m.arousal),
            'sleep': _finite(s.wakefulness, s.pressure)}


def priorities(msg):
    """core/selection/priority -> one priority per action, in ACTIONS order."""
    values = [float(v) for v in msg.data]
    if len(values) != len(ACTIONS):
        raise ValueError(f'{len(values)} priorities for {len(ACTIONS)} actions')
    return _finite(*values)


def action(msg):
    if msg.data not in ACTIONS + ('',):
        raise ValueError(f'no action {msg.data[:40]!r}')
    return msg.data


def objects(msg):
    """core/detect_objects_<eye> -> [{kind, x, y (of the image's width and height, 0..1 from
    the top left), and a ball's r (of the width), a face's w and h}], 20 at most."""
    found = [{'kind': 'ball', 'x': b.centre[0], 'y': b.centre[1], 'r': b.radius}
             for b in msg.balls]
    found += [{'kind': 'face', 'x': f.corner[0], 'y': f.corner[1], 'w': f.size[0],
               'h': f.size[1]} for f in msg.faces]
    found += [{'kind': f'tag {t.id}', 'x': t.centre[0], 'y': t.centre[1]} for t in msg.tags]
    return [{key: value if key == 'kind' else _finite(float(value))[0]
             for key, value in thing.items()} for thing in found[:20]]


def attention_view(msg):
    """core/attention_<eye> (mono8) -> {w, h, data: base64 of its bytes}."""
    if msg.encoding != 'mono8' or msg.width * msg.height > MAX_VIEW_PIXELS \
            or len(msg.data) != msg.width * msg.height or msg.step != msg.width:
        raise ValueError(f'an attention view must be mono8 of at most {MAX_VIEW_PIXELS} '
                         f'pixels, got {msg.encoding} {msg.width}x{msg.height}')
    return {'w': msg.width, 'h': msg.height, 'data': base64.b64encode(bytes(msg.data)).decode()}


# The page's demo readout: (row key, convert, its key there).
READ = [('animal_state', animal_state, 'state'), ('selection_priority', priorities,
                                                   'priorities'),
        ('selection_action', action, 'action')]
# What is drawn over each eye, each with the frame it goes with (pairing.py): (row key of an
# {eye} row, convert, its key in the overlay).
OVERLAY = (('detect_objects', objects, 'objects'), ('attention_view', attention_view, 'view'))


class DemoModeRunner:
    """Demo mode (python -m miro_ball.animal) run for robots, one process each, its last
    lines of output kept for the page's status."""

    def __init__(self, env=None):
        self.env = env
        self.procs = {}  # robot: (Popen, deque of its output)

    def running(self):
        """The robots whose demo mode runs (a process that ended is forgotten)."""
        return sorted(name for name, (proc, _) in self.procs.items() if proc.poll() is None)

    def start(self, robot):
        """Start demo mode for robot (once); None, or why it did not start."""
        if robot in self.running():
            return None
        output = collections.deque(maxlen=20)
        try:
            proc = subprocess.Popen([sys.executable, '-m', 'miro_ball.animal', '--robot', robot],
                                    env=self.env, stdout=subprocess.PIPE,
                                    stderr=subprocess.STDOUT, text=True)
        except OSError as err:
            return f'demo mode did not start: {err}'
        threading.Thread(target=lambda: output.extend(proc.stdout), daemon=True).start()
        self.procs[robot] = (proc, output)
        return None

    def stop(self, robot):
        self._stop([robot])

    def stop_all(self):
        self._stop(list(self.procs))

    def _stop(self, robots):
        """Told all at once, they stop side by side: the slowest sets the time, not the sum."""
        procs = [self.procs.pop(robot)[0] for robot in robots if robot in self.procs]
        for proc in procs:
            if proc.poll() is None:
                proc.terminate()  # as Ctrl+C: it stops the wheels on its way out
        deadline = time.monotonic() + STOP_TIMEOUT_S
        for proc in procs:
            try:
                proc.wait(timeout=max(0.0, deadline - time.monotonic()))
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()

    def reap(self):
        """[(robot, its last line)] of the demo modes that ended by themselves (forgotten
        now): a page should hear why."""
        ended = [(name, output[-1].strip() if output else '')
                 for name, (proc, output) in self.procs.items() if proc.poll() is not None]
        for name, _ in ended:
            del self.procs[name]
        return ended
