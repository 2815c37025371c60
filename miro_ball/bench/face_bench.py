"""What a look for faces costs, before and after issue 39, side by side on the same frames.

Frames: both eyes of MiRo with the den's face board 1 m and 1.5 m away, straight ahead and
60 deg to either side, and of the den turned from its board (no face), drawn by the
simulator at each eye size through the 120-degree pinhole (demo mode's default) or MiRo's
lens. Each repeat times every frame with both ways in turn, so both see the same load:

- ``before``: the frontal cascade on the whole frame scaled to 320 wide, sizes 1.25 apart
  (the face detector before issue 39, restated here as the reference);
- ``after``: sights.FaceDetector at its defaults (the eye's level view, face_width 400,
  sizes 1.15 apart).

Printed: the median and 90th percentile of a look in ms, and the faces found of those in
view. A look is what demo mode pays on one frame in face_every per eye. Run:
``python -m miro_ball.bench.face_bench [--repeats 20]``.
"""
import argparse
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np

from miro_ball.bench.face_board import eye_frames, face_board_world, face_centre
from miro_ball.controller.detection import DetectionParams
from miro_ball.controller.sights import FaceDetector, grey_at_width
from miro_ball.miro.camera_model import CameraModel, LENSES
from miro_sim_bullet.physics.world import SimWorld
from miro_sim_bullet.scene.world_file import load_world

SIZES = ((640, 360), (320, 240), (1280, 720))
PLACES = ((0, 1.0), (60, 1.0), (-60, 1.0), (0, 1.5), (60, 1.5), (-60, 1.5), None)
BEFORE_WIDTH, BEFORE_STEP, BEFORE_MIN_PX = 320, 1.25, 20


def frames_of(camera, folder):
    """[(BGR frame, True if a face is in view)] of both eyes at every place."""
    found = []
    for place in PLACES:
        if place is None:  # the den, MiRo turned from its face board
            world = SimWorld(load_world('den'))
            world.robot.place(0.0, 0.0, np.radians(150.0))
        else:
            world = SimWorld(load_world(face_board_world(folder, *place)))
        try:
            for _, frame, position, rotation in eye_frames(world, camera):
                seen = place is not None and camera.project_from(
                    position, rotation, face_centre(*place)) is not None
                found.append((frame, seen))
        finally:
            world.close()
    return found


def before(detector):
    """The look before issue 39, on the same cascade: (frame, camera) -> faces found."""
    def look(frame, camera):
        grey = grey_at_width(frame, BEFORE_WIDTH)
        return detector.cascade.detect_multi_scale(
            grey, scale_factor=BEFORE_STEP, step_ratio=1,
            min_size=(BEFORE_MIN_PX, BEFORE_MIN_PX), max_size=(grey.shape[0],) * 2)
    return look


def bench(size, lens, repeats, folder):
    camera = CameraModel(*size, lens=lens)
    frames = frames_of(camera, folder)
    after = FaceDetector(DetectionParams(face_every=1))
    ways = {'before': before(after), 'after': after.detect}
    times = {name: [] for name in ways}
    hits = {name: 0 for name in ways}
    for repeat in range(repeats):
        for frame, seen in frames:
            for name, look in ways.items():
                start = time.perf_counter()
                faces = look(frame, camera)
                times[name].append(1000 * (time.perf_counter() - start))
                hits[name] += repeat == 0 and seen and len(faces) > 0
    in_view = sum(seen for _, seen in frames)
    for name in ways:
        ms = sorted(times[name])
        print(f'| {size[0]}x{size[1]} {lens} | {name} | {statistics.median(ms):.1f} | '
              f'{ms[int(0.9 * (len(ms) - 1))]:.1f} | {hits[name]}/{in_view} |', flush=True)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('--repeats', type=int, default=20, help='looks at each frame')
    parser.add_argument('--lens', choices=LENSES, action='append',
                        help='only this lens (again for more); both by default')
    args = parser.parse_args(argv)
    print('| eyes | look | median ms | p90 ms | faces found |\n|---|---|---|---|---|')
    with tempfile.TemporaryDirectory() as folder:
        for lens in args.lens or LENSES:
            for size in SIZES:
                bench(size, lens, max(1, args.repeats), Path(folder))


if __name__ == '__main__':
    main()
