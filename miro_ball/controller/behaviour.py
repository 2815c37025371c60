"""Kick-the-ball behaviours as pure state machines (no rclpy).

Each tick the controller calls ``step(t, left, right, cliff, cameras)`` with the
time in seconds (monotonic), the latest fresh detection of each eye (a
detection.Ball or None), the latest fresh cliff reading ([left, right], 1 = floor,
or None when unknown) and each eye's camera model (camera_model.CameraModel) at the
size of the frame its detection came from. It gets back a Command: wheel speeds in m/s, the
state name and the messages to log for behaviour changes that happened during the
tick.

Both behaviours also implement the controller contract (contract.py): ``act(percepts)``
reads the "ball" detections, the cliff and the cameras from the Percepts and returns
an Action with the same wheel speeds; that is how the node runs them.
"""
import math
import random
from dataclasses import dataclass, field
from typing import NamedTuple, Optional, Sequence, Tuple

from miro_ball.common.ros_params import check_ranges
from miro_ball.controller.contract import Action, Percepts
from miro_ball.controller.detection import to_pixels
from miro_ball.miro.camera_model import CameraModel
from miro_ball.miro.constants import CAM_DIVERGENCE_RAD, CLIFF_THRESHOLD, WHEEL_MAX_SPEED_M_PER_S
from miro_ball.miro.interface import EYE_SIDE, EYES
from miro_ball.miro.kinematics import cmd_vel2wheel_speed, wheel_speed2cmd_vel

SEARCH, LOCK_ON, KICK = 'search', 'lock_on', 'kick'
APPROACH, EXPLORE, AVOID = 'approach', 'explore', 'avoid_cliff'

MESSAGES = {
    SEARCH: 'looking for the ball',
    LOCK_ON: 'locking on to the ball',
    APPROACH: 'ball seen, approaching it',
    KICK: 'kicking the ball',
    EXPLORE: 'nothing in a full turn, exploring',
    AVOID: 'edge ahead, backing away from it',
}
LOST = 'lost the ball'

# MiRo's simulated eyes (120 deg pinholes, the simulator's default frame size and lens):
# the model of both eyes until their camera_info says otherwise.
DEFAULT_CAMERA = CameraModel(640, 360)
DEFAULT_CAMERAS = (DEFAULT_CAMERA,) * len(EYES)


@dataclass(frozen=True)
class BehaviourParams:
    """Tutorial numbers first; the rest tune the improved mode."""

    slow: float = field(default=0.1, metadata={'help': 'wheel speed for turning on the spot, m/s',
                                               'range': (0.001, WHEEL_MAX_SPEED_M_PER_S)})
    fast: float = field(default=0.4, metadata={'help': 'wheel speed of the kick, m/s',
                                               'range': (0.001, WHEEL_MAX_SPEED_M_PER_S)})
    fine: float = field(default=0.03, metadata={'help': 'wheel speed of fine centring, m/s',
                                                'range': (0.001, WHEEL_MAX_SPEED_M_PER_S)})
    centre_error: float = field(
        default=0.05, metadata={'help': 'tutorial: centred when ||left x| - |right x|| <= this',
                                'range': (0.001, 1.0)})
    kick_duration: float = field(default=2.0, metadata={'help': 'length of a kick, s',
                                                        'range': (0.02, 60.0)})
    cliff_threshold: float = field(
        default=CLIFF_THRESHOLD, metadata={'help': 'improved: cliff reading below this = drop',
                                           'range': (0.0, 1.0)})
    seed: int = field(default=0, metadata={'help': 'improved: seed of the exploration RNG',
                                           'range': (0, 2147483647)})
    search_speed: float = field(
        default=0.25,
        metadata={'help': 'improved: wheel speed when turning to search or steer, m/s',
                  'range': (0.001, WHEEL_MAX_SPEED_M_PER_S)})
    approach_speed: float = field(
        default=0.4, metadata={'help': 'improved: forward speed while approaching, m/s',
                               'range': (0.001, WHEEL_MAX_SPEED_M_PER_S)})
    steer_gain: float = field(
        default=3.0, metadata={'help': 'improved: turn rate per rad of ball bearing, 1/s',
                               'range': (0.01, 100.0)})
    turn_only_deg: float = field(
        default=70.0, metadata={'help': 'improved: turn on the spot beyond this bearing, deg',
                                'range': (0.1, 180.0)})
    kick_bearing_deg: float = field(
        default=5.0, metadata={'help': 'improved: kick when the bearing is within this, deg',
                               'range': (0.1, 180.0)})
    kick_radius: float = field(
        default=0.05, metadata={'help': 'improved: kick when ball r / width reaches this',
                                'range': (0.001, 1.0)})
    lost_grace_s: float = field(
        default=0.3, metadata={'help': 'improved: hold course this long after losing the ball, s',
                               'range': (0.0, 60.0)})
    search_turn_deg: float = field(
        default=360.0, metadata={'help': 'improved: turn this far before exploring, deg',
                                 'range': (1.0, 3600.0)})
    explore_distance: float = field(
        default=0.3, metadata={'help': 'improved: longest exploratory drive, m',
                               'range': (0.01, 10.0)})
    backoff_s: float = field(
        default=1.0, metadata={'help': 'improved: reverse this long away from an edge, s',
                               'range': (0.02, 60.0)})

    def __post_init__(self):
        check_ranges(self)


