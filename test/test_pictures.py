"""Pictures on the world: the world file's picture keys and their checks, the bundled
PNGs, and MiRo's eyes seeing an AprilTag poster where the camera model says, in both
renderers, through the pinhole and MiRo's lens."""
import math
import struct
import zlib
from importlib.resources import files

import cv2
import numpy as np
import pytest

from miro_ball.bench import make_pictures
from miro_ball.controller.detection import BallDetector
from miro_ball.miro.camera_model import CameraModel, LENSES
from miro_ball.miro.kc import CAML, CAMR, KinematicChain, WORLD
from miro_sim_bullet.physics.world import SimWorld
from miro_sim_bullet.render.cameras import Cameras
from miro_sim_bullet.render.renderer import probe_egl
from miro_sim_bullet.scene.png import png_size, PngError, SIGNATURE
from miro_sim_bullet.scene.world_checks import bundled_pictures, MAX_PICTURE_BYTES, PICTURE_LIFT
from miro_sim_bullet.scene.world_file import load_world
from miro_sim_bullet.scene.world_model import bundled_folder, WorldError

RENDERERS = ['tiny', pytest.param('egl', marks=pytest.mark.skipif(
    not probe_egl()[0], reason='EGL unavailable: ' + probe_egl()[1]))]
TAG = 'apriltag36h11_0.png'
CORNER_TOLERANCE_PX = 3.0


def write(tmp_path, text, name='pictures.toml'):
    path = tmp_path / name
    path.write_text(text)
    return str(path)


def png_bytes(image):
    ok, data = cv2.imencode('.png', image)
    assert ok
    return data.tobytes()


def chunk(kind, payload):
    return (struct.pack('>I', len(payload)) + kind + payload
            + struct.pack('>I', zlib.crc32(kind + payload)))


def normal(corners):
    c = np.asarray(corners)
    n = np.cross(c[1] - c[0], c[3] - c[0])
    return n / np.linalg.norm(n)


# ------------------------------------------------------------------ the bundled pictures

def test_bundled_pictures_are_what_make_pictures_draws():
    """The committed PNGs can be made again: python -m miro_ball.bench.make_pictures. The
    tags exactly; the drawings but for anti-aliased edges (OpenCV versions differ there)."""
    drawn = make_pictures.pictures()
    assert sorted(drawn) == bundled_pictures()
    folder = bundled_folder() / 'pictures'
    for name, image in drawn.items():
        stored = cv2.imdecode(np.frombuffer((folder / name).read_bytes(), np.uint8),
                              cv2.IMREAD_UNCHANGED)
        assert stored.shape == image.shape, name
        if name.startswith('apriltag'):
            assert np.array_equal(stored, image), name
        else:
            assert np.abs(stored.astype(int) - image).mean() < 1.0, name


@pytest.mark.parametrize('name', bundled_pictures())
def test_no_bundled_picture_looks_like_the_ball_to_the_controller(name):
    image = cv2.imread(str(bundled_folder() / 'pictures' / name), cv2.IMREAD_COLOR)
    assert BallDetector().mask(image).sum() == 0


@pytest.mark.parametrize('tag_id', make_pictures.TAG_IDS)
def test_tag_posters_are_found_by_opencvs_apriltag_detector(tag_id):
    image = cv2.imread(str(bundled_folder() / 'pictures' / f'apriltag36h11_{tag_id}.png'),
                       cv2.IMREAD_GRAYSCALE)
    corners, ids = detect_tags(image)
    assert ids == [tag_id]
    side = image.shape[0]
    inset = make_pictures.tag_fraction() * side - 0.5  # pixel centres count from 0
    want = [(inset, inset), (side - 1 - inset, inset), (side - 1 - inset, side - 1 - inset),
            (inset, side - 1 - inset)]  # top-left, top-right, bottom-right, bottom-left
    assert np.abs(corners[0] - want).max() < 1.5


# ------------------------------------------------------------------------- world files

