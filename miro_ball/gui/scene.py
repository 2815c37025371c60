"""The world as the page draws it: the simulator's scene markers, the robots and /tf, as JSON.

The simulator publishes its world as visualization_msgs Markers (/miro_sim/scene), each
robot's body as its URDF (<robot>/robot_description) and every frame on /tf and
/tf_static, as RViz reads them. The page gets the same in a form three.js takes at once:
a marker, and each primitive <visual> of a URDF, becomes
{"id": "<ns>/<id>", "ns", "frame", "kind", "p", "q", "scale", "colour", ...} and a
frame {"<robot>/<link>": {"parent": "<robot>/<its parent>", "p", "q"}}. SceneState keeps the newest of
each with a sequence number, so each page is sent only what changed since it last heard,
and a page that turns its world view on gets everything. Pictures' PNGs are kept here by key and
served by the web server at TEXTURE_URL; the markers carry the URL, not the bytes.

Nothing here needs ROS: messages are read by their fields, so tests build them freely.
"""
import json
import math
import re

from miro_ball.miro.interface import WORLD_FRAME, frame_id
from miro_ball.miro.rotations import rpy_quaternion
from miro_ball.miro.urdf import parse_visuals, UrdfError

# visualization_msgs/Marker's numbers (the message's own constants; checked in the test).
CUBE, SPHERE, CYLINDER, CUBE_LIST, TRIANGLE_LIST = 1, 2, 3, 6, 11
ADD, DELETE, DELETEALL = 0, 2, 3
KIND = {CUBE: 'box', SPHERE: 'sphere', CYLINDER: 'cylinder', CUBE_LIST: 'cube_list',
        TRIANGLE_LIST: 'picture'}

TEXTURE_PREFIX = 'embedded://'
TEXTURE_KEY = re.compile(r'[A-Za-z0-9_][A-Za-z0-9_.-]{0,99}\Z')  # safe in a URL path
TEXTURE_URL = '/texture/{key}.png'
MAX_TEXTURE_BYTES = 8 << 20
MAX_TEXTURES = 256
MAX_POINTS = 20000  # a LED strip is a few points, a picture 6
MAX_MARKERS = 10000
MAX_FRAMES = 5000
MAX_NAME = 256  # characters of a namespace or frame name
MAX_REMOVED = 10000  # deletions remembered for pages that are behind
# Rounding: a tenth of a millimetre and about 0.001 degree are beyond what a page can show,
# and a number of six digits is a third of the bytes of Python's seventeen.
DIGITS_POSITION, DIGITS_ROTATION, DIGITS_COLOUR = 4, 5, 3


class SceneRejected(ValueError):
    """A marker or transform the page cannot draw; the text says why, in one line."""


def _finite(values, digits, what):
    out = []
    for value in values:
        value = float(value)
        if not math.isfinite(value):
            raise SceneRejected(f'{what} is not finite')
        out.append(round(value, digits))
    return out


def _name(value, what):
    if not isinstance(value, str) or len(value) > MAX_NAME:
        raise SceneRejected(f'{what} is not a name of at most {MAX_NAME} characters')
    return value


def _frame(value, what):
    return _name(value, what).lstrip('/')  # tf2 names have no leading slash


def _xyz(v, digits=DIGITS_POSITION, what='a point'):
    return _finite((v.x, v.y, v.z), digits, what)


def _quaternion(q):
    x, y, z, w = _finite((q.x, q.y, q.z, q.w), 9, 'an orientation')
    norm = math.sqrt(x * x + y * y + z * z + w * w)
    if norm < 1e-9:  # RViz reads all zeros as "no rotation"
        return [0.0, 0.0, 0.0, 1.0]
    return [round(c / norm, DIGITS_ROTATION) for c in (x, y, z, w)]


def _rgba(c):
    return [min(max(v, 0.0), 1.0) for v in _finite((c.r, c.g, c.b, c.a), DIGITS_COLOUR,
                                                     'a colour')]


def marker_id(marker):
    return f'{marker.ns}/{marker.id}'


def texture_key(resource):
    """The key of an 'embedded://<key>.png' texture, or SceneRejected."""
    if not resource.startswith(TEXTURE_PREFIX) or not resource.endswith('.png'):
        raise SceneRejected(f'texture {resource[:60]!r} is not {TEXTURE_PREFIX}<key>.png')
    key = resource[len(TEXTURE_PREFIX):-len('.png')]
    if not TEXTURE_KEY.match(key):
        raise SceneRejected(f'texture key {key[:60]!r}: letters, digits, _ . - only')
    return key


