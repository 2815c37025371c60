"""What the eyes can find besides the ball: faces, AprilTags and motion.

Each detector is a class built from DetectionParams whose ``detect(frame_bgr)`` (the face
detector's ``detect(frame_bgr, camera)``: it needs the eye's lens) returns
its findings in the tutorial's normalised units (detection.Ball's): x from -0.5 (left
edge) to 0.5, y positive above the centre, sizes, all divided by the frame's width, so a
result means the same at every resolution. The node makes one of each per eye: the
motion detector remembers the eye's previous frame.
"""
import math
from typing import NamedTuple, Tuple

import cv2
import numpy as np

from miro_ball.controller.level_view import level_view, px_per_rad


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
    shipped in the scikit-image wheel), looked for in the eye's level view (level_view.py)
    so that a face near the edge of MiRo's 120-degree eye is found as one straight ahead;
    what is found is said in the frame's own pixels. A look costs tens of milliseconds, so
    it runs on one frame in face_every and repeats its last answer in between."""

    def __init__(self, params):
        from skimage import data, feature  # a second to import: only for who asks for faces

        self.params = params
        self.cascade = feature.Cascade(data.lbp_frontal_face_cascade_filename())
        self.count = 0
        self.last = ()

    def detect(self, frame_bgr, camera) -> Tuple[Sight, ...]:
        """Faces in a frame seen through camera (a CameraModel; scaled here if its size is
        not the frame's)."""
        self.count += 1
        if (self.count - 1) % self.params.face_every:
            return self.last
        height, width = frame_bgr.shape[:2]
        scale = px_per_rad(self.params.face_width)
        # A frame more than twice as fine as the view (1280 wide) is scaled down first, so
        # the view does not alias; a finer source than the view keeps faces sharper there
        # (measured: 640 wide straight into the view finds more at 1.5 m than 400 wide).
        source = grey_at_width(frame_bgr, max(
            2, round(2 * width * scale / camera.scaled_to(width, height).intrinsics.fx)))
        view = level_view(camera.scaled_to(source.shape[1], source.shape[0]), scale)
        smallest = self.params.face_min_px
        if min(view.shape) < smallest:
            self.last = ()
            return self.last
        found = self.cascade.detect_multi_scale(
            view.draw(source), scale_factor=self.params.face_scale_step, step_ratio=1,
            min_size=(smallest, smallest), max_size=(view.shape[0],) * 2)
        self.last = tuple(filter(None, (
            _in_frame(view, f, width / source.shape[1], width, height) for f in found)))
        return self.last


def _in_frame(view, box, zoom, width, height):
    """The Sight in the frame (width x height; zoom: its px per source px) of a box found
    in the view, or None if its centre is off the frame. Its size is the distance between
    where the box's left and right middles land (twice the centre to one, at the frame's
    edge)."""
    middle = box['r'] + box['height'] / 2 - 0.5
    left, right = box['c'] - 0.5, box['c'] + box['width'] - 0.5
    u, v = (zoom * (a + 0.5) - 0.5
            for a in view.to_frame([left, (left + right) / 2, right], [middle] * 3))
    if not (np.isfinite(u[1]) and np.isfinite(v[1])):
        return None
    ends = [e for e in (math.hypot(u[i] - u[1], v[i] - v[1]) for i in (0, 2))
            if math.isfinite(e)]
    if not ends:
        return None
    across = sum(ends) if len(ends) == 2 else 2 * ends[0]
    return _normalised(float(u[1]), float(v[1]), float(across), width, height)


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
