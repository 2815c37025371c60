"""The scene on ROS: /miro_sim/scene (markers) and /miro_sim/links/<robot> (their frames).

The node calls publish() at SCENE_RATE_HZ of simulated time. What goes out (scene.py,
frames.py): the layout whenever it changed (the start, a reset, a robot's LEDs), the
movable objects when one moved, and each robot's link frames while someone listens. With
nobody listening it costs a look at the movers' poses, 30 times a simulated second.
"""
from geometry_msgs.msg import PoseArray
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from visualization_msgs.msg import MarkerArray

from miro_ball.miro.interface import SimTopics
from miro_sim_bullet.ros.frames import RobotLinks
from miro_sim_bullet.ros.scene import SceneMarkers

# A viewer that joins late gets the newest layout and the newest movers: each comes from a
# publisher of its own that keeps its last message (RViz: Durability "Transient Local").
LATCHED = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                     durability=DurabilityPolicy.TRANSIENT_LOCAL)
LINKS_QOS = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE)
LAYOUT_MIN_PERIOD_S = 0.5  # LEDs that flicker re-send the layout at most twice a second


class SceneInterface:
    """ros: Endpoints; world: the SimWorld (rebuilt by a reset: noticed by its generation)."""

    def __init__(self, ros, world):
        self.world = world
        topics = SimTopics()
        self.pub_layout = ros.publisher(MarkerArray, topics.scene, LATCHED)
        self.pub_movers = ros.publisher(MarkerArray, topics.scene, LATCHED)
        self.pub_links = {name: ros.publisher(PoseArray, topics.links(name), LINKS_QOS)
                          for name in world.robots}
        self.generation = None

    def _rebuild(self):
        self.generation = self.world.generation
        self.markers = SceneMarkers(self.world)
        self.links = {name: RobotLinks(self.world, name) for name in self.world.robots}
        self.pub_layout.publish(self.markers.layout())
        self.layout_sent = self.world.time

    def publish(self, when):
        """This instant's scene (stamped when) where it changed, and the links listened to."""
        if self.generation != self.world.generation:
            self._rebuild()
        elif self.world.time - self.layout_sent >= LAYOUT_MIN_PERIOD_S \
                and self.markers.colours_changed():
            self.pub_layout.publish(self.markers.layout())
            self.layout_sent = self.world.time
        movers = self.markers.movers_if_moved()
        if movers is not None:
            self.pub_movers.publish(movers)
        for name, publisher in self.pub_links.items():
            if publisher.get_subscription_count():
                publisher.publish(self.links[name].message(when))