def marker_json(marker):
    """(the page's dict of one ADD marker, (texture key, PNG bytes) or None), or
    SceneRejected."""
    kind = KIND.get(marker.type)
    if kind is None:
        raise SceneRejected(f'marker type {marker.type} is not drawn (only '
                            f'{", ".join(KIND.values())})')
    pose = marker.pose
    out = {'id': marker_id(marker), 'ns': _name(marker.ns, 'ns'),
           'frame': _frame(marker.header.frame_id, 'frame_id'), 'kind': kind,
           'p': _xyz(pose.position), 'q': _quaternion(pose.orientation),
           'scale': _xyz(marker.scale, what='a scale'), 'colour': _rgba(marker.color)}
    if marker.text:  # a sound's name: the page stops it by name
        out['text'] = _name(marker.text, 'text')
    texture = None
    if kind in ('cube_list', 'picture'):
        if len(marker.points) > MAX_POINTS:
            raise SceneRejected(f'{len(marker.points)} points (at most {MAX_POINTS})')
        out['points'] = [_xyz(point) for point in marker.points]
        if marker.colors:
            if len(marker.colors) != len(marker.points):
                raise SceneRejected(f'{len(marker.colors)} colours for '
                                    f'{len(marker.points)} points')
            out['colours'] = [_rgba(c) for c in marker.colors]
    if kind == 'picture':
        if len(marker.points) % 3:
            raise SceneRejected(f'a triangle list of {len(marker.points)} points')
        if marker.texture_resource:
            if len(marker.uv_coordinates) != len(marker.points):
                raise SceneRejected(f'{len(marker.uv_coordinates)} texture coordinates for '
                                    f'{len(marker.points)} points')
            out['uv'] = [_finite((c.u, c.v), 5, 'a texture coordinate')
                         for c in marker.uv_coordinates]
            key = texture_key(marker.texture_resource)
            out['texture'] = TEXTURE_URL.format(key=key)
            data = bytes(marker.texture.data)
            if data:  # a marker may refer to a texture an earlier one carried
                if 'png' not in marker.texture.format.lower() or \
                        not data.startswith(b'\x89PNG\r\n\x1a\n'):
                    raise SceneRejected(f'texture {key!r} is not a PNG')
                if len(data) > MAX_TEXTURE_BYTES:
                    raise SceneRejected(f'texture {key!r} of {len(data)} bytes')
                texture = (key, data)
    if marker.text:
        out['link'] = _name(marker.text, 'text')
    return out, texture


DESCRIPTION_ID = 'urdf-'  # the ids of a robot's shapes from its robot_description


def description_markers(robot, text):
    """The page's dicts of the shapes of a robot's robot_description (URDF text), each in
    its link's frame '<robot>/<link>' (which /tf moves), or SceneRejected. The same form as
    a marker's, so the page draws them as it draws the scene: a box by its size, a sphere
    and a cylinder by their diameters, as RViz scales markers."""
    try:
        visuals = parse_visuals(text)
    except UrdfError as err:
        raise SceneRejected(str(err)) from None
    out = []
    for k, (link, shape, rgba) in enumerate(visuals):
        if shape.kind == 'box':
            scale = shape.size
        elif shape.kind == 'sphere':
            scale = (2 * shape.size[0],) * 3
        else:
            radius, length = shape.size
            scale = (2 * radius, 2 * radius, length)
        out.append({'id': f'{robot}/{DESCRIPTION_ID}{k}', 'ns': robot,
                    'frame': frame_id(robot, _name(link, 'link')), 'kind': shape.kind,
                    'p': _finite(shape.xyz, DIGITS_POSITION, 'a point'),
                    'q': [round(c, DIGITS_ROTATION) for c in rpy_quaternion(*shape.rpy)],
                    'scale': _finite(scale, DIGITS_POSITION, 'a scale'),
                    'colour': [min(max(c, 0.0), 1.0) for c in
                               _finite(rgba, DIGITS_COLOUR, 'a colour')],
                    'link': link})
    return out


def tf_frames(transforms):
    """[(child, {"parent", "p", "q"})] of a TFMessage's transforms, each checked (frame
    names, finite numbers); a bad one raises SceneRejected."""
    out = []
    for t in transforms:
        child = _frame(t.child_frame_id, 'child_frame_id')
        parent = _frame(t.header.frame_id, 'frame_id') or WORLD_FRAME
        if not child or child == parent:
            raise SceneRejected(f'the transform of {child[:40]!r} has no frame of its own')
        out.append((child, {'parent': parent, 'p': _xyz(t.transform.translation),
                            'q': _quaternion(t.transform.rotation)}))
    return out