def test_bundled_worlds_have_their_pictures():
    """The arena's logo panels (and posters) on the inner faces of its ring; the pet
    shop's posters inside the pen. Every picture lies 1 mm in front of its panel, facing
    into the arena, upright."""
    arena = load_world('miro')
    names = [p.image.rsplit('/', 1)[1] for p in arena.pictures]
    assert names.count('miro_lab_logo.png') == 10 and len(names) == 12
    assert names[1] == TAG and names[10] == 'face_poster.png'
    for picture in arena.pictures:
        corners = np.asarray(picture.corners)
        centre = corners.mean(axis=0)
        assert picture.source == 'ring[0]'
        assert math.hypot(*centre[:2]) == pytest.approx(1.21 - 0.005 - PICTURE_LIFT)
        assert normal(corners) @ -np.append(centre[:2], 0) > 0.999 * np.linalg.norm(centre[:2])
        assert corners[3][2] > corners[0][2]  # top-left above bottom-left
    cube = load_world('cube')
    assert [p.image for p in cube.pictures] == [arena.pictures[0].image] * 12
    shop = load_world('petshop')
    assert sorted(p.image.rsplit('/', 1)[1] for p in shop.pictures) == [TAG, 'face_poster.png']
    for picture in shop.pictures:
        assert normal(picture.corners) == pytest.approx((-1, 0, 0))
        assert np.asarray(picture.corners)[:, 0] == pytest.approx(0.975 - 0.005 - 0.001)


@pytest.mark.parametrize('face, normal_want, right_want', [
    ('+x', (1, 0, 0), (0, 1, 0)), ('-x', (-1, 0, 0), (0, -1, 0)),
    ('+y', (0, 1, 0), (-1, 0, 0)), ('-y', (0, -1, 0), (1, 0, 0)),
    ('+z', (0, 0, 1), (0, -1, 0))])
def test_a_box_face_picture_faces_out_upright_and_fills_the_face_at_its_aspect(
        tmp_path, face, normal_want, right_want):
    """A box 0.4 x 0.6 x 0.2 m turned 90 deg: the square tag poster on each face, as big
    as the face holds, centred, 1 mm out; seen from outside, the picture's right is the
    viewer's right and its top is up (+z; on the top face, towards the box's +x)."""
    path = write(tmp_path, f'[[box]]\nposition = [1, 2, 0.5]\nsize = [0.4, 0.6, 0.2]\n'
                           f'yaw = {math.pi / 2}\npicture = "{TAG}"\npicture_face = "{face}"\n')
    world = load_world(path)
    picture, = world.pictures
    assert picture.source == 'box[0]' and world.shapes[0].source == 'box[0]'
    assert picture.image.endswith('/pictures/' + TAG)
    turn = np.array([[0, -1, 0], [1, 0, 0], [0, 0, 1]])  # the box's yaw
    corners = np.asarray(picture.corners)
    assert normal(corners) == pytest.approx(turn @ normal_want, abs=1e-9)
    right = corners[1] - corners[0]
    assert right / np.linalg.norm(right) == pytest.approx(turn @ right_want, abs=1e-9)
    up = corners[3] - corners[0]
    side = min(0.2, 0.4 if face[1] == 'y' else 0.6) if face != '+z' else 0.4
    assert np.linalg.norm(right) == pytest.approx(side) and np.linalg.norm(up) == \
        pytest.approx(side)
    half = {'x': 0.2, 'y': 0.3, 'z': 0.1}[face[1]]
    centre = np.array([1, 2, 0.5]) + turn @ (np.asarray(normal_want) * (half + 0.001))
    assert corners.mean(axis=0) == pytest.approx(centre)


def test_wall_sides_panels_sizes_and_paths(tmp_path):
    """A wall's pictures on its left or right, one per panel or '' for none, a size of
    their own; a path from the world file's folder; a bare name next to it."""
    (tmp_path / 'art').mkdir()
    mine = png_bytes(np.full((10, 20, 3), 200, np.uint8))
    (tmp_path / 'art' / 'mine.png').write_bytes(mine)
    (tmp_path / 'beside.png').write_bytes(mine)
    path = write(tmp_path, '[[wall]]\nfrom = [0, 0]\nto = [2, 0]\ncount = 3\n'
                           'picture = ["art/mine.png", "", "beside.png"]\n'
                           'picture_side = "right"\npicture_size = [0.4, 0.2]\n')
    world = load_world(path)
    assert [p.image for p in world.pictures] == [str(tmp_path / 'art' / 'mine.png'),
                                                 str(tmp_path / 'beside.png')]
    for picture, x in zip(world.pictures, (0.0, 2.0)):
        corners = np.asarray(picture.corners)
        assert normal(corners) == pytest.approx((0, -1, 0))  # right of the row along +x
        assert corners.mean(axis=0) == pytest.approx((x, -0.006, 0.15))
        assert np.linalg.norm(corners[1] - corners[0]) == pytest.approx(0.4)
        assert np.linalg.norm(corners[3] - corners[0]) == pytest.approx(0.2)
    left = load_world(write(tmp_path, '[[wall]]\nfrom = [0, 0]\nto = [2, 0]\ncount = 1\n'
                                      f'picture = "{TAG}"\n', 'left.toml'))
    assert normal(left.pictures[0].corners) == pytest.approx((0, 1, 0))  # the default


