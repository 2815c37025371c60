"""The scene on ROS: /miro_sim/scene (markers; the robots move on /tf, see tf.py).

The node calls publish() at SCENE_RATE_HZ of simulated time. What goes out (scene.py,
the layout whenever it changed (the start, a reset, a robot's LEDs, a sound) and the movable
objects when one moved. With nobody listening it costs a look at the movers' poses, 30
times a simulated second.
"""
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from visualization_msgs.msg import MarkerArray

from miro_ball.miro.interface import SimTopics
from miro_sim_bullet.ros.scene import SceneMarkers

# A viewer that joins late gets the newest layout and the newest movers: each comes from a
# publisher of its own that keeps its last message (RViz: Durability "Transient Local").
LATCHED = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                     durability=DurabilityPolicy.TRANSIENT_LOCAL)
LAYOUT_MIN_PERIOD_S = 0.5  # LEDs that flicker re-send the layout at most twice a second


class SceneInterface:
    """ros: Endpoints; world: the SimWorld (rebuilt by a reset: noticed by its generation)."""

    def __init__(self, ros, world):
        self.world = world
        topics = SimTopics()
        self.pub_layout = ros.publisher(MarkerArray, topics.scene, LATCHED)
        self.pub_movers = ros.publisher(MarkerArray, topics.scene, LATCHED)
        self.generation = None
        # Out at once, not at the first step: a simulator started paused shows its world.
        self.publish()

    def _rebuild(self):
        self.generation = self.world.generation
        self.markers = SceneMarkers(self.world)
        self.pub_layout.publish(self.markers.layout())
        self.layout_sent = self.world.time

    def world_reset(self):
        """The world went back to its start, maybe rewound (its bodies kept, the generation
        too): its layout goes out again at the next publish, as after a rebuild."""
        self.generation = None

    def publish(self):
        """This instant's scene where it changed."""
        if self.generation != self.world.generation:
            self._rebuild()
        elif self.world.time - self.layout_sent >= LAYOUT_MIN_PERIOD_S \
                and self.markers.layout_changed():
            self.pub_layout.publish(self.markers.layout())
            self.layout_sent = self.world.time
        movers = self.markers.movers_if_moved()
        if movers is not None:
            self.pub_movers.publish(movers)
