"""The world as markers, for RViz, Foxglove and the GUI's 3D view (/miro_sim/scene).

Two kinds of message go out on the one topic, each from a publisher of its own that keeps
its newest message for late subscribers (transient local), so a viewer that joins at any
time gets both:

- the layout: every static shape and picture in frame ``world``, every sound playing
  (namespace ``sound``, an orange sphere named in ``text``), and every robot's LEDs in
  their link frames (``<robot>/led_lf``, ..., frame-locked: /tf moves them) in the
  colours control/illum gives them. The robots themselves are drawn from their
  robot_description (the URDF). Sent at the start, after a reset, when a robot's LEDs
  change and when a sound starts or stops;
- the movers: every movable object (the ball, named boxes) in frame ``world``, sent at up
  to SCENE_RATE_HZ of simulated time, only when one of them has moved.

A robot costs the scene topic nothing while its LEDs stay as they are: its motion is on
/tf. Marker namespaces are the objects' and robots' names; unnamed statics are grouped by
the world-file table they come from (``wall``, ``ring``, ``table``, ``box``, ``ground``,
``picture``). A robot's markers carry the link's name in ``text``.
"""
import hashlib
import math
from pathlib import Path

from builtin_interfaces.msg import Duration
from geometry_msgs.msg import Point
from sensor_msgs.msg import CompressedImage
from std_msgs.msg import ColorRGBA
from visualization_msgs.msg import Marker, MarkerArray, UVCoordinate

from miro_ball.miro.body import ILLUM_NAMES
from miro_ball.miro.interface import frame_id, WORLD_FRAME
from miro_ball.miro.rotations import matrix_quaternions
from miro_sim_bullet.bullet import pybullet as pb
from miro_sim_bullet.render.visuals import BodyVisuals, MESHES

SCENE_RATE_HZ = 30.0
LED_MARKER_SCALE = 1.15
MOVED_M = 0.0005  # a mover is sent again once it has moved this far...
TURNED = 2e-7  # ... or turned (1 - |q.q'|: about 0.05 degrees)
_TYPES = {'box': Marker.CUBE, 'sphere': Marker.SPHERE, 'cylinder': Marker.CYLINDER}
# A picture is two triangles over its corners (bottom-left, bottom-right, top-right,
# top-left); texture coordinates with v up, as OpenGL and three.js take them.
_PICTURE_CORNERS = (0, 1, 2, 0, 2, 3)
_PICTURE_UV = ((0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0))
SOUND_MARKER_M = 0.08  # across
SOUND_COLOUR = ColorRGBA(r=1.0, g=0.55, b=0.1, a=1.0)


def _shape_marker(mesh, scale, colour, frame, ns, marker_id):
    """A CUBE, SPHERE or CYLINDER marker of one primitive instance (visuals.MESHES);
    ROS scales a sphere and a cylinder by their diameters."""
    kind = MESHES[mesh]
    marker = Marker(ns=ns, id=marker_id, type=_TYPES[kind], action=Marker.ADD)
    marker.header.frame_id = frame
    sx, sy, sz = (float(v) for v in scale)
    if kind == 'sphere':
        sx = sy = sz = 2 * sx
    elif kind == 'cylinder':
        sx, sy = 2 * sx, 2 * sy
    marker.scale.x, marker.scale.y, marker.scale.z = sx, sy, sz
    marker.color = ColorRGBA(r=float(colour[0]), g=float(colour[1]), b=float(colour[2]),
                             a=float(colour[3]))
    marker.lifetime = Duration()  # forever
    return marker


def _place(marker, rotation, position):
    p, o = marker.pose.position, marker.pose.orientation
    p.x, p.y, p.z = (float(v) for v in position)
    o.x, o.y, o.z, o.w = (float(v) for v in matrix_quaternions(rotation)[0])
    return marker


def sound_marker(name, position, marker_id):
    """A sound playing at ``position``: a small orange ball, its name in ``text``."""
    marker = Marker(ns='sound', id=marker_id, type=Marker.SPHERE, action=Marker.ADD,
                    text=name, color=SOUND_COLOUR)
    marker.header.frame_id = WORLD_FRAME
    marker.scale.x = marker.scale.y = marker.scale.z = SOUND_MARKER_M
    marker.pose.orientation.w = 1.0
    p = marker.pose.position
    p.x, p.y, p.z = (float(v) for v in position)
    return marker


