"""What counts as a kick and a fall: one definition for episodes, the demo and grading."""
import math

KICK_DISTANCE_M = 0.3  # the ball has moved this far from where it settled
FELL_BELOW_M = 0.02  # axle height above the robot's floor: 0.045 while it stands


def ball_moved(start, now):
    """Horizontal distance (m) between two ball positions (x, y[, z])."""
    return math.dist(start[:2], now[:2])
