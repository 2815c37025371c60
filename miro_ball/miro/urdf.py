"""MiRo's URDF, written from the one body description (body.py): robot_description.

Link and joint names carry no robot's name (robot_state_publisher's convention); the
frames on /tf do ('<robot>/<link>'). Inertias are those of each link's first shape as a
solid of the link's mass: enough for a viewer, and the simulator takes its own from the
collision shapes.
"""
import math
from xml.etree import ElementTree
from xml.sax.saxutils import quoteattr

from miro_ball.miro.body import BOX, COLOURS, CYLINDER, FIXED, LINKS, ROOT, Shape, SPHERE

ROBOT_NAME = 'miro_e'  # the model's name in the URDF, not a robot's


def _numbers(values):
    return quoteattr(' '.join(f'{float(v):.10g}' for v in values))


def _origin(xyz, rpy):
    return f'<origin xyz={_numbers(xyz)} rpy={_numbers(rpy)}/>'


def _geometry(shape):
    if shape.kind == BOX:
        return f'<box size={_numbers(shape.size)}/>'
    if shape.kind == CYLINDER:
        radius, length = shape.size
        return f'<cylinder radius="{radius:.10g}" length="{length:.10g}"/>'
    return f'<sphere radius="{shape.size[0]:.10g}"/>'


def inertia(link):
    """(ixx, iyy, izz) of the link's first shape as a solid of its mass, about its centre."""
    shapes = link.collisions or link.visuals
    m = link.mass
    if not shapes or m <= 0.0:
        return (0.0, 0.0, 0.0)
    shape = shapes[0]
    if shape.kind == BOX:
        x, y, z = shape.size
        return (m * (y * y + z * z) / 12, m * (x * x + z * z) / 12, m * (x * x + y * y) / 12)
    if shape.kind == CYLINDER:
        r, h = shape.size
        side = m * (3 * r * r + h * h) / 12
        return (side, side, m * r * r / 2)
    r = shape.size[0]
    return (0.4 * m * r * r,) * 3


def _link(link):
    parts = [f'  <link name={quoteattr(link.name)}>']
    if link.mass > 0.0:
        ixx, iyy, izz = inertia(link)
        parts.append(f'    <inertial>{_origin(link.com, (0, 0, 0))}<mass value="{link.mass:.10g}"/>'
                     f'<inertia ixx="{ixx:.10g}" ixy="0" ixz="0" iyy="{iyy:.10g}" iyz="0" '
                     f'izz="{izz:.10g}"/></inertial>')
    for tag, shapes in (('visual', link.visuals), ('collision', link.collisions)):
        for shape in shapes:
            material = (f'<material name={quoteattr(shape.colour)}/>' if tag == 'visual'
                        else '')
            parts.append(f'    <{tag}>{_origin(shape.xyz, shape.rpy)}<geometry>'
                         f'{_geometry(shape)}</geometry>{material}</{tag}>')
    parts.append('  </link>')
    return parts


def _joint(link):
    parts = [f'  <joint name={quoteattr(link.joint)} type="{link.kind}">',
             f'    <parent link={quoteattr(link.parent)}/><child link={quoteattr(link.name)}/>',
             f'    {_origin(link.xyz, link.rpy)}']
    if link.kind != FIXED:
        parts.append(f'    <axis xyz={_numbers(link.axis)}/>')
    if link.limits is not None:
        lo, hi = link.limits
        parts.append(f'    <limit lower="{lo:.10g}" upper="{hi:.10g}" effort="1" velocity="10"/>')
    parts.append('  </joint>')
    return parts


def urdf():
    """The URDF of MiRo-E as XML text."""
    lines = ['<?xml version="1.0"?>', f'<robot name="{ROBOT_NAME}">']
    lines += [f'  <material name={quoteattr(name)}><color rgba={_numbers(rgba)}/></material>'
              for name, rgba in COLOURS.items()]
    lines.append(f'  <link name={quoteattr(ROOT)}/>')
    for link in LINKS:
        lines += _link(link) + _joint(link)
    lines.append('</robot>')
    return '\n'.join(lines) + '\n'


MAX_URDF_BYTES = 1 << 20  # ours is ~15 KB; a robot_description beyond this is refused
MAX_VISUALS = 2000


class UrdfError(ValueError):
    """A robot_description that cannot be drawn; the text says why, in one line."""


def _floats(text, count, what):
    try:
        values = [float(v) for v in (text or '').split()]
    except ValueError:
        raise UrdfError(f'{what} {text[:40]!r} is not {count} numbers') from None
    if len(values) != count or not all(math.isfinite(v) for v in values):
        raise UrdfError(f'{what} {str(text)[:40]!r} is not {count} finite numbers')
    return tuple(values)


def _size(geometry):
    """(kind, size) of a <geometry>'s box, sphere or cylinder, or None (a mesh: not drawn)."""
    for kind, attributes in ((BOX, ('size',)), (SPHERE, ('radius',)),
                             (CYLINDER, ('radius', 'length'))):
        element = geometry.find(kind)
        if element is not None:
            if kind == BOX:
                return kind, _floats(element.get('size'), 3, 'a box size')
            return kind, tuple(_floats(element.get(a), 1, f'a {kind} {a}')[0]
                               for a in attributes)
    return None


def parse_visuals(text):
    """[(link name, Shape, rgba)] of every primitive <visual> of a URDF's text (meshes are
    skipped), or UrdfError in one line. Colours come from the visual's material, by name
    from the robot's materials; grey when it has none."""
    if not isinstance(text, str) or len(text) > MAX_URDF_BYTES:
        raise UrdfError(f'a URDF of at most {MAX_URDF_BYTES} characters is needed')
    try:
        robot = ElementTree.fromstring(text)
    except ElementTree.ParseError as err:
        raise UrdfError(f'not XML: {err}') from None
    if robot.tag != 'robot':
        raise UrdfError(f'the root element is <{robot.tag[:40]}>, not <robot>')
    named = {}
    for material in robot.iter('material'):
        colour = material.find('color')
        if material.get('name') and colour is not None:
            named[material.get('name')] = _floats(colour.get('rgba'), 4, 'a colour')
    out = []
    for link in robot.findall('link'):
        for visual in link.findall('visual'):
            geometry = visual.find('geometry')
            shape = _size(geometry) if geometry is not None else None
            if shape is None:
                continue
            origin = visual.find('origin')
            xyz = _floats(origin.get('xyz', '0 0 0'), 3, 'an origin') if origin is not None \
                else (0.0, 0.0, 0.0)
            rpy = _floats(origin.get('rpy', '0 0 0'), 3, 'an origin') if origin is not None \
                else (0.0, 0.0, 0.0)
            material = visual.find('material')
            rgba = (0.6, 0.6, 0.6, 1.0)
            if material is not None:
                inline = material.find('color')
                rgba = _floats(inline.get('rgba'), 4, 'a colour') if inline is not None \
                    else named.get(material.get('name'), rgba)
            out.append((str(link.get('name', ''))[:256], Shape(*shape, xyz, rpy), rgba))
            if len(out) > MAX_VISUALS:
                raise UrdfError(f'more than {MAX_VISUALS} visuals')
    return out
