"""What an eye publishes, drawn and encoded: JPEG bytes and raw RGB bytes of one image.

Plain functions on numpy images, so that the simulator's thread and its eye worker
processes (render.eye_workers) produce the very same bytes. Images come as RGB or RGBA
rows: our GL renderer reads RGBA back (0.7 ms a 640x360 stereo pair cheaper than RGB on
llvmpipe) and the channel order is fixed here, where a copy is made anyway.
"""
import time
from dataclasses import dataclass

import cv2

JPEG_FORMAT = 'rgb8; jpeg compressed bgr8'  # CompressedImage.format, as image_transport says


@dataclass(frozen=True)
class EyeWants:
    """Which encodings of an eye someone subscribes to."""
    jpeg: bool = True
    raw: bool = False


def to_bgr(image):
    """BGR copy of an RGB or RGBA image (what OpenCV encodes)."""
    code = cv2.COLOR_RGBA2BGR if image.shape[2] == 4 else cv2.COLOR_RGB2BGR
    return cv2.cvtColor(image, code)


def to_rgb(image):
    """Contiguous RGB rows of an RGB or RGBA image (sensor_msgs 'rgb8')."""
    if image.shape[2] == 4:
        return cv2.cvtColor(image, cv2.COLOR_RGBA2RGB)
    return image


def jpeg_bytes(image, quality):
    """JPEG of an RGB or RGBA image at ``quality`` (1-100)."""
    ok, data = cv2.imencode('.jpg', to_bgr(image), [cv2.IMWRITE_JPEG_QUALITY, int(quality)])
    if not ok:
        raise ValueError('OpenCV could not encode the image as JPEG')
    return data.tobytes()


def encode(image, wants, quality):
    """(jpeg bytes or None, raw RGB bytes or None) of one eye image, as ``wants`` asks."""
    jpeg = jpeg_bytes(image, quality) if wants.jpeg else None
    raw = to_rgb(image).tobytes() if wants.raw else None
    return jpeg, raw


def draw_and_encode(render, stages, views, camera, wants, quality, seconds):
    """Encoded images of the eyes at OpenGL ``views`` through CameraModel ``camera``, one
    (jpeg, raw) per view as its EyeWants asks. render(views, camera, rgba) draws them;
    ``stages`` is the renderer's own {stage: seconds} (Renderer.seconds). ``seconds`` (a
    dict) gains the wall time spent drawing ('draw', and the renderer's stages as
    'draw: <stage>') and encoding ('encode')."""
    before = dict(stages)
    started = time.perf_counter()
    images = render(views, camera, rgba=True)
    drawn = time.perf_counter()
    frames = [encode(image, want, quality) for image, want in zip(images, wants)]
    spent = {'draw': drawn - started, 'encode': time.perf_counter() - drawn}
    spent.update({f'draw: {stage}': value - before.get(stage, 0.0)
                  for stage, value in stages.items()})
    for stage, value in spent.items():
        seconds[stage] = seconds.get(stage, 0.0) + value
    return frames
