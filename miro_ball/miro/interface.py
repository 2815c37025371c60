"""MiRo on ROS: robot names and every topic and service name, in one place.

The simulator, the controller, the lab tools and the example clients all take
their names from here, so a robot called ``miro02`` (the MDK's convention for
several robots) is one argument away and no other module spells a topic.
"""
import os
import re
from dataclasses import dataclass

DEFAULT_ROBOT_NAME = 'miro'
ROBOT_NAME_ENV = 'MIRO_ROBOT_NAME'
CLOCK = '/clock'
EYES = ('caml', 'camr')  # index 0 is the left eye, as the MDK's CAM_L
EYE_SIDE = {'caml': +1, 'camr': -1}  # +1 left, -1 right: the sign of the eye's y offset
SIM_NODE_NAME = 'miro_sim'
BALL_NAME = 'ball'  # the simulator's name of the ball, for set_pose and its ground truth
CONTROLLER_NODE_NAME = 'kick_blue_ball'
GUI_NODE_NAME = 'miro_gui'
MAX_NAME_LENGTH = 64
# A ROS name token: what may stand between two slashes of a topic name.
_TOKEN = re.compile(r'[A-Za-z][A-Za-z0-9_]*\Z')


def check_name(name, what='robot name'):
    """The name if it can be a ROS namespace, else ValueError in one line."""
    if not isinstance(name, str) or not _TOKEN.match(name) or len(name) > MAX_NAME_LENGTH:
        raise ValueError(f'{what} {name!r} must be a letter followed by letters, digits or '
                         f'underscores (at most {MAX_NAME_LENGTH} characters)')
    return name


def robots_in(topic_names):
    """Names of the robots whose odometry is among topic_names (a ROS graph listing),
    sorted: how a viewer finds the MiRos that are running."""
    names = set()
    for topic in topic_names:
        parts = topic.split('/')
        if len(parts) > 2 and parts[0] == '' and _TOKEN.match(parts[1]) \
                and len(parts[1]) <= MAX_NAME_LENGTH and RobotTopics(parts[1]).odom == topic:
            names.add(parts[1])
    return sorted(names)


def default_robot_name(environ=None):
    """$MIRO_ROBOT_NAME, as the MDK reads it, else 'miro' (not checked here)."""
    environ = os.environ if environ is None else environ
    return environ.get(ROBOT_NAME_ENV) or DEFAULT_ROBOT_NAME


@dataclass(frozen=True)
class RobotTopics:
    """Absolute names of one MiRo's interface, under /<name>/."""

    name: str

    def __post_init__(self):
        check_name(self.name)

    def topic(self, relative):
        return f'/{self.name}/{relative}'

    # Sensors: what the robot (or the simulator standing in for it) publishes.
    def eye_compressed(self, eye):
        return self.topic(f'sensors/{eye}/compressed')

    def eye_raw(self, eye):
        return self.topic(f'sensors/{eye}')

    def camera_info(self, eye):
        return self.topic(f'sensors/{eye}/camera_info')

    @property
    def kinematic_joints(self):
        return self.topic('sensors/kinematic_joints')

    @property
    def odom(self):
        return self.topic('sensors/odom')

    @property
    def body_pose(self):
        return self.topic('sensors/body_pose')

    @property
    def body_vel(self):
        return self.topic('sensors/body_vel')

    @property
    def wheel_speed_cmd(self):
        return self.topic('sensors/wheel_speed_cmd')

    @property
    def wheel_speed_opto(self):
        return self.topic('sensors/wheel_speed_opto')

    @property
    def cliff(self):
        return self.topic('sensors/cliff')

    @property
    def sonar(self):
        return self.topic('sensors/sonar')

    def imu(self, part):
        """part: 'body' or 'head'."""
        return self.topic(f'sensors/imu_{part}')

    @property
    def battery(self):
        return self.topic('sensors/battery')

    @property
    def light(self):
        return self.topic('sensors/light')

    def touch(self, part):
        """part: 'head' or 'body'."""
        return self.topic(f'sensors/touch_{part}')

    @property
    def sensor_flags(self):
        return self.topic('sensors/flags')

    # Control: what the robot takes.
    @property
    def cmd_vel(self):
        return self.topic('control/cmd_vel')

    @property
    def kinematic_targets(self):
        return self.topic('control/kinematic_joints')

    @property
    def cosmetic_joints(self):
        return self.topic('control/cosmetic_joints')

    @property
    def illum(self):
        return self.topic('control/illum')

    @property
    def tone(self):
        return self.topic('control/tone')

    @property
    def control_flags(self):
        return self.topic('control/flags')

    # The kick_blue_ball controller's annotated frames (read by the demo and viewers).
    def controller_debug(self, eye):
        return self.topic(f'{CONTROLLER_NODE_NAME}/debug/{eye}/compressed')


@dataclass(frozen=True)
class SimTopics:
    """The simulator's own interface, under its node name: not MiRo's, a simulator's."""

    node: str = SIM_NODE_NAME

    def topic(self, relative):
        return f'/{self.node}/{relative}'

    @property
    def ball(self):
        """geometry_msgs/PointStamped: the ball's centre (kept for the first clients)."""
        return self.topic('ball')

    def object_pose(self, name):
        """geometry_msgs/PoseStamped: ground truth of one movable object or robot."""
        return self.topic(f'objects/{name}')

    @property
    def set_pose(self):
        """geometry_msgs/PoseStamped in: move the object or robot named in header.frame_id."""
        return self.topic('set_pose')

    @property
    def overhead(self):
        return self.topic('overhead/compressed')

    @property
    def reset(self):
        return self.topic('reset')

    @property
    def pause(self):
        return self.topic('pause')

    @property
    def step(self):
        return self.topic('step')
