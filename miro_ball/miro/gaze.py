"""Point an eye at a point: the head joints that put it on an eye's optical axis.

Pure numpy, on the kinematic chain (``miro.kc``)::

    from miro_ball.miro.gaze import look_at
    gaze = look_at(kc, (0.8, 0.2, 0.1))     # a point in FOOT; frame=WORLD with kc.set_pose
    gaze.joints                              # (tilt, lift, yaw, pitch) to send, within limits
    gaze.reachable, gaze.error_deg, gaze.reason

MiRo's eyes look 45 degrees up and 27 degrees out of its head, and the head moves in a
small box of joint angles (lift 8..60, yaw -55..55, pitch -22..8 degrees), so an eye can
look at most ~20 degrees below the horizon: a ball on the floor closer than half a metre
or so is out of its reach. ``look_at`` then turns the eye as close as it can and says why
the rest is missing.

How: damped least squares from the joints the chain has now (the smallest movement that
gets there), on the target's bearing and elevation seen from the eye, with a numeric
Jacobian over lift, yaw and pitch; a joint at a limit that the step pushes further is held
there and the others do the work. When that ends short of the target (a joint limit can
stop the descent in a corner, or a near target moves a lot as the eye moves), a second
descent starts from a first guess worked out in closed form, and the closer of the two wins.
"""
import math
from dataclasses import dataclass

import numpy as np

from miro_ball.miro.constants import JOINT_LIMITS_RAD
from miro_ball.miro.kc import CAML, CAMR, clamp_joints, EYE_SIDE, FOOT, FRAME_NAMES, HEAD, \
    KinematicChain, NECK, rot_y
from miro_ball.miro.kinematics import wrap

REACH_TOLERANCE_RAD = math.radians(2.0)  # reachable: the target this close to the axis
# Nearer than this to the eye, an unreachable target is "too close": MiRo's own feet and
# the floor under its nose are.
TOO_CLOSE_M = 0.3
# Within this the solver stops: well under a pixel of the eye's ~0.2 deg.
CONVERGED_RAD = math.radians(0.01)
ON_AXIS_RAD = math.radians(0.1)  # a search that ends nearer than this has found the target
MAX_ITERATIONS = 40
DAMPING = 0.05  # rad: keeps steps finite where the target can not be reached
MAX_STEP_RAD = 0.5  # no joint moves more than this in one iteration
JACOBIAN_DELTA_RAD = 1e-5
GUESS_LIFTS = 5  # lifts across the range at which a first guess is worked out
_LOW = np.array([lo for lo, _ in JOINT_LIMITS_RAD[1:]])
_HIGH = np.array([hi for _, hi in JOINT_LIMITS_RAD[1:]])


@dataclass(frozen=True)
class Gaze:
    """What ``look_at`` found.

    joints: (tilt, lift, yaw, pitch) in radians, within MiRo's limits: send them to
    control/kinematic_joints. eye: CAML or CAMR, the eye aimed. error_rad: the angle left
    between that eye's optical axis and the target at these joints. reachable: error
    within 2 degrees. reason: why not, in a few words ('' when reachable).
    """

    joints: tuple
    eye: int
    error_rad: float
    reachable: bool
    reason: str

    @property
    def error_deg(self):
        return math.degrees(self.error_rad)

    def __str__(self):
        lift, yaw, pitch = (math.degrees(j) for j in self.joints[1:])
        said = 'on target' if self.reachable else f'out of reach: {self.reason}'
        return (f'{FRAME_NAMES[self.eye]} {said} ({self.error_deg:.1f} deg off); lift '
                f'{lift:.1f}, yaw {yaw:.1f}, pitch {pitch:.1f} deg')


