"""From percepts to stimuli: what each detection and sound is, and where, around MiRo.

A Stimulus gives a direction in MiRo's body frame (azimuth 0 ahead, + to the left;
elevation + up, both rad, seen from the head), the angle it spans and, for things of
known size, its range. The eyes' detections go through each eye's camera model and the
kinematic chain at the head's joints of their frame's instant, and are turned by what the
body turned since (own_motion.py), so what the left eye saw 27 degrees off its axis lands
where it is now; the ears' direction is in the head frame, turned by the head's yaw.
"""
import math
from typing import NamedTuple, Optional

from miro_ball.miro.constants import KIN_CALIB_RAD, YAW
from miro_ball.miro.interface import EYES
from miro_ball.miro.kc import BODY, EYE_FRAMES, HEAD, KinematicChain
from miro_ball.miro.kinematics import wrap

KINDS = ('ball', 'face', 'tag', 'motion', 'sound')


class Stimulus(NamedTuple):
    kind: str  # one of KINDS
    azimuth: float  # rad in the body frame, + left
    elevation: float  # rad, + up
    span: float  # angle it spans, rad
    range: Optional[float] = None  # m, for things of known size
    strength: float = 1.0  # detector's own measure: motion's area, a sound's loudness 0..1
    eye: int = -1  # the eye it was seen by (EYES order), -1 heard
    tag_id: int = -1


def _direction(vector):
    x, y, z = vector
    return math.atan2(y, x), math.atan2(z, math.hypot(x, y))


def _pixel(sight, camera):
    """Pixel (u, v) of a normalised detection (detection.Ball, sights.Sight)."""
    return (sight.x + 0.5) * camera.width, camera.height / 2 - sight.y * camera.width


class Senses:
    """Stimuli of one tick from the percepts (detections in each eye, a sound heard)."""

    def __init__(self, spatial, action):
        self.spatial, self.action = spatial, action
        self.kc = KinematicChain(KIN_CALIB_RAD)

    def sights(self, percepts, include_motion, motion=None):
        """The stimuli of every eye's detections; motion (own_motion.OwnMotion) says where
        head and body were when each was found (without it: where they are now)."""
        now = percepts.joints or KIN_CALIB_RAD
        found = []
        for index, eye in enumerate(percepts.eyes):
            def seen(kind, sight, size, **more):
                then = motion.then(eye.found_at(kind)) if motion is not None else None
                return self._seen(kind, sight, size, eye.camera, EYE_FRAMES[EYES[index]],
                                  index, then.joints if then else now,
                                  then.turned if then else 0.0, **more)
            ball = eye.found('ball')
            if ball is not None:
                found.append(seen('ball', ball, 2 * ball.r, known_size=self.action.ball_size_m))
            for face in eye.found('face') or ():
                found.append(seen('face', face, face.size, known_size=self.action.face_size_m))
            for tag in eye.found('tag') or ():
                found.append(seen('tag', tag, tag.size, tag_id=tag.id))
            moving = eye.found('motion')
            if moving is not None and include_motion:
                found.append(seen('motion', moving, moving.size, strength=moving.conf))
        return found

    def _seen(self, kind, sight, size, camera, frame, eye, joints, turned, known_size=None,
              strength=1.0, tag_id=-1):
        """The Stimulus of a sight seen with the head at joints, the body having turned by
        turned (rad, + left) since."""
        if tuple(joints) != self.kc.joints:
            self.kc.set_joints(*joints)
        u, v = _pixel(sight, camera)
        half = size * camera.width / 2
        centre = camera.pixel_to_direction(self.kc, frame, u, v, BODY)
        edges = [camera.pixel_to_direction(self.kc, frame, u + d, v, BODY) for d in (-half, half)]
        cos = sum(a * b for a, b in zip(*edges))
        span = math.acos(max(-1.0, min(1.0, float(cos))))
        azimuth, elevation = _direction(centre)
        distance = None
        if known_size is not None and span > 1e-6:
            distance = known_size / (2 * math.tan(span / 2))
        return Stimulus(kind, wrap(azimuth - turned), elevation, span, distance, strength, eye,
                        tag_id)

    def sound(self, heard, joints):
        """A stimulus of a sound heard (miro.hearing.Heard), or None if too quiet."""
        if heard is None or heard.level_db < self.spatial.quiet_db:
            return None
        loud = (heard.level_db - self.spatial.quiet_db) / (self.spatial.loud_db
                                                           - self.spatial.quiet_db)
        azimuth = wrap(heard.azimuth + (joints or KIN_CALIB_RAD)[YAW])
        self.kc.set_joints(*(joints or KIN_CALIB_RAD))
        head_height = self.kc.origin(HEAD, BODY)[2]
        elevation = math.atan2(self.spatial.sound_height_m - head_height,
                               self.spatial.sound_range_m)
        return Stimulus('sound', azimuth, elevation, 0.1, self.spatial.sound_range_m,
                        min(1.0, loud))

