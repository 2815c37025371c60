"""What a Robot hears: the latest of each sensor, checked, and the eyes' latest frames.

Each topic's message is turned into plain Python values as it arrives; a message that
does not make sense (wrong length, NaN, a JPEG that does not decode) is dropped with a
rate-limited warning and the last good value stays.
"""
import math
from dataclasses import dataclass
from typing import NamedTuple, Optional, Tuple

import cv2
from geometry_msgs.msg import Pose2D
from sensor_msgs.msg import BatteryState, CameraInfo, CompressedImage, JointState, Range
from std_msgs.msg import Float32MultiArray, UInt16

from miro_ball.common.checks import finite_values
from miro_ball.common.jpeg import decode_jpeg, ImageRejected
from miro_ball.miro.camera_model import CameraModel
from miro_ball.miro.constants import JOINT_POSITIONS
from miro_ball.miro.interface import EYE_QOS, EYES, RobotTopics, SENSOR_QOS


class Pose(NamedTuple):
    """Where the robot is on odometry: x, y (m) and heading theta (rad, CCW from x)."""

    x: float
    y: float
    theta: float

    def __str__(self):
        return f'Pose(x={self.x:.3f}, y={self.y:.3f}, theta={self.theta:.3f})'


@dataclass(frozen=True)
class Sensors:
    """The latest of MiRo's body sensors (None until the first message).

    cliff: (left, right), 1 over the floor, below 0.7 a drop. sonar: metres to what is ahead
    (inf: no echo). light: four light sensors, 0..1. touch_head, touch_body: a bit per touch
    sensor. battery: volts.
    """

    cliff: Optional[Tuple[float, float]] = None
    sonar: Optional[float] = None
    light: Optional[Tuple[float, ...]] = None
    touch_head: Optional[int] = None
    touch_body: Optional[int] = None
    battery: Optional[float] = None


def _sonar(msg):
    distance = float(msg.range)
    if math.isnan(distance) or distance < 0:
        raise ValueError(f'range must be a distance (inf: no echo), got {distance}')
    return distance


# What the robot reads: name -> (message type, topic, QoS, message -> value or ValueError)
_T = RobotTopics()  # relative names: the node lives in the robot's namespace
READINGS = {
    'pose': (Pose2D, _T.body_pose, SENSOR_QOS,
             lambda m: Pose(*finite_values((m.x, m.y, m.theta), 3, 'x, y, theta'))),
    'joints': (JointState, _T.kinematic_joints, SENSOR_QOS,
               lambda m: finite_values(m.position, 4, JOINT_POSITIONS)),
    'cliff': (Float32MultiArray, _T.cliff, SENSOR_QOS, lambda m: finite_values(m.data, 2, 'values')),
    'sonar': (Range, _T.sonar, SENSOR_QOS, _sonar),
    'light': (Float32MultiArray, _T.light, SENSOR_QOS, lambda m: finite_values(m.data, 4, 'values')),
    'touch_head': (UInt16, _T.touch('head'), SENSOR_QOS, lambda m: int(m.data)),
    'touch_body': (UInt16, _T.touch('body'), SENSOR_QOS, lambda m: int(m.data)),
    'battery': (BatteryState, _T.battery, SENSOR_QOS,
                lambda m: finite_values((m.voltage,), 1, 'voltage')[0]),
}


class Readings:
    """The latest value of each of READINGS, and how many have arrived (``count``)."""

    def __init__(self, connection):
        self.latest = {}
        self.count = dict.fromkeys(READINGS, 0)
        for name, (msg_type, topic, qos, convert) in READINGS.items():
            connection.subscribe(msg_type, topic, qos,
                                 self._taker(name, topic, convert, connection.warn))

    def _taker(self, name, topic, convert, warn):
        def take(msg):
            try:
                self.latest[name] = convert(msg)
            except ValueError as err:
                warn(name, f'{topic} ignored: {err}')
                return
            self.count[name] += 1
        return take

    def sensors(self):
        return Sensors(**{name: self.latest.get(name) for name in Sensors.__dataclass_fields__})


class Eyes:
    """Both eyes' latest frames (RGB) and camera models, from the first time they are asked
    for: the simulator draws an eye only while someone subscribes to it."""

    def __init__(self, connection):
        self._connection = connection
        self._jpeg = {}  # eye -> the latest CompressedImage's bytes
        self._decoded = {}  # eye -> (bytes, RGB image) of the frame decoded last
        self.cameras = {}  # eye -> CameraModel from its camera_info
        self.subscribed = False

    def subscribe(self):
        if self.subscribed:
            return
        self.subscribed = True
        topics, c = RobotTopics(), self._connection
        for eye in EYES:
            c.subscribe(CompressedImage, topics.eye_compressed(eye), EYE_QOS,
                        lambda msg, eye=eye: self._jpeg.__setitem__(eye, bytes(msg.data)))
            c.subscribe(CameraInfo, topics.camera_info(eye), EYE_QOS,
                        lambda msg, eye=eye: self._on_camera_info(eye, msg))

    def ready(self):
        return all(eye in self._jpeg and eye in self.cameras for eye in EYES)

    def _on_camera_info(self, eye, msg):
        try:
            self.cameras[eye] = CameraModel.from_camera_info(msg)
        except ValueError as err:
            self._connection.warn(f'{eye} camera_info',
                                  f'{RobotTopics().camera_info(eye)} ignored: {err}')

    def images(self):
        """{eye: RGB image} of the latest frames that decode (an eye whose frames never
        did is missing)."""
        for eye, data in list(self._jpeg.items()):
            seen, rgb = self._decoded.get(eye, (None, None))
            if seen is data:
                continue
            try:
                rgb = cv2.cvtColor(decode_jpeg(data), cv2.COLOR_BGR2RGB)
            except ImageRejected as err:  # the frame before stays the latest
                self._connection.warn(f'{eye} jpeg',
                                      f'{RobotTopics().eye_compressed(eye)} ignored: {err}')
            self._decoded[eye] = (data, rgb)
        return {eye: rgb for eye, (_, rgb) in self._decoded.items() if rgb is not None}
