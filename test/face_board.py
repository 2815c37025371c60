"""The den world's face board (a 0.4 m photographed face) anywhere around MiRo, facing it,
for the tests that look for faces (test_faces, test_animal)."""
import math

BOARD_HEIGHT = 0.3  # m, the centre of the board and of its photo


def face_centre(azimuth_deg, distance):
    """(x, y, z) of the photo's centre, MiRo at the origin facing +x."""
    a = math.radians(azimuth_deg)
    return distance * math.cos(a), distance * math.sin(a), BOARD_HEIGHT


def face_board_world(folder, azimuth_deg, distance=1.0):
    """Path of a world file (written in folder): the board azimuth_deg to MiRo's left
    (negative: right), distance m from it, its photo turned to MiRo; the ball far away."""
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
