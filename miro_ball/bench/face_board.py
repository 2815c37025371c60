"""The den world's face board (a 0.4 m photographed face) anywhere around MiRo, facing it,
and what MiRo's eyes see of it: for the face benchmark (face_bench.py) and the face tests
(test_faces)."""
import math
import sys

import cv2

BOARD_HEIGHT = 0.3  # m, the centre of the board and of its photo


def face_centre(azimuth_deg, distance):
    """(x, y, z) of the photo's centre, MiRo at the origin facing +x."""
    a = math.radians(azimuth_deg)
    return distance * math.cos(a), distance * math.sin(a), BOARD_HEIGHT


def face_board_world(folder, azimuth_deg, distance=1.0):
    """Path of a world file (written in folder, a pathlib.Path): the board azimuth_deg to
    MiRo's left (negative: right), distance m from it, its photo turned to MiRo; the ball
    far away."""
    x, y, _ = face_centre(azimuth_deg, distance)
    path = folder / f'face_{azimuth_deg:+g}deg_{distance:g}m.toml'
    path.write_text(f'''description = "a face board {azimuth_deg:g} deg left of MiRo, {distance:g} m"
[ground]
height = 0.0
colour = [0.6, 0.6, 0.58]

[ball]
position = [-30.0, 0.0]

[[box]]
name = "face_board"
position = [{x:.4f}, {y:.4f}, {BOARD_HEIGHT}]
yaw = {math.radians(azimuth_deg):.6f}
size = [0.02, 0.5, 0.6]
colour = [0.80, 0.78, 0.72]
picture = "face_photo.png"
picture_face = "-x"
picture_size = [0.4, 0.45]
''')
    return str(path)


def eye_frames(world, camera):
    """[(side, BGR frame, eye position, eye rotation)] of both eyes of the world's robot
    (side +1 left, -1 right) through a CameraModel, once the world has settled 0.3 s (the
    renderer's name to stderr, off the benchmark's table)."""
    from miro_sim_bullet.render.cameras import Cameras

    world.run(0.3)
    cameras = Cameras(world, 'auto', log=lambda line: print(line, file=sys.stderr))
    try:
        frames = cameras.render_eyes([(world.robot, +1), (world.robot, -1)], camera)
    finally:
        cameras.close()
    return [(side, cv2.cvtColor(rgb, cv2.COLOR_RGB2BGR), *world.robot.eye_pose(side))
            for side, rgb in zip((+1, -1), frames)]