class Command(NamedTuple):
    left: float  # wheel speeds, m/s
    right: float
    state: str
    messages: Tuple[str, ...] = ()


def eye_bearing(ball, camera: CameraModel, eye_azimuth):
    """Bearing (rad, + = left of the robot) of a detection in one eye.

    camera is the eye's model at the size of the frame the ball was found in: the
    ball's pixel gives the angle off the optical axis across the image (through the
    lens), and the eye's own azimuth (+27 deg left, -27 right) is added. The eyes'
    elevation and lateral offset are ignored: the error is a few degrees and the
    steering closes the loop anyway.
    """
    u, v, _ = to_pixels(ball, (camera.height, camera.width))
    return eye_azimuth + camera.bearing(u, v)


def ball_bearing(left, right, cameras: Sequence[CameraModel]) -> Optional[float]:
    """Mean bearing from the eyes that see the ball, or None if neither does.

    cameras: (left, right) camera models, each at the size of its eye's frame.
    """
    bearings = [eye_bearing(ball, camera, EYE_SIDE[eye] * CAM_DIVERGENCE_RAD)
                for eye, ball, camera in zip(EYES, (left, right), cameras) if ball is not None]
    return sum(bearings) / len(bearings) if bearings else None


def fit_to_limit(left, right, limit=WHEEL_MAX_SPEED_M_PER_S):
    """Scale both wheels down together so neither exceeds the limit (keeps the curve)."""
    top = max(abs(left), abs(right))
    if top <= limit:
        return left, right
    return left * limit / top, right * limit / top


def spin(direction, speed):
    """Wheel speeds to turn on the spot: direction +1 = counter-clockwise (left)."""
    return -direction * speed, direction * speed


class _Machine:
    """Shared bookkeeping: the state name and the messages of this tick."""

    # The tutorial sets the head pose before its loop starts: wheels still meanwhile.
    waits_for_head = True
    detectors = ('ball',)  # the contract: what the node runs on each eye's frames

    def __init__(self, params: BehaviourParams):
        self.params = params
        self.state = None
        self._said = []

    def act(self, percepts: Percepts) -> Action:
        """The contract: step() on the percepts' ball detections, cliff and cameras."""
        left, right = percepts.found('ball')
        command = self.step(percepts.t, left, right, percepts.cliff, percepts.cameras)
        return Action(wheels=(command.left, command.right), state=command.state,
                      messages=command.messages)

    def _go(self, state, *extra):
        self._said.extend(extra)
        self._said.append(MESSAGES[state])
        self.state = state

    def step(self, t, left, right, cliff=None, cameras=DEFAULT_CAMERAS) -> Command:
        self._said = []
        if self.state is None:
            self._go(SEARCH)
        wheels = self._decide(t, left, right, cliff, cameras)
        return Command(wheels[0], wheels[1], self.state, tuple(self._said))

    def _decide(self, t, left, right, cliff, cameras):
        raise NotImplementedError


