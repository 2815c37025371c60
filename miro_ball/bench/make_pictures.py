"""Draws the bundled pictures of worlds/pictures/: ``python -m miro_ball.bench.make_pictures``.

Every picture is our own, drawn here with OpenCV, so the PNGs in the repository can be
made again and checked (test_pictures compares them with what this script draws):

- ``apriltag36h11_<id>.png``: AprilTag tag36h11 markers 0..3 (OpenCV's
  DICT_APRILTAG_36h11), each with a white border two cells wide (detectors need one;
  with one, OpenCV's takes the poster's edge and the tag's for one candidate and
  misses the tag);
- ``miro_lab_logo.png``: the arena's panel logo, the wall panel's 0.65 x 0.30 shape;
- ``face_poster.png``: a simple drawn face, for demos that look for one;
- ``face_photo.png``: a photographed face for real face detectors (demo mode's): the face of
  scikit-image's ``astronaut`` (a NASA portrait, public domain), cropped, no blue in it.

No blue anywhere: the controller looks for the blue ball.
"""
import argparse
from pathlib import Path

import cv2
import numpy as np

TAG_IDS = (0, 1, 2, 3)
TAG_CELL_PX = 32  # a tag is 8 cells (6 data + the black border) and the white border
TAG_WHITE_CELLS = 2
LOGO_SIZE = (1040, 480)  # width, height: the panel's 0.65 x 0.30 m
FACE_SIZE = (480, 560)

# BGR
INK = (40, 40, 40)
ORANGE = (20, 120, 230)
PANEL = (184, 199, 204)  # the panel's colour (0.80, 0.78, 0.72)
WHITE = (255, 255, 255)


def apriltag(tag_id):
    """The tag36h11 marker ``tag_id`` with its white border, greyscale."""
    dictionary = cv2.aruco.getPredefinedDictionary(cv2.aruco.DICT_APRILTAG_36h11)
    marker = cv2.aruco.generateImageMarker(dictionary, tag_id, 8 * TAG_CELL_PX, borderBits=1)
    pad = TAG_WHITE_CELLS * TAG_CELL_PX
    return cv2.copyMakeBorder(marker, pad, pad, pad, pad, cv2.BORDER_CONSTANT, value=255)


def tag_fraction():
    """Where the tag's outer (black) corners sit in its picture, as a share of its side
    from the picture's edge: detectors report those corners."""
    return TAG_WHITE_CELLS / (8 + 2 * TAG_WHITE_CELLS)


def logo():
    """A MiRo head in a circle beside the words 'MiRo lab', on the panel's colour."""
    width, height = LOGO_SIZE
    image = np.full((height, width, 3), PANEL, np.uint8)
    cv2.rectangle(image, (24, 24), (width - 25, height - 25), WHITE, -1, cv2.LINE_AA)
    cv2.rectangle(image, (24, height - 80), (width - 25, height - 56), ORANGE, -1)
    centre = (230, 220)
    cv2.circle(image, centre, 150, ORANGE, -1, cv2.LINE_AA)
    # The head: a rounded muzzle, two tall ears, two eyes.
    for side in (-1, 1):
        ear = np.array([(centre[0] + side * 40, centre[1] - 40),
                        (centre[0] + side * 110, centre[1] - 130),
                        (centre[0] + side * 100, centre[1] - 10)], np.int32)
        cv2.fillConvexPoly(image, ear, WHITE, cv2.LINE_AA)
    cv2.ellipse(image, (centre[0], centre[1] + 20), (95, 80), 0, 0, 360, WHITE, -1,
                cv2.LINE_AA)
    for side in (-1, 1):
        cv2.circle(image, (centre[0] + side * 40, centre[1] + 5), 16, INK, -1, cv2.LINE_AA)
    cv2.ellipse(image, (centre[0], centre[1] + 60), (22, 14), 0, 0, 360, INK, -1,
                cv2.LINE_AA)
    cv2.putText(image, 'MiRo', (440, 230), cv2.FONT_HERSHEY_DUPLEX, 4.2, INK, 10,
                cv2.LINE_AA)
    cv2.putText(image, 'lab', (450, 350), cv2.FONT_HERSHEY_DUPLEX, 3.0, ORANGE, 8,
                cv2.LINE_AA)
    return image


def face():
    """A face seen from the front: skin, hair, two eyes, brows, nose and a smile."""
    width, height = FACE_SIZE
    image = np.full((height, width, 3), (225, 235, 240), np.uint8)
    skin, hair, iris = (150, 185, 225), (30, 50, 80), (40, 70, 110)
    cx, cy = width // 2, height // 2 + 20
    cv2.ellipse(image, (cx, cy - 40), (190, 210), 0, 180, 360, hair, -1, cv2.LINE_AA)
    for side in (-1, 1):  # ears
        cv2.ellipse(image, (cx + side * 165, cy), (30, 50), 0, 0, 360, skin, -1, cv2.LINE_AA)
    cv2.ellipse(image, (cx, cy), (160, 210), 0, 0, 360, skin, -1, cv2.LINE_AA)
    cv2.ellipse(image, (cx, cy - 150), (150, 70), 0, 180, 360, hair, -1, cv2.LINE_AA)
    for side in (-1, 1):
        eye = (cx + side * 65, cy - 40)
        cv2.ellipse(image, eye, (36, 20), 0, 0, 360, WHITE, -1, cv2.LINE_AA)
        cv2.circle(image, eye, 16, iris, -1, cv2.LINE_AA)
        cv2.circle(image, eye, 7, INK, -1, cv2.LINE_AA)
        cv2.ellipse(image, (eye[0], eye[1] - 38), (42, 14), 0, 200, 340, hair, 9,
                    cv2.LINE_AA)
    cv2.ellipse(image, (cx, cy + 35), (24, 14), 0, 0, 180, (110, 140, 190), 6, cv2.LINE_AA)
    cv2.ellipse(image, (cx, cy + 95), (70, 35), 0, 10, 170, (60, 60, 170), 9, cv2.LINE_AA)
    return image


FACE_PHOTO_CROP = (slice(40, 210), slice(150, 300))  # rows, columns of astronaut()


def face_photo():
    """The astronaut's face, BGR (scikit-image ships the photo)."""
    from skimage import data

    return cv2.cvtColor(data.astronaut()[FACE_PHOTO_CROP], cv2.COLOR_RGB2BGR)


def pictures():
    """{file name: BGR or greyscale image} of every bundled picture."""
    drawn = {f'apriltag36h11_{tag_id}.png': apriltag(tag_id) for tag_id in TAG_IDS}
    drawn['miro_lab_logo.png'] = logo()
    drawn['face_poster.png'] = face()
    drawn['face_photo.png'] = face_photo()
    return drawn


def main(argv=None):
    parser = argparse.ArgumentParser(prog='python -m miro_ball.bench.make_pictures',
                                     description=__doc__.split('\n\n')[0])
    parser.add_argument('--out', default=str(Path(__file__).resolve().parents[2] / 'worlds'
                                             / 'pictures'),
                        help='folder to write them to (default: the source tree\'s '
                             'worlds/pictures)')
    args = parser.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    for name, image in pictures().items():
        cv2.imwrite(str(out / name), image, [cv2.IMWRITE_PNG_COMPRESSION, 9])
        print(out / name)


if __name__ == '__main__':
    main()