def picture_marker(picture, marker_id):
    """A picture as a textured TRIANGLE_LIST in frame world (its PNG travels inside)."""
    data = picture.png
    key = f'{Path(picture.image).stem}-{hashlib.sha1(data).hexdigest()[:10]}'
    marker = Marker(ns='picture', id=marker_id, type=Marker.TRIANGLE_LIST, action=Marker.ADD,
                    texture_resource=f'embedded://{key}.png',
                    texture=CompressedImage(format='png', data=data), text=picture.source)
    marker.header.frame_id = WORLD_FRAME
    marker.pose.orientation.w = 1.0
    marker.scale.x = marker.scale.y = marker.scale.z = 1.0
    marker.color = ColorRGBA(r=1.0, g=1.0, b=1.0, a=1.0)
    marker.points = [Point(x=float(x), y=float(y), z=float(z))
                     for x, y, z in (picture.corners[k] for k in _PICTURE_CORNERS)]
    marker.uv_coordinates = [UVCoordinate(u=_PICTURE_UV[k][0], v=_PICTURE_UV[k][1])
                             for k in _PICTURE_CORNERS]
    return marker


class SceneMarkers:
    """The markers of one built SimWorld (make a new one after a reset)."""

    def __init__(self, world):
        self.world = world
        self.labels = world.body_labels  # body id -> (namespace, kind of body)
        self.visuals = {body: BodyVisuals(world.client, body) for body in self.labels}
        self.robot_bodies = {robot.body_id: name for name, robot in world.robots.items()}
        # Each robot's LED patches: drawn-only parts, a body each (physics.drawn).
        self.leds = {name: [(led, BodyVisuals(world.client, robot.model.drawn.bodies[led]))
                            for led in ILLUM_NAMES] for name, robot in world.robots.items()}
        self.movers = {body: ns for body, (ns, kind) in self.labels.items() if kind == 'mover'}
        self._sent = {}  # mover body -> its base's (position, quaternion) last sent
        self._shown = None

    # -- the layout ---------------------------------------------------------------------------
    def layout(self):
        """MarkerArray of the statics, the pictures and the robots' links."""
        markers, counts = [], {}
        for body, (ns, kind) in self.labels.items():
            visuals = self.visuals[body]
            if kind == 'static':
                rotations, positions = visuals.world_poses()
                colours = visuals.colours()
                for k in range(len(visuals.mesh)):
                    index = counts[ns] = counts.get(ns, -1) + 1
                    markers.append(_place(_shape_marker(visuals.mesh[k], visuals.scale[k],
                                                        colours[k], WORLD_FRAME, ns, index),
                                          rotations[k], positions[k]))
            elif kind == 'robot':
                markers += self._robot_markers(ns)
        for index, picture in enumerate(getattr(self.world.description, 'pictures', ())):
            markers.append(picture_marker(picture, index))
        for index, (name, position) in enumerate(self.sounds()):
            markers.append(sound_marker(name, position, index))
        self._shown = self.layout_state()
        return MarkerArray(markers=markers)

    def sounds(self):
        """[(name, position)] of the world's sounds playing now."""
        return [(name, tuple(source.position)) for name, (_, source)
                in self.world.acoustics.sounds.items()]

    def _robot_markers(self, robot):
        """A robot's LEDs in their link frames, frame-locked: /tf moves them. A shade larger
        than the URDF's patches, so a viewer that draws both shows the lit colour."""
        markers = []
        for index, (link, visuals) in enumerate(self.leds[robot]):
            marker = _shape_marker(visuals.mesh[0], visuals.scale[0] * LED_MARKER_SCALE,
                                   visuals.colours()[0], frame_id(robot, link), robot, index)
            marker.frame_locked, marker.text = True, link
            markers.append(_place(marker, visuals.rot[0], visuals.offset[0]))
        return markers

    def layout_state(self):
        """What changes the layout while the world runs: the robots' LEDs, the sounds."""
        return (tuple(tuple(robot.illum) for robot in self.world.robots.values()),
                tuple(self.sounds()))

    def layout_changed(self):
        return self.layout_state() != self._shown

    # -- the movers ---------------------------------------------------------------------------
    def movers_if_moved(self):
        """MarkerArray of every movable object if any moved since last sent, else None."""
        # A look at the bases' poses is all it takes to know (0.01 ms a look, where the
        # shapes' poses took 0.2: 6 % of the simulator's time at 30 looks a simulated second).
        poses = {body: pb.getBasePositionAndOrientation(body, physicsClientId=self.world.client)
                 for body in self.movers}
        if not any(self._moved(body, pose) for body, pose in poses.items()):
            return None
        markers = []
        for body, pose in poses.items():
            visuals = self.visuals[body]
            rotations, positions = visuals.world_poses()
            colours = visuals.colours()
            for k in range(len(visuals.mesh)):
                markers.append(_place(_shape_marker(visuals.mesh[k], visuals.scale[k],
                                                    colours[k], WORLD_FRAME, self.movers[body],
                                                    k), rotations[k], positions[k]))
            self._sent[body] = pose
        return MarkerArray(markers=markers)

    def _moved(self, body, pose):
        last = self._sent.get(body)
        if last is None:
            return True
        (position, orientation), (was_at, was_turned) = pose, last
        turned = 1.0 - abs(sum(a * b for a, b in zip(orientation, was_turned)))
        return math.dist(position, was_at) > MOVED_M or turned > TURNED