class TutorialBehaviour(_Machine):
    """search -> lock_on -> kick as taught; blind to cliffs.

    Every tick yields a command: a state change takes effect in the same tick
    rather than skipping one, and the kick is timed in seconds, not loop counts.
    Like the tutorial it centres on raw image columns, so it needs no camera model.
    """

    def _decide(self, t, left, right, cliff, cameras):
        p = self.params
        if self.state == SEARCH:
            if left is None and right is None:
                return p.slow, -p.slow
            self._go(LOCK_ON)
        if self.state == LOCK_ON:
            wheels = self._lock_on(t, left, right)
            if wheels is not None:
                return wheels
        if self.state == KICK:
            if t - self._kick_start < p.kick_duration:
                return p.fast, p.fast
            self._go(SEARCH)
        return p.slow, -p.slow

    def _lock_on(self, t, left, right):
        """Turn to centre the ball; None once the state has moved on."""
        p = self.params
        if left is None and right is None:
            self._go(SEARCH, LOST)
            return None
        if left is None:
            return spin(-1, p.slow)
        if right is None:
            return spin(1, p.slow)
        error = abs(left.x) - abs(right.x)
        if error > p.centre_error:
            return spin(-1, p.fine)
        if error < -p.centre_error:
            return spin(1, p.fine)
        self._kick_start = t
        self._go(KICK)
        return None


class Manoeuvre:
    """Open-loop wheel-speed segments (left, right, seconds) played back to back."""

    def __init__(self, t, segments):
        self.segments = []  # (end time, left, right)
        for left, right, seconds in segments:
            t += seconds
            self.segments.append((t, left, right))

    def at(self, t):
        """(left, right) for time t, or None when the manoeuvre is over."""
        for end, left, right in self.segments:
            if t < end:
                return left, right
        return None


