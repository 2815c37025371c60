"""What the eyes can find besides the ball: faces, AprilTags and motion.

Each detector is a class built from DetectionParams whose ``detect(frame_bgr)`` returns
its findings in the tutorial's normalised units (detection.Ball's): x from -0.5 (left
edge) to 0.5, y positive above the centre, sizes, all divided by the frame's width, so a
result means the same at every resolution. The node makes one of each per eye: the
motion detector remembers the eye's previous frame.
"""
from typing import NamedTuple, Tuple

import cv2
import numpy as np


class Sight(NamedTuple):
    """One thing seen: where (normalised, as detection.Ball), how big, how sure, which."""

    x: float
    y: float
    size: float  # width / frame width
    conf: float = 1.0
    id: int = -1  # an AprilTag's number; -1 for faces and motion


def _normalised(u, v, size_px, width, height, **more):
    return Sight((u - width / 2) / width, -(v - height / 2) / width, size_px / width, **more)


def grey_at_width(frame_bgr, width):
    """The frame in grey, scaled down (never up) to width pixels."""
    grey = cv2.cvtColor(frame_bgr, cv2.COLOR_BGR2GRAY)
    if grey.shape[1] > width:
        height = round(grey.shape[0] * width / grey.shape[1])
        grey = cv2.resize(grey, (width, height), interpolation=cv2.INTER_AREA)
    return grey


class FaceDetector:
    """Frontal faces with scikit-image's LBP cascade (OpenCV's LBP frontal-face model,
    shipped in the scikit-image wheel). A pass costs tens of milliseconds, so it runs on
    one frame in face_every and repeats its last answer in between."""

    def __init__(self, params):
        from skimage import data, feature  # a second to import: only for who asks for faces

        self.params = params
        self.cascade = feature.Cascade(data.lbp_frontal_face_cascade_filename())
        self.count = 0
        self.last = ()

    def detect(self, frame_bgr) -> Tuple[Sight, ...]:
        self.count += 1
        if (self.count - 1) % self.params.face_every:
            return self.last
        grey = grey_at_width(frame_bgr, self.params.face_width)
        height, width = grey.shape
        smallest = self.params.face_min_px
        found = self.cascade.detect_multi_scale(
            grey, scale_factor=self.params.face_scale_step, step_ratio=1,
            min_size=(smallest, smallest), max_size=(height, height))
        self.last = tuple(_normalised(f['c'] + f['width'] / 2, f['r'] + f['height'] / 2,
                                      f['width'], width, height) for f in found)
        return self.last


class TagDetector:
    """AprilTags (tag36h11, the MDK's family) with OpenCV's aruco module."""

    def __init__(self, params):
        dictionary = cv2.aruco.getPredefinedDictionary(cv2.aruco.DICT_APRILTAG_36h11)
        self.detector = cv2.aruco.ArucoDetector(dictionary, cv2.aruco.DetectorParameters())
        self.width = params.tag_width

    def detect(self, frame_bgr) -> Tuple[Sight, ...]:
        grey = grey_at_width(frame_bgr, self.width)
        height, width = grey.shape
        corners, ids, _ = self.detector.detectMarkers(grey)
        if ids is None:
            return ()
        found = []
        for quad, tag_id in zip(corners, ids.ravel()):
            quad = quad.reshape(4, 2)
            (u, v), side = quad.mean(axis=0), float(np.ptp(quad[:, 0]))
            found.append(_normalised(float(u), float(v), side, width, height, id=int(tag_id)))
        return tuple(found)


class MotionDetector:
    """Frame differencing: the largest region that changed since this eye's previous
    frame. It cannot tell the world's motion from MiRo's own: whoever uses it ignores
    what it says while MiRo's head or body moves (demo mode does)."""

    def __init__(self, params):
        self.params = params
        self.previous = None

    def detect(self, frame_bgr):
        grey = cv2.GaussianBlur(grey_at_width(frame_bgr, self.params.motion_width), (5, 5), 0)
        previous, self.previous = self.previous, grey
        if previous is None or previous.shape != grey.shape:
            return None
        changed = (cv2.absdiff(grey, previous) > self.params.motion_threshold).astype(np.uint8)
        count, _, stats, centres = cv2.connectedComponentsWithStats(changed)
        if count < 2:
            return None
        biggest = 1 + int(np.argmax(stats[1:, cv2.CC_STAT_AREA]))
        height, width = grey.shape
        area = stats[biggest, cv2.CC_STAT_AREA] / (width * height)
        if area < self.params.motion_min_area:
            return None
        u, v = centres[biggest]
        side = max(stats[biggest, cv2.CC_STAT_WIDTH], stats[biggest, cv2.CC_STAT_HEIGHT])
        return _normalised(float(u), float(v), float(side), width, height, conf=float(area))
