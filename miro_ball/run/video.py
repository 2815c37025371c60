"""The video of a run: the overhead view beside every robot's eyes with its controller's
detections drawn, one video frame per overhead image."""
import cv2
import numpy as np

VIDEO_FPS = 10.0  # frames per simulated second (= the simulator's overhead_rate for it)
VIDEO_HEIGHT = 540


class Video:
    """Overhead view | every robot's eyes (one robot: left over right; several: a row
    each). times: (first, last) simulated s of the frames written, None before any."""

    def __init__(self, path, robots):
        """robots: the names of those whose eyes are shown ([]: the overhead view only)."""
        self.path = path
        self.robots = robots
        rows, self.columns = (2, 1) if len(robots) == 1 else (len(robots), 2)
        height = VIDEO_HEIGHT // max(1, rows)
        self.panel = (height * 16 // 9, height)
        self.eyes = [np.zeros((height, self.panel[0], 3), np.uint8)
                     for _ in range(rows * self.columns)]
        self.writer = None
        self.frames = 0
        self.times = None

    def eye(self, robot_index, side, bgr):
        slot = side if len(self.robots) == 1 else 2 * robot_index + side
        panel = cv2.resize(bgr, self.panel, interpolation=cv2.INTER_AREA)
        if side == 0 and len(self.robots) > 1:
            cv2.putText(panel, self.robots[robot_index], (6, 18), cv2.FONT_HERSHEY_SIMPLEX,
                        0.5, (0, 0, 0), 1)
        self.eyes[slot] = panel

    def overhead(self, bgr, t, note=''):
        """A video frame of this overhead image at simulated time t (s) of the run."""
        frame = cv2.resize(bgr, (VIDEO_HEIGHT, VIDEO_HEIGHT), interpolation=cv2.INTER_AREA)
        if self.eyes:
            frame = np.hstack([frame, np.vstack([
                np.hstack(self.eyes[i:i + self.columns])
                for i in range(0, len(self.eyes), self.columns)])])
        cv2.putText(frame, f't = {t:5.1f} s   {note}', (8, 22), cv2.FONT_HERSHEY_SIMPLEX, 0.6,
                    (0, 0, 0), 2)
        if self.writer is None:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            self.writer = cv2.VideoWriter(str(self.path), cv2.VideoWriter_fourcc(*'mp4v'),
                                          VIDEO_FPS, (frame.shape[1], frame.shape[0]))
        self.writer.write(frame)
        self.frames += 1
        self.times = (t if self.times is None else self.times[0], t)

    def close(self):
        if self.writer is not None:
            self.writer.release()
