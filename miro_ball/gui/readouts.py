"""MiRo's sensor readings in the units and scales the MDK GUI shows them in.

Plain numbers in, plain numbers or text out, so the page shows what a student of
the MDK tutorial expects and these rules are tested without ROS.
"""
import math

GRAVITY = 9.81
ACCEL_SCALE = 50.0  # the MDK GUI's bars: a / g x 50, so +-100 is +-2 g
CLIFF_STEPS = 15.0  # the cliff sensors read in steps of 1/15
SONAR_MAX_M = 1.0


def sonar_text(range_m):
    """'short' at 0, 'inf' beyond 1 m (or no echo), else metres, as the MDK GUI writes it."""
    if not isinstance(range_m, (int, float)) or math.isnan(range_m):
        return '-'
    if range_m <= 0.0:
        return 'short'
    if range_m > SONAR_MAX_M:
        return 'inf'
    return f'{range_m:.2f}m'


def accel(xyz):
    """Linear acceleration (m/s^2) -> the MDK GUI's [x, y, z, magnitude] on +-100 = +-2 g."""
    scaled = [v / GRAVITY * ACCEL_SCALE for v in xyz]
    return scaled + [math.sqrt(sum(v * v for v in scaled))]


def cliff(values):
    """0..1 per sensor -> 0..15, the MDK GUI's bars."""
    return [v * CLIFF_STEPS for v in values]


def light(values):
    """0..1 per sensor -> 0..100."""
    return [v * 100.0 for v in values]


def wheels_mm_s(values):
    """[left, right] m/s -> mm/s."""
    return [v * 1000.0 for v in values]


def head_degrees(positions):
    """kinematic_joints positions [tilt, lift, yaw, pitch] rad -> [lift, yaw, pitch] deg."""
    return [math.degrees(v) for v in positions[1:4]]


def finite_or_none(value):
    """JSON has no NaN or inf: those become None (shown as '-')."""
    return value if isinstance(value, (int, float)) and math.isfinite(value) else None


def jsonable(value):
    """A readout with every non-finite number replaced by None, lists kept."""
    if isinstance(value, dict):
        return {k: jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [jsonable(v) for v in value]
    if isinstance(value, str) or value is None or isinstance(value, bool):
        return value
    return finite_or_none(value)


def eye_fov_deg(camera):
    """[horizontal, vertical] field of view (deg) of a camera_model.CameraModel, edge to edge
    through the image's centre lines (the lens included), for drawing what an eye sees."""
    w, h = camera.width, camera.height
    cu, cv = (w - 1) / 2.0, (h - 1) / 2.0
    x, y, z = camera.pixel_to_ray([-0.5, w - 0.5, cu, cu], [cv, cv, -0.5, h - 0.5]).T
    across = math.atan2(y[0], x[0]) - math.atan2(y[1], x[1])  # y is left
    up = math.atan2(z[2], x[2]) - math.atan2(z[3], x[3])  # z is up
    return [round(math.degrees(across), 3), round(math.degrees(up), 3)]
