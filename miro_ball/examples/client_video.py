"""Both eyes as image files, or recorded to a video: no window needed.

Like the MDK's client_video. It decodes each eye's JPEG from
sensors/cam{l,r}/compressed, keeps the latest left and right frames in DIR
(caml.jpg, camr.jpg: open them in any viewer that reloads), and with --video
writes every stereo pair side by side (left | right) to an MJPG .avi at 15
frames per second, as the MDK client does.

    python -m miro_ball.examples.client_video [--out eyes] [--video eyes.avi] [--frames 0]
"""
import os
import sys
from pathlib import Path

import cv2
import numpy as np
from sensor_msgs.msg import CompressedImage

from miro_ball.common.jpeg import ImageRejected, decode_jpeg
from miro_ball.common.throttle import Throttled
from miro_ball.examples._client import Client, make_parser, run
from miro_ball.miro.interface import EYE_QOS, EYES

VIDEO_FPS = 15.0


class Video(Client):
    def __init__(self, options, context=None):
        super().__init__('client_video', options, context)
        self.out = Path(options.out)
        self.out.mkdir(parents=True, exist_ok=True)
        self.writer = None
        self.latest = {}  # eye -> (stamp, BGR image)
        self.pairs = 0
        self.warn = Throttled(self.get_logger().warning)
        for eye in EYES:
            self.subscribe(CompressedImage, self.topics.eye_compressed(eye),
                           lambda msg, eye=eye: self.on_image(eye, msg), EYE_QOS)

    def on_image(self, eye, msg):
        try:
            image = decode_jpeg(msg.data)
        except ImageRejected as err:
            self.warn(eye, f'{eye}: frame ignored: {err}')
            return
        # Written aside, then renamed: a viewer never reads a half-written file.
        cv2.imwrite(str(self.out / f'.{eye}.jpg'), image)
        os.replace(self.out / f'.{eye}.jpg', self.out / f'{eye}.jpg')
        stamp = (msg.header.stamp.sec, msg.header.stamp.nanosec)
        self.latest[eye] = (stamp, image)
        left, right = (self.latest.get(e) for e in EYES)
        if left and right and left[0] == right[0]:  # both eyes of one instant
            self.on_pair(left[1], right[1])

    def on_pair(self, left, right):
        self.pairs += 1
        if self.options.video:
            if right.shape != left.shape:
                right = cv2.resize(right, (left.shape[1], left.shape[0]))
            frame = np.hstack([left, right])
            if self.writer is None:
                self.writer = cv2.VideoWriter(self.options.video, cv2.VideoWriter_fourcc(*'MJPG'),
                                              VIDEO_FPS, (frame.shape[1], frame.shape[0]))
                if not self.writer.isOpened():
                    self.get_logger().error(f'can not write {self.options.video}')
                    raise SystemExit(1)
            self.writer.write(frame)
        last = self.pairs == self.options.frames
        if self.pairs % 75 == 1 or last:  # every 5 s at 15 Hz, and the count at the end
            self.say(f'{self.now():7.2f} s  {self.pairs} stereo frames '
                     f'({left.shape[1]}x{left.shape[0]}) in {self.out}/'
                     + (f' and {self.options.video}' if self.options.video else ''))
        if last:
            raise SystemExit(0)

    def destroy_node(self):
        if self.writer is not None:
            self.writer.release()  # finishes the .avi, however the client ends
        super().destroy_node()


def build_parser():
    parser = make_parser('client_video', __doc__)
    parser.add_argument('--out', default='eyes', metavar='DIR',
                        help='folder for the latest caml.jpg and camr.jpg (eyes)')
    parser.add_argument('--video', metavar='FILE',
                        help='also record the eyes side by side to this .avi (MJPG, 15 fps)')
    parser.add_argument('--frames', type=int, default=0,
                        help='exit after this many stereo frames; 0 = until Ctrl+C (0)')
    return parser


def main(argv=None):
    return run(Video, build_parser(), argv)


if __name__ == '__main__':
    sys.exit(main())
