"""The scene as the page gets it: markers, robot_description and /tf -> JSON, and only what
changed."""
import json
import math

import pytest
from geometry_msgs.msg import Point, TransformStamped
from std_msgs.msg import ColorRGBA
from visualization_msgs.msg import Marker, UVCoordinate

from miro_ball.gui import scene as s
from miro_ball.miro.interface import DEFAULT_ROBOT_NAME, WORLD_FRAME
from miro_ball.miro.urdf import parse_visuals, urdf

PNG = b'\x89PNG\r\n\x1a\n' + b'\x00' * 20  # the page decodes it; the server only keeps it


def marker(ns='ball', id_=0, type_=Marker.SPHERE, xyz=(1.0, 2.0, 0.05), frame=WORLD_FRAME,
           action=Marker.ADD, **fields):
    m = Marker(ns=ns, id=id_, type=type_, action=action, **fields)
    m.header.frame_id = frame
    m.pose.position.x, m.pose.position.y, m.pose.position.z = xyz
    m.pose.orientation.w = 1.0
    m.scale.x = m.scale.y = m.scale.z = 0.1
    m.color = ColorRGBA(r=0.0, g=0.0, b=1.0, a=1.0)
    return m


def picture(key='logo'):
    m = marker('picture', 3, Marker.TRIANGLE_LIST, (0.0, 0.0, 0.0))
    corners = [(0, 0, 0), (1, 0, 0), (1, 0, 1), (0, 0, 1)]
    uv = [(0, 1), (1, 1), (1, 0), (0, 0)]
    order = [0, 1, 2, 0, 2, 3]  # two triangles
    m.points = [Point(x=float(x), y=float(y), z=float(z)) for x, y, z in
                (corners[i] for i in order)]
    m.uv_coordinates = [UVCoordinate(u=float(uv[i][0]), v=float(uv[i][1])) for i in order]
    m.texture_resource = f'embedded://{key}.png'
    m.texture.format = 'png'
    m.texture.data = list(PNG)
    return m


FRAMES = ('miro02/odom', 'miro02/base_link', 'miro02/body', 'miro02/neck')


def transforms(xyz=(0.0, 0.0, 0.0), parent=WORLD_FRAME):
    """/tf's transforms of a chain of frames under ``parent``."""
    out = []
    for i, child in enumerate(FRAMES):
        t = TransformStamped(child_frame_id=child)
        t.header.frame_id = parent if i == 0 else FRAMES[i - 1]
        v = t.transform.translation
        v.x, v.y, v.z = xyz[0] + i * 0.01, xyz[1], xyz[2]
        t.transform.rotation.w = 1.0
        out.append(t)
    return out


class Warnings(list):
    def __call__(self, key, message):
        self.append(message)


def test_the_marker_numbers_are_visualization_msgs_own():
    assert (s.CUBE, s.SPHERE, s.CYLINDER, s.CUBE_LIST, s.TRIANGLE_LIST) == (
        Marker.CUBE, Marker.SPHERE, Marker.CYLINDER, Marker.CUBE_LIST, Marker.TRIANGLE_LIST)
    assert (s.ADD, s.DELETE, s.DELETEALL) == (Marker.ADD, Marker.DELETE, Marker.DELETEALL)


def test_a_ball_becomes_a_sphere_where_the_simulator_put_it():
    out, texture = s.marker_json(marker())
    assert out == {'id': 'ball/0', 'ns': 'ball', 'frame': WORLD_FRAME, 'kind': 'sphere',
                   'p': [1.0, 2.0, 0.05], 'q': [0.0, 0.0, 0.0, 1.0], 'scale': [0.1, 0.1, 0.1],
                   'colour': [0.0, 0.0, 1.0, 1.0]}
    assert texture is None


def test_a_robots_link_says_which_link_it_is_and_its_frame():
    m = marker(DEFAULT_ROBOT_NAME, 5, Marker.CUBE, frame=f'{DEFAULT_ROBOT_NAME}/head',
               text='head')
    out, _ = s.marker_json(m)
    assert out['kind'] == 'box' and out['link'] == 'head'
    assert out['frame'] == f'{DEFAULT_ROBOT_NAME}/head'