class SceneState:
    """The newest of every marker and transform, each with the sequence number of its last
    change, so a page is sent what changed since the number it last got."""

    def __init__(self):
        self.seq = 0
        self.markers = {}  # id: (seq, JSON text)
        self.removed = {}  # id: seq of its removal
        self.frames = {}  # child: (seq, JSON text of {"parent", "p", "q"})
        self.textures = {}  # key: PNG bytes

    def _next(self):
        self.seq += 1
        return self.seq

    def apply_markers(self, markers, warn):
        """Take a MarkerArray's markers; warn(key, text) about each one not drawn.
        Returns how many changed. A DELETEALL followed by the same markers again (a
        publisher re-sending its whole layout) changes only what differs."""
        changed = 0
        doomed = set()  # deleted by a DELETEALL unless added again in this array
        for marker in markers:
            try:
                if marker.action == DELETEALL:
                    doomed.update(i for i in self.markers
                                  if not marker.ns or i.startswith(marker.ns + '/'))
                    continue
                doomed.discard(marker_id(marker))
                changed += self._apply_marker(marker)
            except SceneRejected as err:
                warn(f'marker:{marker_id(marker)[:80]}',
                     f'scene marker {marker_id(marker)[:80]!r} not drawn: {err}')
            except (TypeError, ValueError, AttributeError) as err:  # garbage from the graph
                warn('marker', f'a malformed scene marker ignored: {err}')
        for i in doomed:
            changed += self._remove(i)
        return changed

    def _apply_marker(self, marker):
        if marker.action == DELETE:
            return self._remove(marker_id(marker))
        if marker.action != ADD:  # ADD and MODIFY are one number
            raise SceneRejected(f'action {marker.action} unknown')
        out, texture = marker_json(marker)
        if texture is not None:
            key, data = texture
            if key not in self.textures and len(self.textures) >= MAX_TEXTURES:
                raise SceneRejected(f'more than {MAX_TEXTURES} textures')
            self.textures[key] = data
        return self._set_marker(out)

    def _set_marker(self, out):
        """Keep one marker's dict; 1 if it changed, else 0."""
        text = json.dumps(out, separators=(',', ':'))
        old = self.markers.get(out['id'])
        if old is not None and old[1] == text:
            return 0  # re-published unchanged: nothing to send
        if old is None and len(self.markers) >= MAX_MARKERS:
            raise SceneRejected(f'more than {MAX_MARKERS} markers')
        self.markers[out['id']] = (self._next(), text)
        self.removed.pop(out['id'], None)
        return 1

    def _remove(self, marker_id_):
        if self.markers.pop(marker_id_, None) is None:
            return 0
        self.removed[marker_id_] = self._next()
        if len(self.removed) > MAX_REMOVED:  # the oldest: a page that far behind is gone
            del self.removed[next(iter(self.removed))]
        return 1

    def apply_description(self, robot, text, warn):
        """Take a robot's robot_description: its shapes replace those it had. Returns how
        many markers changed."""
        try:
            markers = description_markers(robot, text)
        except SceneRejected as err:
            warn(f'description:{robot}', f'the robot_description of {robot} not drawn: {err}')
            return 0
        prefix = f'{robot}/{DESCRIPTION_ID}'
        ids = {m['id'] for m in markers}
        changed = sum(self._remove(i) for i in list(self.markers)
                      if i.startswith(prefix) and i not in ids)
        for out in markers:
            changed += self._set_marker(out)
        return changed

    def apply_tf(self, transforms, warn):
        """Take a TFMessage's transforms; returns how many frames changed."""
        try:
            frames = tf_frames(transforms)
        except SceneRejected as err:
            warn('tf', f'a /tf message not shown: {err}')
            return 0
        except (TypeError, ValueError, AttributeError) as err:  # garbage from the graph
            warn('tf', f'a malformed /tf message ignored: {err}')
            return 0
        changed = 0
        for child, out in frames:
            text = json.dumps(out, separators=(',', ':'))
            old = self.frames.get(child)
            if old is not None and old[1] == text:
                continue
            if old is None and len(self.frames) >= MAX_FRAMES:
                warn('frames', f'more than {MAX_FRAMES} frames: {child[:40]!r} not shown')
                continue
            self.frames[child] = (self._next(), text)
            changed += 1
        return changed

    def scene_message(self, since):
        """JSON text of {"t": "scene"} with the markers changed and removed after seq
        ``since``, or None when nothing changed; since None: the whole scene."""
        full = since is None
        markers = [text for seq, text in self.markers.values() if full or seq > since]
        removed = [] if full else [i for i, seq in self.removed.items() if seq > since]
        if not (full or markers or removed):
            return None
        return ('{"t":"scene","markers":[' + ','.join(markers) + '],"removed":'
                + json.dumps(removed) + '}')

    def tf_message(self, since):
        """JSON text of {"t": "tf"} with the frames changed after seq ``since`` (None: all),
        or None when there are none."""
        frames = [json.dumps(child) + ':' + text for child, (seq, text) in self.frames.items()
                  if since is None or seq > since]
        if not frames:
            return None
        return '{"t":"tf","frames":{' + ','.join(frames) + '}}'
