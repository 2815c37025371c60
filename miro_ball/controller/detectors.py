"""Detectors by name: what the node runs on each eye's frames for the controller.

A detector factory gets the node's DetectionParams and returns a callable
``detect(image, camera) -> result or None`` (image: BGR frame, camera: the eye's
CameraModel at the frame's size). The result lands in ``Eye.detections[name]`` of
the next Percepts. "ball" is the tutorial's blue-ball detector; face, AprilTag,
motion and sound detectors register here the same way.
"""
from typing import Any, Callable, Dict

from miro_ball.controller.detection import BallDetector, DetectionParams

Detect = Callable[[Any, Any], Any]
DETECTORS: Dict[str, Callable[[DetectionParams], Detect]] = {}


def register(name, factory):
    """Make a detector available to controllers under name (a later one replaces it)."""
    DETECTORS[name] = factory


def make_detectors(names, detection_params):
    """{name: detect} for the names a controller asks for; ValueError names unknown ones."""
    unknown = [name for name in names if name not in DETECTORS]
    if unknown:
        raise ValueError('no detector named %s (known: %s)'
                         % (', '.join(map(repr, unknown)), ', '.join(sorted(DETECTORS))))
    return {name: DETECTORS[name](detection_params) for name in names}


def _ball(params):
    detector = BallDetector(params)
    return lambda image, camera: detector.detect(image)


register('ball', _ball)
