"""What a world is: the dataclasses a world file becomes, its limits, and its error.

A world has one robot or several (RobotSpec), an optional ball (Ball), an optional ground
plane and any number of shapes (Shape: boxes, cylinders and spheres, with the panels and
table parts a file's compound tables expand into), pictures on flat quads (Picture), named
poses (NamedPose; named_poses() adds where its robots and ball start), sounds and hearing
options (scene.sounds). One table of a world file is also what a spawn request carries
(Model). world_checks makes these from a file's tables, world_file reads a file by its
name, URI or path, world_catalogue lists the files a client may load.

Names (ground truth, and the ROS namespace of each robot) follow ROS name rules and are
unique among robots and objects; 'ball' always means the ball. Every movable shape
(mass > 0) is named.
"""
import importlib.resources
import reprlib
from dataclasses import dataclass, field

from miro_ball.miro.interface import BALL_NAME
from miro_sim_bullet.scene.sounds import Hearing

DEFAULT_COLOUR = (0.7, 0.7, 0.7)
MAX_MAGNITUDE = 1000.0  # of every number of a world (m, rad, kg)
MAX_ROBOTS = 16
MAX_SHAPES = 2000  # once rings, walls and tables are expanded
START_SUFFIX = '_start'  # of the poses named_poses() makes: a declared pose cannot end so

# Values quoted in error messages are shortened, so a message stays short
# even when the value at fault is a huge string or a deeply nested list.
_SHORT = reprlib.Repr()
_SHORT.maxlevel, _SHORT.maxlist, _SHORT.maxstring, _SHORT.maxother, _SHORT.maxlong = \
    2, 4, 40, 40, 20


def shown(value):
    """``value`` as a WorldError quotes it: short, whatever it is."""
    return _SHORT.repr(value)


class WorldError(ValueError):
    """A world file that cannot be used; str() is one line for the user, ``kind`` what is
    wrong: MISSING (there is no such world, or no such file where one may be read) or
    INVALID (the file is there, and breaks a rule)."""
    MISSING = 'missing'
    INVALID = 'invalid'

    def __init__(self, message, kind=INVALID):
        super().__init__(message)
        self.kind = kind


@dataclass(frozen=True)
class Shape:
    kind: str  # box | cylinder | sphere
    position: tuple  # centre (m)
    yaw: float = 0.0
    size: tuple = ()  # box full extents
    radius: float = 0.0
    length: float = 0.0
    colour: tuple = DEFAULT_COLOUR
    mass: float = 0.0  # 0 = static
    friction: float = 0.8
    restitution: float = 0.0
    name: str | None = None  # always set when mass > 0
    source: str = ''  # the world-file table it comes from: 'box[1]', 'ring[0]', 'ground'


@dataclass(frozen=True)
class Picture:
    """A PNG on a flat quad. corners: four (x, y, z) world points, bottom-left,
    bottom-right, top-right, top-left as seen from the front (counter-clockwise there),
    which take the image's corners: in image coordinates (u right, v down, 0..1) the
    corners' (u, v) are (0, 1), (1, 1), (1, 0), (0, 0)."""
    source: str  # the world-file table: 'wall[2]', 'ring[0]', 'box[1]'
    image: str  # absolute path of the PNG: its name
    corners: tuple
    # The file's bytes as checked when the world was read: what is drawn and sent, never the
    # file again (a link or a FIFO put in its place later would be read unchecked).
    png: bytes = field(default=b'', repr=False, compare=False)


PICTURE_UV = ((0.0, 1.0), (1.0, 1.0), (1.0, 0.0), (0.0, 0.0))  # of Picture.corners


@dataclass(frozen=True)
class Ball:
    position: tuple  # x, y of the point it rests on
    radius: float
    mass: float
    colour: tuple
    restitution: float
    friction: float
    floor: float = 0.0  # height (m) of the surface it rests on


@dataclass(frozen=True)
class RobotSpec:
    name: str | None  # None only for a single unnamed robot: the simulator names it
    pose: tuple  # x, y (m), yaw (rad) of the point on the floor under the wheel axle
    floor: float = 0.0  # height (m) of the surface the robot stands on


@dataclass(frozen=True)
class NamedPose:
    """A place a tool may ask for by name: the point on the floor a robot stands on (or a
    ball's centre), and the heading."""
    name: str
    description: str = ''
    tags: tuple = ()
    position: tuple = (0.0, 0.0, 0.0)
    yaw: float = 0.0


@dataclass(frozen=True)
class Model:
    """One entity of a spawn request: a Shape (named when the table names it, else None)
    or the Ball, and what its file says about it."""
    body: Shape | Ball
    description: str = ''
    tags: tuple = ()


@dataclass(frozen=True)
class World:
    name: str
    source: str
    description: str = ''
    tags: tuple = ()
    poses: tuple = ()  # of NamedPose, as the file declares them (named_poses() adds starts)
    robots: tuple = (RobotSpec(None, (0.0, 0.0, 0.0)),)  # never empty
    ball: Ball | None = None
    ground_height: float | None = None
    ground_colour: tuple = DEFAULT_COLOUR
    ground_size: tuple = (100.0, 100.0)
    shapes: tuple = field(default_factory=tuple)
    pictures: tuple = field(default_factory=tuple)  # of Picture
    sounds: tuple = ()  # of scene.sounds.Sound
    hearing: Hearing = Hearing()



def named_poses(world, robot_name):
    """The NamedPoses of a world: where each robot starts ('<robot>_start'; a single
    unnamed robot is ``robot_name``) and the ball ('ball_start', its centre), then the
    poses the file declares."""
    starts = [NamedPose(f'{robot.name or robot_name}{START_SUFFIX}',
                        f'where {robot.name or robot_name} starts', ('start', 'robot'),
                        (robot.pose[0], robot.pose[1], robot.floor), robot.pose[2])
              for robot in world.robots]
    if world.ball is not None:
        ball = world.ball
        starts.append(NamedPose(f'{BALL_NAME}{START_SUFFIX}', 'where the ball starts',
                                ('start', BALL_NAME),
                                (*ball.position, ball.floor + ball.radius)))
    return starts + list(world.poses)


def half_extents(body):
    """(x, y, z) half extents of a Shape or the Ball in its own frame: what its bounds, its
    room and its height above the floor are made of."""
    if isinstance(body, Ball) or body.kind == 'sphere':
        return (body.radius,) * 3
    if body.kind == 'cylinder':
        return (body.radius, body.radius, body.length / 2)
    return tuple(size / 2 for size in body.size)


def table_of(shape):
    """The world-file table a Shape comes from: 'wall' for 'wall[2]' (its kind when the
    source says none)."""
    return shape.source.split('[')[0] or shape.kind


def bundled_folder():
    """The folder of the worlds, models and pictures installed with the package."""
    return importlib.resources.files('miro_sim_bullet.worlds')