def test_leds_keep_a_colour_per_cube():
    m = marker(DEFAULT_ROBOT_NAME, 9, Marker.CUBE_LIST, text='leds')
    m.points = [Point(x=0.1 * i) for i in range(6)]
    m.colors = [ColorRGBA(r=1.0, g=0.0, b=0.0, a=1.0)] * 5 + [ColorRGBA(r=2.0, a=-1.0)]
    out, _ = s.marker_json(m)
    assert out['kind'] == 'cube_list' and len(out['points']) == 6
    assert out['colours'][0] == [1.0, 0.0, 0.0, 1.0]
    assert out['colours'][5] == [1.0, 0.0, 0.0, 0.0]  # clamped to 0..1


def test_a_picture_carries_its_texture_coordinates_and_the_url_of_its_png():
    state = s.SceneState()
    assert state.apply_markers([picture('arena_logo')], Warnings()) == 1
    scene = json.loads(state.scene_message(None))
    (out,) = scene['markers']
    assert out['kind'] == 'picture' and out['texture'] == '/texture/arena_logo.png'
    assert len(out['points']) == len(out['uv']) == 6
    assert state.textures['arena_logo'] == PNG


def test_a_page_gets_the_whole_scene_then_only_what_moved_or_went():
    state, warn = s.SceneState(), Warnings()
    state.apply_markers([marker('ball'), marker('box1', type_=Marker.CUBE),
                         marker('wall', 7, Marker.CUBE)], warn)
    full = json.loads(state.scene_message(None))
    assert full['t'] == 'scene' and {m['id'] for m in full['markers']} == \
        {'ball/0', 'box1/0', 'wall/7'} and full['removed'] == []
    seen = state.seq
    # The simulator re-publishes what did not move: nothing to send.
    state.apply_markers([marker('box1', type_=Marker.CUBE)], warn)
    assert state.scene_message(seen) is None
    state.apply_markers([marker('ball', xyz=(1.5, 2.0, 0.05)),
                         marker('box1', action=Marker.DELETE)], warn)
    change = json.loads(state.scene_message(seen))
    assert [m['id'] for m in change['markers']] == ['ball/0'] and change['removed'] == ['box1/0']
    assert change['markers'][0]['p'] == [1.5, 2.0, 0.05]
    assert {m['id'] for m in json.loads(state.scene_message(None))['markers']} == \
        {'ball/0', 'wall/7'}
    state.apply_markers([marker('wall', action=Marker.DELETEALL)], warn)
    assert [m['id'] for m in json.loads(state.scene_message(None))['markers']] == ['ball/0']
    assert warn == []


def test_a_layout_sent_again_after_a_deleteall_sends_only_what_differs():
    state, warn = s.SceneState(), Warnings()
    layout = [marker('wall', 1, Marker.CUBE), marker('wall', 2, Marker.CUBE),
              marker('leds', 0, Marker.CUBE)]
    state.apply_markers([marker(action=Marker.DELETEALL, ns='')] + layout, warn)
    seen = state.seq
    state.apply_markers([marker(action=Marker.DELETEALL, ns='')] + layout, warn)
    assert state.scene_message(seen) is None  # the same layout: nothing to send
    lit = marker('leds', 0, Marker.CUBE)
    lit.color.r = 1.0
    state.apply_markers([marker(action=Marker.DELETEALL, ns=''), layout[0], lit], warn)
    change = json.loads(state.scene_message(seen))
    assert [m['id'] for m in change['markers']] == ['leds/0']
    assert change['removed'] == ['wall/2']  # not in the layout any more


@pytest.mark.parametrize('spoil, why', [
    (lambda m: setattr(m.pose.position, 'x', math.nan), 'not finite'),
    (lambda m: setattr(m, 'type', Marker.ARROW), 'not drawn'),
    (lambda m: setattr(m, 'action', 7), 'action'),
    (lambda m: setattr(m, 'ns', 'n' * 300), 'name'),
])
def test_a_marker_the_page_cannot_draw_is_left_out_with_a_warning(spoil, why):
    bad = marker('bad')
    spoil(bad)
    state, warn = s.SceneState(), Warnings()
    assert state.apply_markers([bad, marker('ball')], warn) == 1
    assert [m['id'] for m in json.loads(state.scene_message(None))['markers']] == ['ball/0']
    assert len(warn) == 1 and why in warn[0]