class ImprovedBehaviour(_Machine):
    """The tutorial's three exercises.

    1. The side the ball was last seen on sets the search direction.
    2. After a full fruitless turn, a random turn and short drive for a new view;
       never forward over an edge (a cliff reading is required to explore, and a
       drop seen while moving forward triggers back-off-and-turn-away).
    3. One approach that steers by the ball's bearing while driving, speeding up
       into the kick once the ball is centred and close.
    """

    waits_for_head = False  # the head starts in its pose anyway: search while it settles

    def __init__(self, params: BehaviourParams):
        super().__init__(params)
        self.rng = random.Random(params.seed)
        self.side = -1  # -1 right, +1 left; the tutorial's default search is clockwise
        self.turned = 0.0
        self._last_t = None
        self._manoeuvre = None
        self._kick_start = None
        self._seen = None  # (time, bearing) of the latest sighting
        self._spin_rate = wheel_speed2cmd_vel(spin(1, params.search_speed))[1]  # rad/s, > 0

    def _decide(self, t, left, right, cliff, cameras):
        dt = 0.0 if self._last_t is None else max(0.0, t - self._last_t)
        self._last_t = t
        bearing = ball_bearing(left, right, cameras)
        closest = max((b.r for b in (left, right) if b is not None), default=0.0)
        if bearing is not None:
            self.side = 1 if bearing > 0 else -1
            self._seen = (t, bearing)
        elif (self.state in (APPROACH, KICK) and self._seen is not None
              and t - self._seen[0] <= self.params.lost_grace_s):
            # One missed frame (the ball between the eyes' views, a bad JPEG) should not
            # end an approach: hold course on the last bearing for a moment.
            bearing = self._seen[1]
        wheels = self._by_state(t, dt, bearing, closest, cliff)
        drops = self._drops(cliff)
        if any(drops) and sum(wheels) > 0:
            wheels = self._avoid(t, drops)
        return fit_to_limit(*wheels)

    def _by_state(self, t, dt, bearing, closest, cliff):
        if self.state == AVOID:  # the ball waits until we are clear of the edge
            wheels = self._manoeuvre.at(t)
            if wheels is not None:
                return wheels
            self._start_search()
        if self.state == KICK:
            if t - self._kick_start < self.params.kick_duration:
                return self._kick(bearing)
            self._start_search()
        if self.state in (SEARCH, EXPLORE) and bearing is not None:
            self._go(APPROACH)
        if self.state == APPROACH:
            if bearing is None:
                self._start_search(LOST)
            elif (closest >= self.params.kick_radius
                  and abs(bearing) <= math.radians(self.params.kick_bearing_deg)):
                self._kick_start = t
                self._go(KICK)
                return self._kick(bearing)
            else:
                return self._steer(self.params.approach_speed, bearing, taper=True)
        if self.state == EXPLORE:
            wheels = self._manoeuvre.at(t)
            if wheels is not None and sum(wheels) > 0 and cliff is None:
                wheels = None  # no cliff reading: never drive blind
            if wheels is not None:
                return wheels
            self._start_search()
        return self._search(t, dt)

    def _kick(self, bearing):
        """Full speed, still steering while the ball is in view."""
        return self._steer(self.params.fast, 0.0 if bearing is None else bearing, taper=False)

    def _search(self, t, dt):
        self.turned += self._spin_rate * dt
        if self.turned >= math.radians(self.params.search_turn_deg):
            return self._explore(t)
        return spin(self.side, self.params.search_speed)

    def _start_search(self, *extra):
        self.turned = 0.0
        self._go(SEARCH, *extra)

    def _steer(self, speed, bearing, taper):
        """Drive at speed while turning towards the bearing.

        With taper, forward speed falls to zero as the bearing grows to
        turn_only_deg, so a ball far to the side is faced before it is chased.
        """
        p = self.params
        rate = max(-self._spin_rate, min(self._spin_rate, p.steer_gain * bearing))
        if taper:
            speed *= max(0.0, 1.0 - abs(bearing) / math.radians(p.turn_only_deg))
        return cmd_vel2wheel_speed(speed, rate)

    def _turn_for(self, direction, angle):
        """A spin segment turning `angle` rad towards direction at the search speed."""
        return spin(direction, self.params.search_speed) + (angle / self._spin_rate,)

    def _explore(self, t):
        p = self.params
        turn = self._turn_for(self.rng.choice((-1, 1)), self.rng.uniform(math.pi / 4, math.pi))
        distance = self.rng.uniform(0.5, 1.0) * p.explore_distance
        drive = (p.approach_speed, p.approach_speed, distance / p.approach_speed)
        self._manoeuvre = Manoeuvre(t, [turn, drive])
        self._go(EXPLORE)
        return self._manoeuvre.at(t)

    def _avoid(self, t, drops):
        """Back off, then turn away from the side that saw the drop."""
        p = self.params
        if drops[0] and drops[1]:
            away = self.rng.choice((-1, 1))
        else:
            away = -1 if drops[0] else 1
        back = (-p.slow, -p.slow, p.backoff_s)
        turn = self._turn_for(away, self.rng.uniform(math.pi / 2, math.pi))
        self._manoeuvre = Manoeuvre(t, [back, turn])
        self._go(AVOID)
        return self._manoeuvre.at(t)

    def _drops(self, cliff: Optional[Sequence[float]]):
        if cliff is None:
            return (False, False)
        return tuple(v < self.params.cliff_threshold for v in cliff)


MODES = {'tutorial': TutorialBehaviour, 'improved': ImprovedBehaviour}


def make_behaviour(mode: str, params: BehaviourParams):
    if mode not in MODES:
        raise ValueError("mode must be one of %s, not '%s'" % (', '.join(MODES), mode))
    return MODES[mode](params)
