"""Pictures of MiRo's body as the simulator builds it: ``python -m miro_ball.bench.model_pictures``.

Draws the one body description (miro.body) through the physics body and the eyes'
renderer, from the front, the side and three-quarters behind, the tail wagged to one side
and the left eyelid half shut, and writes them side by side (docs/pictures/miro_model.png
by default), so the docs show what the other robots' eyes, the URDF and the world view show.
"""
import argparse
import math
from pathlib import Path

import cv2
import numpy as np

from miro_ball.miro.body import COSMETIC_JOINTS
from miro_ball.miro.camera_model import Intrinsics
from miro_ball.miro.constants import KIN_CALIB_RAD
from miro_sim_bullet.bullet import pybullet as pb
from miro_sim_bullet.physics import model as rb
from miro_sim_bullet.render.renderer import Renderer, view_matrix_from_pose

SIZE_PX = (480, 480)
HFOV_DEG = 32.0
DISTANCE_M = 0.85
TARGET = np.array([-0.03, 0.0, 0.17])  # about the middle of MiRo, floor to ear tips
VIEWS = (('front', 0.0, 12.0), ('side', 90.0, 8.0), ('three-quarter', 215.0, 22.0))
FLOOR = (0.62, 0.60, 0.56, 1.0)
FLOOR_HALF_M = 20.0
POSE = {'wag': 0.25, 'eyelid_l': 0.5, 'droop': 0.3}  # cosmetic 0..1 for a livelier picture


def _look_at(azimuth_deg, elevation_deg):
    """A camera DISTANCE_M from TARGET at that bearing (0: in front of MiRo), looking at it."""
    az, el = math.radians(azimuth_deg), math.radians(elevation_deg)
    offset = DISTANCE_M * np.array([math.cos(el) * math.cos(az), math.cos(el) * math.sin(az),
                                    math.sin(el)])
    forward = -offset / np.linalg.norm(offset)
    left = np.cross((0.0, 0.0, 1.0), forward)
    left /= np.linalg.norm(left)
    return TARGET + offset, np.column_stack((forward, left, np.cross(forward, left)))


def draw():
    """The three views side by side, RGB."""
    client = pb.connect(pb.DIRECT)
    try:
        kw = {'physicsClientId': client}
        ground = pb.createVisualShape(pb.GEOM_BOX, halfExtents=(FLOOR_HALF_M, FLOOR_HALF_M, 0.01), rgbaColor=FLOOR, **kw)
        pb.createMultiBody(0, -1, ground, (0, 0, -0.01), **kw)
        robot = rb.MiroModel(client)
        robot.place(0.0, 0.0, 0.0)
        joints = dict(zip(('lift', 'yaw', 'pitch'), KIN_CALIB_RAD[1:]))
        for name, link in zip(('lift', 'yaw', 'pitch'), (rb.NECK, rb.GIMBAL, rb.HEAD)):
            pb.resetJointState(robot.body_id, link, joints[name], **kw)
        robot.pose_drawn([lo + POSE.get(name, 1 / 3) * (hi - lo)
                          for name, (lo, hi) in zip(COSMETIC_JOINTS, rb.COSMETIC_RANGES)])
        renderer = Renderer(client, log=lambda line: None)
        intrinsics = Intrinsics.from_hfov(*SIZE_PX, HFOV_DEG)
        images = []
        for label, azimuth, elevation in VIEWS:
            image = np.ascontiguousarray(
                renderer.render(view_matrix_from_pose(*_look_at(azimuth, elevation)), intrinsics))
            cv2.putText(image, label, (12, 28), cv2.FONT_HERSHEY_SIMPLEX, 0.8, (40, 40, 40), 2)
            images.append(image)
        renderer.close()
        return np.hstack(images)
    finally:
        pb.disconnect(client)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--out', default='docs/pictures/miro_model.png',
                        help='PNG to write (default %(default)s)')
    args = parser.parse_args(argv)
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    cv2.imwrite(args.out, cv2.cvtColor(draw(), cv2.COLOR_RGB2BGR))
    print(f'wrote {args.out}')


if __name__ == '__main__':
    main()