def look_at(kc, target, frame=FOOT, eye=None):
    """The head joints that put ``target`` (a point of ``frame``) on an eye's optical axis.

    kc: the chain as it is now (its joints are where the search starts, so the head moves
    as little as it can; its pose matters only for frame=WORLD). eye: CAML or CAMR; None
    aims whichever eye puts the target on its axis with the smaller movement of the head,
    or, when neither does, the one that gets closer. Returns a ``Gaze``; ValueError for a
    target that is not three finite numbers or an eye that is not CAML or CAMR.
    """
    try:
        point = np.asarray(target, dtype=float)
    except (TypeError, ValueError):
        point = None
    if point is None or point.shape != (3,) or not np.all(np.isfinite(point)):
        raise ValueError(f'target must be three finite numbers, got {target!r}')
    if eye is not None and eye not in EYE_SIDE:
        raise ValueError(f'eye must be CAML or CAMR (or None for either), got {eye!r}')
    in_foot = kc.change_frame_abs(frame, FOOT, point)
    tilt = clamp_joints(*kc.joints)[0]
    start = np.array(clamp_joints(*kc.joints)[1:])
    eyes = (eye,) if eye is not None else (CAML, CAMR)
    found = [_aim(KinematicChain(kc.joints), tilt, start, in_foot, side) for side in eyes]
    # An eye whose search ended on the axis beats one that stopped short of it, even within
    # the 2 degrees that count as reachable (a local minimum can stop there: 1.5 degrees).
    return min(found, key=lambda gaze: (not gaze.reachable, gaze.error_rad > ON_AXIS_RAD,
                                        _movement(gaze, start) if gaze.reachable
                                        else gaze.error_rad))


def _movement(gaze, start):
    return float(np.sum((np.array(gaze.joints[1:]) - start) ** 2))


def _offsets(chain, tilt, head, target, eye):
    """(bearing, elevation) of the target seen from ``eye`` with the head at ``head``
    (lift, yaw, pitch), in the eye's frame: zero when it is on the optical axis."""
    chain.set_joints(tilt, *head)
    x, y, z = chain.change_frame_abs(FOOT, eye, target)
    return np.array([math.atan2(y, x), math.atan2(z, math.hypot(x, y))])


def _angle(offsets):
    """The angle between the axis and a direction at (bearing, elevation) from it."""
    bearing, elevation = offsets
    return math.acos(max(-1.0, min(1.0, math.cos(bearing) * math.cos(elevation))))


def _descend(chain, tilt, head, target, eye):
    """Damped least squares from ``head`` to the joints that bring the offsets nearest to
    zero within the limits: (head, offsets)."""
    offsets = _offsets(chain, tilt, head, target, eye)
    for _ in range(MAX_ITERATIONS):
        error = _angle(offsets)
        if error < CONVERGED_RAD:
            break
        jacobian = np.empty((2, 3))
        for joint in range(3):
            nudged = head.copy()
            nudged[joint] += JACOBIAN_DELTA_RAD
            jacobian[:, joint] = (_offsets(chain, tilt, nudged, target, eye)
                                  - offsets) / JACOBIAN_DELTA_RAD
        step = _step(jacobian, offsets, head)
        # Halve a step that makes things worse (far from the target the offsets are far
        # from linear in the joints).
        for _ in range(6):
            moved = np.clip(head + step, _LOW, _HIGH)
            new_offsets = _offsets(chain, tilt, moved, target, eye)
            if _angle(new_offsets) < error:
                break
            step = step / 2.0
        else:
            break  # no step improves: as near as the limits allow
        head, offsets = moved, new_offsets
    return head, offsets


def _step(jacobian, offsets, head):
    """The damped least-squares step, with the joints it would push past a limit held."""
    free = np.ones(3, bool)
    step = np.zeros(3)
    for _ in range(3):
        j = jacobian[:, free]
        step[:] = 0.0
        step[free] = -j.T @ np.linalg.solve(j @ j.T + DAMPING ** 2 * np.eye(2), offsets)
        blocked = free & (((head <= _LOW) & (step < 0)) | ((head >= _HIGH) & (step > 0)))
        if not blocked.any():
            break
        free &= ~blocked
        if not free.any():
            return np.zeros(3)
    largest = np.max(np.abs(step))
    return step * (MAX_STEP_RAD / largest) if largest > MAX_STEP_RAD else step