@pytest.mark.parametrize('spoil', [
    lambda m: setattr(m, 'texture_resource', 'embedded://../../etc/passwd.png'),
    lambda m: setattr(m, 'texture_resource', 'file:///etc/passwd.png'),
    lambda m: setattr(m.texture, 'data', list(b'GIF89a' + b'\x00' * 10)),
    lambda m: setattr(m, 'uv_coordinates', m.uv_coordinates[:3]),
    lambda m: setattr(m, 'points', m.points[:4]),
])
def test_a_picture_with_a_bad_texture_is_left_out(spoil):
    bad = picture()
    spoil(bad)
    state, warn = s.SceneState(), Warnings()
    assert state.apply_markers([bad], warn) == 0
    assert state.textures == {} and len(warn) == 1


def test_too_many_points_are_refused():
    m = marker(type_=Marker.CUBE_LIST)
    m.points = [Point()] * (s.MAX_POINTS + 1)
    with pytest.raises(s.SceneRejected):
        s.marker_json(m)


def test_tf_frames_keep_their_parents_and_only_changes_go_out():
    state, warn = s.SceneState(), Warnings()
    assert state.apply_tf(transforms(), warn) == len(FRAMES)
    frames = json.loads(state.tf_message(None))['frames']
    assert set(frames) == set(FRAMES)
    assert frames['miro02/odom'] == {'parent': WORLD_FRAME, 'p': [0.0, 0.0, 0.0],
                                     'q': [0.0, 0.0, 0.0, 1.0]}
    assert frames['miro02/body']['parent'] == 'miro02/base_link'
    seen = state.seq
    assert state.apply_tf(transforms(), warn) == 0
    assert state.tf_message(seen) is None  # nothing moved: nothing to send
    state.apply_tf(transforms(xyz=(0.5, 0.0, 0.0)), warn)
    assert len(json.loads(state.tf_message(seen))['frames']) == len(FRAMES)
    assert warn == []


def test_bad_transforms_are_refused_with_a_warning():
    state, warn = s.SceneState(), Warnings()
    bad = transforms()
    bad[0].transform.rotation.w = math.inf
    assert state.apply_tf(bad, warn) == 0
    looped = transforms()
    looped[1].header.frame_id = looped[1].child_frame_id  # its own parent
    assert state.apply_tf(looped, warn) == 0
    assert state.tf_message(None) is None and len(warn) == 2


def test_a_robot_is_drawn_from_its_robot_description():
    state, warn = s.SceneState(), Warnings()
    visuals = parse_visuals(urdf())
    assert state.apply_description('miro02', urdf(), warn) == len(visuals)
    markers = [json.loads(text) for _, text in state.markers.values()]
    assert {m['frame'] for m in markers} == {f'miro02/{link}' for link, _, _ in visuals}
    assert {m['ns'] for m in markers} == {'miro02'}
    assert {'head', 'body', 'ear_l', 'ear_r', 'tail', 'eyelid_l'} <= {m['link'] for m in markers}
    spheres = [m for m in markers if m['kind'] == 'sphere']
    assert spheres and all(len(set(m['scale'])) == 1 for m in spheres)  # by their diameter
    assert state.apply_description('miro02', urdf(), warn) == 0  # again: nothing changed
    assert warn == []


@pytest.mark.parametrize('text', [
    'not xml <', '<html/>', 'x' * (2 << 20),
    '<robot><link name="a"><visual><geometry><box size="1 nan 1"/></geometry></visual>'
    '</link></robot>',
    '<robot><link name="a"><visual><geometry><sphere radius="big"/></geometry></visual>'
    '</link></robot>',
])
def test_a_bad_robot_description_is_refused_in_one_line(text):
    state, warn = s.SceneState(), Warnings()
    assert state.apply_description('miro02', text, warn) == 0
    assert len(warn) == 1 and '\n' not in warn[0] and state.markers == {}


def test_orientations_are_unit_quaternions_and_numbers_short():
    m = marker(xyz=(0.123456789, 0.0, 0.0))
    m.pose.orientation.z, m.pose.orientation.w = 2.0, 2.0
    out, _ = s.marker_json(m)
    assert out['q'] == [0.0, 0.0, pytest.approx(math.sqrt(0.5), abs=1e-5),
                        pytest.approx(math.sqrt(0.5), abs=1e-5)]
    assert out['p'][0] == 0.1235
    m.pose.orientation.z = m.pose.orientation.w = 0.0
    assert s.marker_json(m)[0]['q'] == [0.0, 0.0, 0.0, 1.0]  # all zeros: no rotation
