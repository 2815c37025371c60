"""MiRo's differential-drive formula (MDK wheel_speed2cmd_vel and its inverse)."""
import math

from miro_ball.miro.constants import WHEEL_MAX_SPEED_M_PER_S, WHEEL_TRACK_M


def wheel_speed2cmd_vel(wheel_speed, track=WHEEL_TRACK_M):
    """[left, right] wheel speeds in m/s -> (forward m/s, turn rate rad/s, CCW +)."""
    left, right = wheel_speed
    return (left + right) / 2.0, (right - left) / track


def cmd_vel2wheel_speed(linear, angular, track=WHEEL_TRACK_M):
    """(forward m/s, turn rate rad/s) -> (left, right) wheel speeds in m/s."""
    half = angular * track / 2.0
    return linear - half, linear + half


def clamp_wheel_speeds(left, right, limit=WHEEL_MAX_SPEED_M_PER_S):
    """Clamp each wheel to +-limit; each wheel independently, like the platform. A speed
    that is not finite is passed on as it is, for the taker to refuse: min and max made a
    NaN the full +0.4 m/s, a wheel driven by nothing."""
    return tuple(speed if not math.isfinite(speed) else max(-limit, min(limit, speed))
                 for speed in (left, right))


def clamped_cmd_vel(left, right, limit=WHEEL_MAX_SPEED_M_PER_S):
    """Wheel speeds (m/s) -> the cmd_vel (forward m/s, turn rate rad/s) a controller sends
    for them: each wheel clamped to +-limit, then the MDK's formula (the controller host,
    the GUI and the learning rig all drive so). A non-finite speed gives a non-finite
    cmd_vel, which the simulator refuses."""
    return wheel_speed2cmd_vel(clamp_wheel_speeds(left, right, limit))


def wrap(angle):
    """The angle in (-pi, pi]: headings and turns compared the short way round."""
    return math.atan2(math.sin(angle), math.cos(angle))


