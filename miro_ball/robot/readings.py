"""What a Robot hears: the latest of each sensor, checked, and the eyes' latest frames.

Each topic's message is turned into plain Python values as it arrives (miro.readers); a
message that does not make sense (wrong length, NaN, a JPEG that does not decode) is dropped
with a rate-limited warning and the last good value stays.
"""
from dataclasses import dataclass
from typing import Optional, Tuple

import cv2
from sensor_msgs.msg import CameraInfo, CompressedImage

from miro_ball.common.jpeg import decode_jpeg, ImageRejected
from miro_ball.common.messages import message_class
from miro_ball.miro.camera_model import CameraModel
from miro_ball.miro.interface import EYE_QOS, EYES, RobotTopics, TOPIC
from miro_ball.miro.readers import PERCEPT_READINGS, Pose, read, Refused

__all__ = ['Eyes', 'Pose', 'READINGS', 'Readings', 'Sensors']


@dataclass(frozen=True)
class Sensors:
    """The latest of MiRo's body sensors (None until the first message), as miro.readers
    reads them.

    cliff: (left, right), 1 over the floor, below 0.7 a drop. sonar: metres to what is ahead
    (inf: nothing in range). light: four light sensors, 0..1. touch_head, touch_body: a bit
    per touch sensor. battery: volts.
    """

    cliff: Optional[Tuple[float, float]] = None
    sonar: Optional[float] = None
    light: Optional[Tuple[float, ...]] = None
    touch_head: Optional[int] = None
    touch_body: Optional[int] = None
    battery: Optional[float] = None


# What the robot reads: name -> (the reader and interface row, fields of its topic name): the
# controller's percepts and where it is and its battery.
READINGS = {'pose': ('body_pose', {}), **PERCEPT_READINGS, 'battery': ('battery', {})}


class Readings:
    """The latest value of each of READINGS, and how many have arrived (``count``)."""

    def __init__(self, connection):
        self.latest = {}
        self.count = dict.fromkeys(READINGS, 0)
        for name, (key, fields) in READINGS.items():
            row = TOPIC[key]
            topic = RobotTopics().row(key, **fields)
            connection.subscribe(message_class(row.type), topic, row.qos,
                                 self._taker(name, key, topic, connection.warn))

    def _taker(self, name, key, topic, warn):
        def take(msg):
            try:
                self.latest[name] = read(key, msg)
            except Refused as err:
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
