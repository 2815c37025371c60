"""Detectors by name: what the node runs on each eye's frames for the controller.

A detector factory gets the node's DetectionParams and returns a callable
``detect(image, camera) -> result or None`` (image: BGR frame, camera: the eye's
CameraModel at the frame's size). The result lands in ``Eye.detections[name]`` of
the next Percepts. The node makes each detector once per eye (one may remember the
eye's previous frame). "ball" is the tutorial's blue-ball detector (a Ball or None);
"face" and "tag" find faces and AprilTags (tuples of sights.Sight), "motion" the
largest moving region (a Sight or None). A detector that looks at one frame in N (faces)
returns its last answer, the very same object, for the frames in between: found_in()
tells such an answer by that, and the node says which frame it was found in
(``Eye.found_at``).
"""
from typing import Any, Callable, Dict

from miro_ball.controller.detection import BallDetector, DetectionParams

Detect = Callable[[Any, Any], Any]
DETECTORS: Dict[str, Callable[[DetectionParams], Detect]] = {}


def register(name, factory):
    """Make a detector available to controllers under name (a later one replaces it)."""
    DETECTORS[name] = factory


def check_names(names):
    """ValueError naming those of ``names`` that are no detector's."""
    unknown = [name for name in names if name not in DETECTORS]
    if unknown:
        raise ValueError('no detector named %s (known: %s)'
                         % (', '.join(map(repr, unknown)), ', '.join(sorted(DETECTORS))))


def make_detectors(names, detection_params):
    """{name: detect} for the names a controller asks for; ValueError names unknown ones."""
    check_names(names)
    return {name: DETECTORS[name](detection_params) for name in names}


def _ball(params):
    detector = BallDetector(params)
    return lambda image, camera: detector.detect(image)


def _sight(name, with_camera=False):
    def factory(params):
        from miro_ball.controller import sights  # scikit-image only for who asks for faces

        detector = getattr(sights, name)(params)
        if with_camera:
            return detector.detect
        return lambda image, camera: detector.detect(image)
    return factory


register('ball', _ball)
register('face', _sight('FaceDetector', with_camera=True))
register('tag', _sight('TagDetector'))
register('motion', _sight('MotionDetector'))


def found_in(found, before):
    """{name: stamp} of the results in ``found`` (this frame's, {name: result}) that their
    detector handed back again: the very objects it gave for the eye's previous frame.
    ``before``: (results, stamp, found_in) of that frame, or None. Such a result was found
    in that frame, or in the one it was carried from in turn."""
    if before is None:
        return {}
    results, stamp, carried = before
    # Not an empty answer: () is one object in CPython, whatever frame found nothing.
    return {name: carried.get(name, stamp) for name, result in found.items()
            if result and result is results.get(name)}