def big_png(tmp_path, name, side):
    path = tmp_path / name
    path.write_bytes(png_bytes(np.full((side, side), 128, np.uint8)))
    return path


@pytest.mark.parametrize('text, expected', [
    ('[[box]]\nsize = [1, 1, 1]\npicture = "nowhere.png"\n',
     "box[0].picture: no picture 'nowhere.png' in the allowed folders: bundled "
     '(face_photo.png, face_poster.png, miro_lab_logo.png, apriltag36h11_N.png (N = 0, 1, 2, '
     "3)), the world's folder, world_folders"),
    ('[[box]]\nsize = [1, 1, 1]\npicture = 3\n',
     'box[0].picture: must be the file name of a PNG, got 3'),
    ('[[box]]\nsize = [1, 1, 1]\npicture = ""\n', 'box[0].picture: must be the file name'),
    (f'[[box]]\nsize = [1, 1, 1]\npicture = "{"x" * 5000}"\n', 'box[0].picture: no picture'),
    (f'[[box]]\nsize = [1, 1, 1]\npicture = "{TAG}"\npicture_face = "-z"\n',
     "box[0].picture_face: must be one of +x, -x, +y, -y, +z, got '-z'"),
    (f'[[box]]\nsize = [1, 1, 1]\nmass = 1\npicture = "{TAG}"\n',
     'box[0].picture: only a static box (mass 0) can carry a picture'),
    (f'[[box]]\nsize = [1, 1, 1]\npicture = "{TAG}"\npicture_size = [1.5, 1]\n',
     'box[0].picture_size: [1.5, 1] does not fit on the face, 1 x 1 m'),
    (f'[[box]]\nsize = [1, 1, 1]\npicture = "{TAG}"\npicture_size = [0, 1]\n',
     'box[0].picture_size: every extent must be > 0'),
    ('[[box]]\nsize = [1, 1, 1]\npicture_face = "+x"\n', "box[0].picture_face: needs 'picture'"),
    (f'[[sphere]]\nradius = 1\npicture = "{TAG}"\n', "sphere[0]: unknown key 'picture'"),
    (f'[[ring]]\ncount = 3\npicture = ["{TAG}"]\n',
     'ring[0].picture: a list must name a picture (or "") for each of the 3 panels, got 1'),
    (f'[[ring]]\ncount = 2\npicture = ["{TAG}", 7]\n', 'ring[0].picture[1]: must be the file'),
    (f'[[ring]]\npicture = "{TAG}"\npicture_side = "left"\n',
     "ring[0].picture_side: must be inside or outside, got 'left'"),
    (f'[[wall]]\nfrom = [0, 0]\ncount = 1\npicture = "{TAG}"\npicture_side = "inside"\n',
     "wall[0].picture_side: must be left or right, got 'inside'"),
    ('[[ring]]\npicture_size = [0.1, 0.1]\n', "ring[0].picture_size: needs 'picture'"),
])
def test_picture_mistakes_name_the_file_and_the_key(tmp_path, text, expected):
    path = write(tmp_path, text, 'broken.toml')
    with pytest.raises(WorldError) as err:
        load_world(path)
    message = str(err.value)
    assert message.startswith(path + ': ') and expected in message, message
    assert '\n' not in message and len(message) - len(path) < 240


