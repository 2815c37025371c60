"""rclpy QoS profiles of the plain ones the interface table names (miro/interface.py)."""
from rclpy.qos import QoSProfile, ReliabilityPolicy


def profile(qos):
    """The rclpy QoSProfile of an interface.Qos."""
    return QoSProfile(
        depth=qos.depth,
        reliability=ReliabilityPolicy.RELIABLE if qos.reliable else ReliabilityPolicy.BEST_EFFORT)
