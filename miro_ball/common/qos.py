"""rclpy QoS profiles of the plain ones the interface table names (miro/interface.py), and
the profile that matches what a topic's publishers offer."""
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy


def profile(qos):
    """The rclpy QoSProfile of an interface.Qos."""
    return QoSProfile(
        depth=qos.depth,
        reliability=ReliabilityPolicy.RELIABLE if qos.reliable else ReliabilityPolicy.BEST_EFFORT,
        durability=DurabilityPolicy.TRANSIENT_LOCAL if qos.latched
        else DurabilityPolicy.VOLATILE)


def matching(publishers, depth=10):
    """A subscription profile every one of ``publishers`` (rclpy TopicEndpointInfo) matches:
    best effort if any offers only that; transient local if all keep their last messages,
    so that a late subscriber still gets /tf_static or robot_description (as ros2 topic echo
    does)."""
    qos = [p.qos_profile for p in publishers]
    reliable = all(q.reliability == ReliabilityPolicy.RELIABLE for q in qos)
    latched = bool(qos) and all(q.durability == DurabilityPolicy.TRANSIENT_LOCAL for q in qos)
    return QoSProfile(depth=depth,
                      reliability=ReliabilityPolicy.RELIABLE if reliable
                      else ReliabilityPolicy.BEST_EFFORT,
                      durability=DurabilityPolicy.TRANSIENT_LOCAL if latched
                      else DurabilityPolicy.VOLATILE)
