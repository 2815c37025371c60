"""The images the pages show: newest-only, one slot per robot and channel, kept as the JPEG
bytes that arrived (checked for size first) and handed to the web server's thread.

A channel's last frame stays when no page shows it any more (its subscription is dropped):
a page opened while the simulator is paused, when no new frame comes, shows the last one.
Demo mode's overlays of each eye are kept here too, so that each goes with its own frame
(pairing.py)."""
import threading
from collections import defaultdict
from dataclasses import dataclass
from typing import Optional

from sensor_msgs.msg import CompressedImage

from miro_ball.common.jpeg import MAX_SIDE, ImageRejected, jpeg_size
from miro_ball.common.qos import profile
from miro_ball.common.stamps import seconds
from miro_ball.gui.pairing import Overlays, window_end
from miro_ball.gui.protocol import CHANNELS, MAX_FRAME_BYTES
from miro_ball.miro.interface import EYE_QOS


@dataclass(frozen=True)
class Frame:
    seq: int
    stamp: float
    jpeg: bytes
    previous: Optional[float] = None  # the stamp of the channel's frame before this one


def _problem(data):
    """Why a JPEG is not shown, or None."""
    if len(data) > MAX_FRAME_BYTES:
        return f'{len(data)} bytes'
    try:
        width, height = jpeg_size(data)
    except ImageRejected as err:
        return str(err)
    if not (0 < width <= MAX_SIDE and 0 < height <= MAX_SIDE):
        return f'{width}x{height} pixels'
    return None


class FrameStore:
    """The newest frame of each (robot, channel); robot None for the simulator's own views.
    warn(key, text): a rate-limited warning; on_frame(channel): a frame has arrived."""

    def __init__(self, warn, on_frame):
        self.warn = warn
        self.on_frame = on_frame
        self._lock = threading.Lock()
        self._frames = {}
        self._overlays = defaultdict(Overlays)  # (robot, eye): demo mode's overlays
        self._seq = 0

    def subscribe(self, node, topic, channel, robot=None):
        """Subscribe on ``node`` to a JPEG topic shown on ``channel`` of ``robot``'s pages."""
        def on_image(msg):
            data = bytes(msg.data)
            problem = _problem(data)
            if problem:
                self.warn(f'image:{topic}', f'{topic}: image not shown: {problem}')
                return
            stamp = seconds(msg.header.stamp)
            with self._lock:
                self._seq += 1
                last = self._frames.get((robot, channel))
                self._frames[(robot, channel)] = Frame(self._seq, stamp, data,
                                                       last.stamp if last else None)
            self.on_frame(channel)
        return node.create_subscription(CompressedImage, topic, on_image, profile(EYE_QOS))

    def shown_with(self, robot):
        """{channel: Frame} that a page watching ``robot`` may show (thread-safe)."""
        with self._lock:
            return {ch: f for (who, ch), f in self._frames.items() if who in (robot, None)}

    def forget(self, robot):
        """``robot`` has gone: none of its frames is shown again."""
        with self._lock:
            self._frames = {key: f for key, f in self._frames.items() if key[0] != robot}
        self.forget_overlays(robot)

    def add_overlay(self, robot, eye, stamp, overlay):
        """Demo mode's overlay of ``robot``'s ``eye`` for the instant ``stamp`` (s)."""
        with self._lock:
            self._overlays[(robot, eye)].add(stamp, overlay)

    def overlay_on(self, robot, channel, frame):
        """(stamp, overlay) to draw on ``frame`` of ``robot``'s ``channel`` (an eye's, or
        its debug image's), or None (thread-safe)."""
        eye = CHANNELS[channel].removeprefix('debug_')
        with self._lock:
            overlays = self._overlays.get((robot, eye))
            return overlays and overlays.on(frame.stamp, window_end(frame.stamp,
                                                                    frame.previous))

    def forget_overlays(self, robot):
        """Demo mode is no longer shown for ``robot``: its overlays go."""
        with self._lock:
            for key in [key for key in self._overlays if key[0] == robot]:
                del self._overlays[key]