def corrupt_pngs():
    good = png_bytes(np.random.default_rng(0).integers(0, 255, (40, 60, 3), np.uint8))
    flipped = bytearray(good)
    flipped[70] ^= 0xFF  # inside the image data: its checksum fails
    header = struct.pack('>IIBBBBB', 10, 10, 8, 2, 0, 0, 0)
    bomb = (SIGNATURE + chunk(b'IHDR', header)
            + chunk(b'IDAT', zlib.compress(bytes(50_000_000))) + chunk(b'IEND', b''))
    huge = (SIGNATURE + chunk(b'IHDR', struct.pack('>IIBBBBB', 5000, 40, 8,
                                                                    2, 0, 0, 0))
            + chunk(b'IEND', b''))
    return {
        'text.png': (b'hello, not a picture\n', 'not a PNG file'),
        'truncated.png': (good[:len(good) // 2], 'corrupt PNG: truncated'),
        'flipped.png': (bytes(flipped), 'corrupt PNG: bad checksum'),
        'bomb.png': (bomb, 'corrupt PNG: image data of the wrong length'),
        'huge.png': (huge, '5000x40 pixels, more than 2048 a side'),
        'empty.png': (b'', 'not a PNG file'),
    }


def test_an_unreadable_or_corrupt_png_fails_the_world_at_load_in_one_line(tmp_path):
    for name, (data, why) in corrupt_pngs().items():
        (tmp_path / name).write_bytes(data)
        path = write(tmp_path, f'[[box]]\nsize = [1, 1, 1]\npicture = "{name}"\n', 'w.toml')
        with pytest.raises(WorldError) as err:
            load_world(path)
        message = str(err.value)
        assert message.startswith(f"{path}: box[0].picture: '{name}': {why}"), message
        assert '\n' not in message
    (tmp_path / 'big.png').write_bytes(SIGNATURE + bytes(MAX_PICTURE_BYTES))
    with pytest.raises(WorldError, match=r"box\[0\].picture: 'big.png' is larger than 8000000"):
        load_world(write(tmp_path, '[[box]]\nsize = [1, 1, 1]\npicture = "big.png"\n'))
    (tmp_path / 'folder.png').mkdir()
    with pytest.raises(WorldError, match=r"box\[0\].picture: no picture 'folder.png'"):
        load_world(write(tmp_path, '[[box]]\nsize = [1, 1, 1]\npicture = "folder.png"\n'))


def test_a_worlds_pictures_have_a_pixel_budget(tmp_path):
    """Four different 2048 x 2048 pictures are more than 16 million pixels: refused; the
    same picture on many panels counts once."""
    names = [big_png(tmp_path, f'big{k}.png', 2048).name for k in range(4)]
    once = write(tmp_path, f'[[ring]]\ncount = 40\npicture = "{names[0]}"\n', 'once.toml')
    assert len(load_world(once).pictures) == 40
    listed = ', '.join(f'"{n}"' for n in names)
    path = write(tmp_path, f'[[ring]]\ncount = 4\npicture = [{listed}]\n', 'four.toml')
    with pytest.raises(WorldError, match=r"ring\[0\].picture\[3\]: the world's pictures have "
                                         r'more than 16000000 pixels in all'):
        load_world(path)


def test_png_size_reads_the_size_of_what_opencv_writes():
    for shape in ((3, 5), (7, 9, 3), (4, 6, 4)):
        assert png_size(png_bytes(np.zeros(shape, np.uint8)), 64) == (shape[1], shape[0])
    with pytest.raises(PngError, match='more than 4 a side'):
        png_size(png_bytes(np.zeros((3, 5), np.uint8)), 4)


# ---------------------------------------------------------------------------- the eyes

def detect_tags(gray):
    """(corners (n, 4, 2) top-left, top-right, bottom-right, bottom-left; ids) of the
    tag36h11 markers OpenCV's ArUco detector finds, corners refined to sub-pixels."""
    parameters = cv2.aruco.DetectorParameters()
    parameters.cornerRefinementMethod = cv2.aruco.CORNER_REFINE_SUBPIX
    detector = cv2.aruco.ArucoDetector(
        cv2.aruco.getPredefinedDictionary(cv2.aruco.DICT_APRILTAG_36h11), parameters)
    corners, ids, _ = detector.detectMarkers(gray)
    if ids is None:
        return np.empty((0, 4, 2)), []
    return np.array(corners).reshape(-1, 4, 2), [int(i) for i in ids.ravel()]


def tag_corners(picture):
    """World points of the tag's outer corners (top-left, top-right, bottom-right,
    bottom-left, as ArUco orders them) on a tag poster."""
    bl, br, tr, tl = np.asarray(picture.corners)
    f = make_pictures.tag_fraction()

    def at(u, v):  # u across from the left, v down from the top, 0..1
        return tl + u * (tr - tl) + v * (bl - tl)
    return np.array([at(f, f), at(1 - f, f), at(1 - f, 1 - f), at(f, 1 - f)])


@pytest.fixture(params=RENDERERS)
def tag_world(request, tmp_path):
    """MiRo at the origin facing a tag poster 0.6 m ahead on a board, and its Cameras."""
    path = write(tmp_path, '[ground]\nheight = 0.0\ncolour = [0.6, 0.6, 0.58]\n'
                           '[[box]]\nposition = [0.6, 0.0, 0.3]\nsize = [0.02, 0.3, 0.3]\n'
                           f'colour = [0.5, 0.45, 0.4]\npicture = "{TAG}"\n'
                           'picture_face = "-x"\npicture_size = [0.25, 0.25]\n')
    world = SimWorld(load_world(path))
    cameras = Cameras(world, request.param, log=lambda _: None)
    yield world, cameras
    cameras.close()
    world.close()


def predicted_corners(robot, camera, eye, points):
    """Pixels of world points in ``eye`` by the camera model and MiRo's kinematic chain
    (the joints as sensors/kinematic_joints reports them, the robot where it stands)."""
    kc = KinematicChain(robot.sensors.kinematic_positions)
    x, y, z, yaw = robot.ground_truth()
    kc.set_pose(x, y, yaw, z)
    u, v = camera.points_to_pixels(kc, eye, points, frame=WORLD)
    return np.stack([u, v], axis=-1)


@pytest.mark.parametrize('lens', LENSES)
def test_each_eye_finds_the_tag_where_the_camera_model_predicts(tag_world, lens):
    world, cameras = tag_world
    world.run(0.5)  # MiRo settles on its wheels
    camera = CameraModel(640, 360, lens=lens)
    picture, = world.description.pictures
    for eye, side in ((CAML, 1), (CAMR, -1)):
        rgb, = cameras.render_eyes([(world.robot, side)], camera)
        corners, ids = detect_tags(cv2.cvtColor(rgb, cv2.COLOR_RGB2GRAY))
        assert ids == [0], (eye, ids)
        want = predicted_corners(world.robot, camera, eye, tag_corners(picture))
        assert np.isfinite(want).all()
        error = np.linalg.norm(corners[0] - want, axis=1)
        assert error.max() < CORNER_TOLERANCE_PX, (eye, corners[0], want)


@pytest.mark.parametrize('kind', RENDERERS)
def test_miro_sees_the_arenas_tag_and_the_pictures_survive_a_reset(kind):
    """In the default world the left eye finds tag 0 on the panel 30 deg to the left,
    and after a world reset the eyes see exactly what they saw."""
    world = SimWorld('miro')
    cameras = Cameras(world, kind, log=lambda _: None)
    try:
        camera = CameraModel(640, 360)
        first, = cameras.render_eyes([(world.robot, 1)], camera)
        world.run(0.5)
        rgb, = cameras.render_eyes([(world.robot, 1)], camera)
        corners, ids = detect_tags(cv2.cvtColor(rgb, cv2.COLOR_RGB2GRAY))
        assert ids == [0]
        tag = world.description.pictures[1]
        want = predicted_corners(world.robot, camera, CAML, tag_corners(tag))
        assert np.linalg.norm(corners[0] - want, axis=1).max() < CORNER_TOLERANCE_PX
        world.reset()
        again, = cameras.render_eyes([(world.robot, 1)], camera)
        assert np.array_equal(first, again)
    finally:
        cameras.close()
        world.close()


@pytest.mark.parametrize('renderer', RENDERERS)
def test_a_picture_is_read_once_and_a_file_put_in_its_place_later_is_never_read(tmp_path,
                                                                                 renderer):
    """The renderers and the scene's markers drew and sent the file again by its path: a
    link put there after the check showed (and published) any file."""
    from miro_sim_bullet.ros.scene import SceneMarkers

    pictures = files('miro_sim_bullet.worlds') / 'pictures'
    mine = tmp_path / 'mine.png'
    mine.write_bytes((pictures / TAG).read_bytes())
    path = write(tmp_path, '[ground]\nheight = 0.0\n[[box]]\nposition = [0.6, 0.0, 0.3]\n'
                           'size = [0.02, 0.3, 0.3]\npicture = "mine.png"\n'
                           'picture_face = "-x"\npicture_size = [0.25, 0.25]\n')
    description = load_world(path)
    checked = mine.read_bytes()
    mine.unlink()
    mine.symlink_to(pictures / 'apriltag36h11_1.png')  # tag 1 where tag 0 was checked
    world = SimWorld(description)
    cameras = Cameras(world, renderer, log=lambda _: None)
    try:
        rgb, = cameras.render_eyes([(world.robot, 1)], CameraModel(640, 360))
        assert detect_tags(cv2.cvtColor(rgb, cv2.COLOR_RGB2GRAY))[1] == [0]
        sent = [m for m in SceneMarkers(world).layout().markers if m.ns == 'picture']
        assert [bytes(m.texture.data) for m in sent] == [checked]
    finally:
        cameras.close()
        world.close()