def _aim(chain, tilt, start, target, eye):
    """The best Gaze of ``eye`` at ``target`` (FOOT), searching from ``start`` first."""
    tried = [_descend(chain, tilt, start.copy(), target, eye)]
    if _angle(tried[0][1]) > ON_AXIS_RAD:
        tried.append(_descend(chain, tilt, _first_guess(chain, tilt, target, eye), target, eye))
    on_axis = [t for t in tried if _angle(t[1]) <= ON_AXIS_RAD]
    head, offsets = (min(on_axis, key=lambda t: np.sum((t[0] - start) ** 2))
                     if on_axis else min(tried, key=lambda t: _angle(t[1])))
    error = _angle(offsets)
    reachable = error <= REACH_TOLERANCE_RAD
    reason = '' if reachable else _why(chain, tilt, head, target, eye)
    return Gaze(joints=(tilt, *(float(j) for j in head)), eye=eye, error_rad=error,
                reachable=reachable, reason=reason)


def _first_guess(chain, tilt, target, eye):
    """A head pose near the best, in closed form for a few lifts: with the eye taken as
    fixed where it is at that lift, pitch (about y) gives the axis its height in the neck's
    frame and yaw (about the neck's z) its bearing. The one nearest the target wins."""
    axis = chain.axis(eye, HEAD)
    reach, phase = math.hypot(axis[0], axis[2]), math.atan2(axis[0], axis[2])
    guesses = []
    for lift in np.linspace(_LOW[0], _HIGH[0], GUESS_LIFTS):
        chain.set_joints(tilt, lift, 0.0, 0.0)
        wanted = chain.change_frame_rel(FOOT, NECK, target - chain.origin(eye))
        wanted = wanted / max(np.linalg.norm(wanted), 1e-9)
        turn = math.acos(max(-1.0, min(1.0, wanted[2] / reach)))
        for pitch in (turn - phase, -turn - phase):
            seen = rot_y(pitch) @ axis
            yaw = wrap(math.atan2(wanted[1], wanted[0]) - math.atan2(seen[1], seen[0]))
            guesses.append(np.clip((lift, yaw, pitch), _LOW, _HIGH))
    return min(guesses, key=lambda head: _angle(_offsets(chain, tilt, head, target, eye)))


def _why(chain, tilt, head, target, eye):
    """Why the eye at ``head`` stays off the target, in the robot's terms: where the target
    is from the eye against where the axis points (both seen in FOOT), and which limits
    hold the head back."""
    chain.set_joints(tilt, *head)
    to_target = target - chain.origin(eye)
    distance = float(np.linalg.norm(to_target))
    if distance < TOO_CLOSE_M:
        return f'too close ({distance:.2f} m from the eye)'
    (target_bearing, target_elevation), (axis_bearing, axis_elevation) = (
        (math.atan2(v[1], v[0]), math.atan2(v[2], math.hypot(v[0], v[1])))
        for v in (to_target, chain.axis(eye)))
    up = math.degrees(target_elevation - axis_elevation)
    # Across, an angle of bearing counts less the more steeply the target is seen.
    left = math.degrees(wrap(target_bearing - axis_bearing) * math.cos(target_elevation))
    lift, yaw, pitch = head
    vertical_held = (up < 0 and lift >= _HIGH[0] and pitch >= _HIGH[2]) or \
        (up > 0 and lift <= _LOW[0] and pitch <= _LOW[2])
    sideways_held = (left > 0 and yaw >= _HIGH[1]) or (left < 0 and yaw <= _LOW[1])
    if vertical_held if vertical_held != sideways_held else abs(up) >= abs(left):
        return (f'{"above" if up > 0 else "below"} what the head can look at '
                f'({abs(up):.0f} deg short)')
    return f'too far {"left" if left > 0 else "right"} for the head to turn to ' \
           f'({abs(left):.0f} deg short)'
