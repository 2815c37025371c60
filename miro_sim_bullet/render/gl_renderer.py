"""Our own OpenGL renderer: moderngl on a headless EGL context (Mesa llvmpipe, or a GPU).

PyBullet's getCameraImage spends most of its time copying pixels on the CPU and renders
one view per call. This renderer draws the client's visual shapes itself, from the poses
PyBullet reports, with instanced primitive meshes (box, sphere, cylinder; a capsule is a
cylinder and two spheres) and per-vertex lighting like the MDK worlds' (a sun from
SUN_DIRECTION, ambient 0.4), then the world's pictures (World.pictures) as textured quads lit
the same way, one texture per image file. Several views (both eyes of every robot) go into one
framebuffer, stacked vertically, and come back in one read-back. Each view draws only the
shapes whose bounding spheres reach into it (_visible): the same pixels, a quarter of the
vertices to shade.

Images follow the pinhole model of :func:`renderer.opengl_projection`. The projection is
flipped vertically so that the first row read back is the top row of the image: no copy.
"""
import collections
import functools
import importlib.util
import math
import os
import time
from dataclasses import dataclass

import cv2
import numpy as np

from miro_sim_bullet.render.visuals import client_visuals, MESHES, VisualsGroup
from miro_sim_bullet.scene.world_model import PICTURE_UV

SUN_DIRECTION = (-0.5, 0.5, -1.0)  # where the sun's light travels (MDK worlds)
AMBIENT = 0.4
DIFFUSE = 0.8
SKY = (0.7, 0.7, 0.7)  # Gazebo's background grey

_VERTEX_SHADER = """
#version 330
uniform mat4 view_projection;
uniform vec3 to_sun;
in vec3 in_position;
in vec3 in_normal;
in vec3 in_r0;
in vec3 in_r1;
in vec3 in_r2;
in vec3 in_offset;
in vec3 in_scale;
in vec3 in_colour;
out vec3 v_colour;
void main() {
    mat3 rotation = mat3(in_r0, in_r1, in_r2);
    vec3 world = rotation * (in_scale * in_position) + in_offset;
    vec3 normal = normalize(rotation * (in_normal / in_scale));
    float light = %(ambient)f + %(diffuse)f * max(dot(normal, to_sun), 0.0);
    v_colour = min(in_colour * light, vec3(1.0));
    gl_Position = view_projection * vec4(world, 1.0);
}
"""
_FRAGMENT_SHADER = """
#version 330
in vec3 v_colour;
out vec4 f_colour;
void main() {
    f_colour = vec4(v_colour, 1.0);
}
"""
_PICTURE_VERTEX_SHADER = """
#version 330
uniform mat4 view_projection;
in vec3 in_position;
in vec2 in_uv;
in float in_light;
out vec2 v_uv;
out float v_light;
void main() {
    v_uv = in_uv;
    v_light = in_light;
    gl_Position = view_projection * vec4(in_position, 1.0);
}
"""
_PICTURE_FRAGMENT_SHADER = """
#version 330
uniform sampler2D image;
in vec2 v_uv;
in float v_light;
out vec4 f_colour;
void main() {
    f_colour = vec4(min(texture(image, v_uv).rgb * v_light, vec3(1.0)), 1.0);
}
"""
# Per picture corner: position, texture coordinates, light (6 floats); a quad is the
# corners 0, 1, 2 and 0, 2, 3 (counter-clockwise from the front).
_QUAD = (0, 1, 2, 0, 2, 3)
# Bilinear in the nearest mipmap level, no anisotropy: on llvmpipe the arena's two 640x360
# eyes take 4.1 ms so (3.1 without pictures); trilinear 4.6, with 4x anisotropy 9.6.
PICTURE_FILTER = ('LINEAR_MIPMAP_NEAREST', 'LINEAR')
# Per instance: rotation columns, offset, scale, colour (18 floats).
_INSTANCE_FORMAT = '3f 3f 3f 3f 3f 3f/i'
_INSTANCE_ATTRIBUTES = ('in_r0', 'in_r1', 'in_r2', 'in_offset', 'in_scale', 'in_colour')


class GlUnavailable(RuntimeError):
    """No usable EGL/OpenGL 3.3 context here; str() is one line for the user."""


# --------------------------------------------------------------------------- meshes
# The unit primitives of visuals.MESHES, built in that order (box, sphere, cylinder).

def _box_mesh():
    """Unit cube centred on the origin: (vertices (n, 6) position+normal, indices)."""
    vertices, indices = [], []
    for axis in range(3):
        for sign in (1.0, -1.0):
            normal = np.zeros(3)
            normal[axis] = sign
            u = np.zeros(3)
            u[(axis + 1) % 3] = 1.0
            v = np.cross(normal, u)  # (u, v, normal) right-handed: counter-clockwise outside
            base = len(vertices)
            for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
                vertices.append([*(0.5 * (normal + a * u + b * v)), *normal])
            indices += [base, base + 1, base + 2, base, base + 2, base + 3]
    return np.array(vertices, 'f4'), np.array(indices, 'i4')


# Tessellation. llvmpipe shades every vertex of every view on the CPU: 24 x 16 spheres and
# 32-sided cylinders made the draw calls a third of the football pitch's drawing. At 16 x 12
# and 20 sides the outline strays at most 2 % of the radius from the circle (under a pixel
# for the ball a metre away) and the draw calls cost half as much (BENCHMARKS.md).
SPHERE_SLICES, SPHERE_STACKS = 16, 12
CYLINDER_SLICES = 20


def _sphere_mesh(slices=SPHERE_SLICES, stacks=SPHERE_STACKS):
    """Unit-radius sphere."""
    vertices = []
    for i in range(stacks + 1):
        polar = math.pi * i / stacks
        for j in range(slices + 1):
            azimuth = 2 * math.pi * j / slices
            n = (math.sin(polar) * math.cos(azimuth), math.sin(polar) * math.sin(azimuth),
                 math.cos(polar))
            vertices.append([*n, *n])
    indices = []
    for i in range(stacks):
        for j in range(slices):
            a, b = i * (slices + 1) + j, (i + 1) * (slices + 1) + j
            indices += [a, b, a + 1, a + 1, b, b + 1]
    return np.array(vertices, 'f4'), np.array(indices, 'i4')


def _cylinder_mesh(slices=CYLINDER_SLICES):
    """Unit radius, unit length along z, centred on the origin: side and two caps."""
    vertices, indices = [], []
    ring = [(math.cos(2 * math.pi * j / slices), math.sin(2 * math.pi * j / slices))
            for j in range(slices + 1)]
    for x, y in ring:  # side: pairs (bottom, top) with radial normals
        vertices += [[x, y, -0.5, x, y, 0.0], [x, y, 0.5, x, y, 0.0]]
    for j in range(slices):
        a = 2 * j
        indices += [a, a + 2, a + 1, a + 1, a + 2, a + 3]
    for z in (0.5, -0.5):
        centre = len(vertices)
        vertices.append([0.0, 0.0, z, 0.0, 0.0, 2 * z])
        for x, y in ring:
            vertices.append([x, y, z, 0.0, 0.0, 2 * z])
        for j in range(slices):
            a, b = centre + 1 + j, centre + 2 + j
            indices += [centre, a, b] if z > 0 else [centre, b, a]
    return np.array(vertices, 'f4'), np.array(indices, 'i4')


def _instances(visuals, colours=None):
    """(n, 18) float32 rows in _INSTANCE_FORMAT of the shapes of ``visuals`` (a
    render.visuals.VisualsGroup) as they are now (their colours ``colours`` if given)."""
    rot, offset = visuals.world_poses()
    rows = np.empty((len(visuals.mesh), 18), 'f4')
    rows[:, 0:9] = rot.transpose(0, 2, 1).reshape(-1, 9)  # columns of each rotation
    rows[:, 9:12] = offset
    rows[:, 12:15] = visuals.scale
    rows[:, 15:18] = (visuals.colours() if colours is None else colours)[:, :3]
    return rows


# Per mesh of visuals.MESHES, what a row's scale is multiplied by for a radius about its
# offset that holds the whole shape: the unit cube's corners (0.5 each way), the unit
# cylinder (radius 1, half a length each way); a sphere's is its largest scale (its mesh's
# corners lie on the unit sphere), which for a robot's head seen by its own eyes leaves
# out a third of the football pitch's drawing.
_BOUNDS = np.array([(0.5, 0.5, 0.5), (1.0, 1.0, 1.0), (1.0, 1.0, 0.5)])
_SPHERE = MESHES.index('sphere')
# How much further than its bound a shape must be from a side of the view to be left out: a
# shape drawn in float32 strays far less, and a shape kept that draws nothing costs only its
# vertices.
_CULL_MARGIN = 1e-3


def _visible(matrices, centres, radii):
    """(n, views): whether each sphere (centres (n, 3), radii (n,)) may show in each view of
    ``matrices`` (view_projection()'s bytes): False only for one wholly outside a side of
    the view, whose every triangle clipping would discard (the same pixels, without shading
    its vertices)."""
    rows = np.frombuffer(b''.join(matrices), 'f4').astype(float).reshape(-1, 4, 4)
    rows = rows.transpose(0, 2, 1)  # the matrices' rows: they are column-major
    # The six sides (a, b, c, d) of each view: (x, y, z) is inside when a x + b y + c z + d
    # >= 0 for all six (left, bottom, near, right, top, far).
    planes = np.concatenate([rows[:, 3:] + rows[:, :3], rows[:, 3:] - rows[:, :3]],
                            axis=1).reshape(-1, 4)
    norms = np.sqrt(np.einsum('ij,ij->i', planes[:, :3], planes[:, :3]))
    reach = centres @ planes[:, :3].T + planes[:, 3]  # (n, 6 * views)
    inside = reach >= -(radii[:, None] * (1 + _CULL_MARGIN) + _CULL_MARGIN) * norms
    return inside.reshape(len(centres), len(matrices), 6).all(axis=2)


def _picture_vertices(pictures, to_sun):
    """(n * 6, 6) float32 corners (xyz, uv, light) of the pictures' quads, lit by their
    normals as the shapes are."""
    rows = []
    for picture in pictures:
        corners = np.asarray(picture.corners, float)
        normal = np.cross(corners[1] - corners[0], corners[3] - corners[0])
        normal /= np.linalg.norm(normal) or 1.0
        light = AMBIENT + DIFFUSE * max(float(normal @ to_sun), 0.0)
        rows += [[*corners[k], *PICTURE_UV[k], light] for k in _QUAD]
    return np.array(rows, 'f4').reshape(-1, 6)


def _load_rgb(png):
    """The PNG's bytes (checked when the world was read) as RGB rows, top row first."""
    bgr = cv2.imdecode(np.frombuffer(png, np.uint8), cv2.IMREAD_COLOR)
    return None if bgr is None else np.ascontiguousarray(cv2.cvtColor(bgr, cv2.COLOR_BGR2RGB))


# ------------------------------------------------------------------------ the renderer

def probe_egl():
    """(ok, one-line reason): whether an EGL OpenGL 3.3 context can be made here. Decided
    once per process; a failing EGL raises in moderngl, it does not end the process."""
    ok, reason, _ = _probe()
    return ok, reason


def egl_device():
    """The GL_RENDERER of this process's EGL contexts (None if there are none)."""
    return _probe()[2]


@functools.lru_cache(maxsize=1)
def _probe():
    try:
        context = _create_context()
    except GlUnavailable as exc:
        return False, str(exc), None
    name = context.info['GL_RENDERER']
    context.release()
    return True, f'EGL works: {name}', name


@functools.lru_cache(maxsize=1)
def _triton_before_mesa():
    """PyTorch's compiler, triton, carries an LLVM of its own, and Mesa's software renderer
    (llvmpipe, where there is no GPU) puts another among the process's global symbols:
    triton imported after the first EGL context crashes the process (Stable-Baselines3
    imports it as it starts to train on a learning environment). Imported first, both work.
    Nothing happens where PyTorch is not installed; 0.1 s once where it is."""
    if importlib.util.find_spec('triton') is not None:
        importlib.import_module('triton')


def _create_context():
    _triton_before_mesa()
    try:
        import moderngl
    except ImportError as exc:
        raise GlUnavailable(f'moderngl is not installed ({exc})') from None
    # llvmpipe (no GPU) rasterises in the calling thread: as fast here as with its own
    # threads, and it leaves the other cores to physics and the controllers.
    os.environ.setdefault('LP_NUM_THREADS', '0')
    try:
        return moderngl.create_standalone_context(backend='egl', require=330)
    except Exception as exc:  # glcontext raises plain Exception with EGL's words
        reason = ' '.join(str(exc).split()) or type(exc).__name__
        raise GlUnavailable(f'no EGL OpenGL 3.3 context: {reason}') from None


@dataclass(frozen=True)
class SceneLayout:
    """What the GL renderer keeps of a world between frames: the mesh (index into
    visuals.MESHES) of every instance, static ones first, the static instances' rows (n, 18)
    and the pictures (World.pictures). Plain data: a process without PyBullet can draw
    from it, given each frame's moving rows."""

    meshes: np.ndarray
    static_rows: np.ndarray
    pictures: tuple


class ClientScene:
    """A PyBullet client's visual shapes as the GL renderer draws them: ``layout``, and
    moving_rows() of each instant. Make a new one after the client's bodies were rebuilt.

    ``colour_key``: None, the colours are read at every instant; or a function whose value
    changes whenever a shape's colour may have (a simulated world: its robots' LEDs), and
    they are read again only then (reading them was a third of moving_rows())."""

    def __init__(self, client_id, pictures=(), colour_key=None):
        self._colour_key = colour_key
        self._colours = self._key = None
        bodies = client_visuals(client_id)
        static = [b for b in bodies if b.static]
        self.moving = VisualsGroup(b for b in bodies if not b.static)
        self.layout = SceneLayout(
            meshes=np.concatenate([VisualsGroup(static).mesh, self.moving.mesh]),
            static_rows=_instances(VisualsGroup(static)), pictures=tuple(pictures))

    def moving_rows(self):
        """(n, 18) float32 rows of the moving instances as they are now."""
        key = None if self._colour_key is None else self._colour_key()
        if key is None or self._colours is None or key != self._key:
            self._colours, self._key = self.moving.colours(), key
        return _instances(self.moving, self._colours)


class GlBackend:
    """Draws a SceneLayout with the moving rows of an instant; set_layout() after the
    world was rebuilt (a reset)."""

    def __init__(self, layout, seconds=None):
        self.ctx = _create_context()
        self.device = self.ctx.info['GL_RENDERER']
        sun = -np.asarray(SUN_DIRECTION) / np.linalg.norm(SUN_DIRECTION)
        self.program = self.ctx.program(
            vertex_shader=_VERTEX_SHADER % {'ambient': AMBIENT, 'diffuse': DIFFUSE},
            fragment_shader=_FRAGMENT_SHADER)
        self.program['to_sun'].value = tuple(sun)
        self.to_sun = sun
        self.picture_program = self.ctx.program(vertex_shader=_PICTURE_VERTEX_SHADER,
                                                fragment_shader=_PICTURE_FRAGMENT_SHADER)
        self.meshes = []
        for build in (_box_mesh, _sphere_mesh, _cylinder_mesh):
            vertices, indices = build()
            self.meshes.append((self.ctx.buffer(vertices.tobytes()),
                                self.ctx.buffer(indices.tobytes())))
        self.max_height = self.ctx.info['GL_MAX_RENDERBUFFER_SIZE']
        self.max_height = min(self.max_height, self.ctx.info['GL_MAX_VIEWPORT_DIMS'][1])
        self._framebuffers = {}
        # Wall time per stage of drawing, summed (into the caller's counter, if given).
        self.seconds = collections.Counter() if seconds is None else seconds
        with self.ctx:
            self._read_layout(layout)

    def set_layout(self, layout):
        """Draw this SceneLayout from now on."""
        with self.ctx:
            self._read_layout(layout)

    def _read_layout(self, layout):
        self.layout = layout
        meshes = layout.meshes
        self._release_vaos()
        # Each view draws the instances of each mesh that may show in it (_visible): llvmpipe
        # shades every vertex drawn on the CPU, and most of a world is out of an eye's view.
        # The instance counts are fixed until the next rebuild: a buffer and vertex array
        # per mesh and view of a pass, made at its first use and rewritten every frame.
        self.by_mesh = [(index, np.flatnonzero(meshes == index))
                        for index in range(len(self.meshes))]
        self.by_mesh = [(index, chosen) for index, chosen in self.by_mesh if len(chosen)]
        self._bounds = _BOUNDS[meshes]
        self._spheres = meshes == _SPHERE
        self._slots = {}  # (mesh, view in the pass) -> (buffer, vertex array)
        self._read_pictures(layout.pictures)

    def _slot(self, mesh, view):
        """The instance buffer and vertex array of ``mesh`` for the pass's view ``view``."""
        if (mesh, view) not in self._slots:
            vertices, indices = self.meshes[mesh]
            count = np.count_nonzero(self.layout.meshes == mesh)
            buffer = self.ctx.buffer(reserve=count * 18 * 4)
            vao = self.ctx.vertex_array(
                self.program, [(vertices, '3f 3f', 'in_position', 'in_normal'),
                               (buffer, _INSTANCE_FORMAT, *_INSTANCE_ATTRIBUTES)],
                index_buffer=indices)
            self._slots[mesh, view] = buffer, vao
        return self._slots[mesh, view]

    def _read_pictures(self, pictures):
        """A texture per image file and a vertex array of every quad that shows it."""
        import moderngl
        by_image = {}
        for picture in pictures:
            by_image.setdefault(picture.image, []).append(picture)
        self.by_texture = []  # (texture, buffer, vertex array, its quads' bounds)
        picture_centres, picture_radii = [], []
        for pictures in by_image.values():
            rgb = _load_rgb(pictures[0].png)
            if rgb is None:
                continue
            texture = self.ctx.texture((rgb.shape[1], rgb.shape[0]), 3, rgb.tobytes(),
                                       alignment=1)
            texture.build_mipmaps()
            texture.filter = tuple(getattr(moderngl, name) for name in PICTURE_FILTER)
            texture.repeat_x = texture.repeat_y = False
            buffer = self.ctx.buffer(_picture_vertices(pictures, self.to_sun).tobytes())
            vao = self.ctx.vertex_array(self.picture_program,
                                        [(buffer, '3f 2f 1f', 'in_position', 'in_uv',
                                          'in_light')])
            self.by_texture.append((texture, buffer, vao,
                                    len(picture_centres) + np.arange(len(pictures))))
            corners = np.array([picture.corners for picture in pictures], float)
            picture_centres += list(corners.mean(axis=1))
            picture_radii += list(np.linalg.norm(corners - corners.mean(axis=1)[:, None],
                                                 axis=2).max(axis=1))
        # Each quad's bounding sphere, after the instances' in _visible's arguments.
        self._picture_bounds = (np.array(picture_centres).reshape(-1, 3),
                                np.array(picture_radii))

    def _release_vaos(self):
        for buffer, vao in getattr(self, '_slots', {}).values():
            vao.release()
            buffer.release()
        self._slots = {}
        for texture, buffer, vao, *_ in getattr(self, 'by_texture', ()):
            vao.release()
            buffer.release()
            texture.release()
        self.by_texture = []

    def _draw_view(self, view, matrix, rows, shown):
        """Draw, in the viewport set, what may show (``shown``: _visible's column of this
        view) of ``rows`` (all instances of this instant) and of the pictures from
        view-projection ``matrix``, as view ``view`` of the pass."""
        self.program['view_projection'].write(matrix)
        for mesh, chosen in self.by_mesh:
            chosen = chosen[shown[chosen]]
            if len(chosen):
                buffer, vao = self._slot(mesh, view)
                buffer.write(rows[chosen].tobytes())
                vao.render(instances=len(chosen))
        pictures = [(texture, vao) for texture, _, vao, quads in self.by_texture
                    if shown[len(rows) + quads].any()]
        if pictures:
            self.picture_program['view_projection'].write(matrix)
            for texture, vao in pictures:
                texture.use(0)
                vao.render()

    def _framebuffer(self, width, height):
        key = (width, height)
        if key not in self._framebuffers:
            if len(self._framebuffers) >= 4:  # sizes seldom change: keep a few
                for fbo in self._framebuffers.pop(next(iter(self._framebuffers))):
                    fbo.release()
            colour = self.ctx.renderbuffer((width, height), 4)
            depth = self.ctx.depth_renderbuffer((width, height))
            fbo = self.ctx.framebuffer(colour, depth)
            self._framebuffers[key] = (fbo, colour, depth)
        return self._framebuffers[key][0]

    def render_views(self, moving_rows, view_projections, width, height, components=3):
        """RGB images (height, width, 3) uint8 (RGBA with components=4) of the layout with
        the moving instances at ``moving_rows`` (ClientScene.moving_rows()), one per
        column-major 4x4 view-projection matrix (already flipped vertically), drawn in as
        few passes as fit."""
        with self.ctx:  # current in this thread for the call: any thread may render
            return self._render_views(moving_rows, view_projections, width, height,
                                      components)

    def _render_views(self, moving_rows, view_projections, width, height, components):
        import moderngl
        clock = time.perf_counter
        started = clock()
        rows = np.concatenate([self.layout.static_rows, moving_rows])
        reach = rows[:, 12:15] * self._bounds
        radii = np.where(self._spheres, rows[:, 12:15].max(axis=1),
                         np.sqrt(np.einsum('ij,ij->i', reach, reach)))
        shown = _visible(view_projections,
                         np.concatenate([rows[:, 9:12], self._picture_bounds[0]]),
                         np.concatenate([radii,
                                         self._picture_bounds[1]]))
        mark = clock()
        self.seconds['upload'] += mark - started
        per_pass = max(1, self.max_height // height)
        images = []
        ctx = self.ctx
        ctx.enable(moderngl.DEPTH_TEST | moderngl.CULL_FACE)
        ctx.front_face = 'cw'  # the vertical flip mirrors the winding
        for first in range(0, len(view_projections), per_pass):
            batch = view_projections[first:first + per_pass]
            fbo = self._framebuffer(width, height * len(batch))
            fbo.use()
            ctx.clear(*SKY, 1.0, depth=1.0)
            for k, matrix in enumerate(batch):
                ctx.viewport = (0, k * height, width, height)
                self._draw_view(k, matrix, rows, shown[:, first + k])
            # RGBA is the framebuffer's own format: llvmpipe reads it back without a
            # conversion (a 640x360 stereo pair 2.4 ms instead of 3.1, rasterising included).
            pixels = np.empty((len(batch) * height, width, components), np.uint8)
            drawn = clock()
            fbo.read_into(pixels, components=components, alignment=1)
            # llvmpipe rasterises when the pixels are asked for: 'read back' includes it.
            self.seconds['draw calls'] += drawn - mark
            mark = clock()
            self.seconds['read back'] += mark - drawn
            images += [pixels[k * height:(k + 1) * height] for k in range(len(batch))]
        return images

    def close(self):
        if self.ctx is not None:
            self.ctx.release()
            self.ctx = None


def view_projection(view_matrix, projection):
    """Column-major float32 bytes of projection @ view, flipped vertically so that the
    first row read back is the image's top row."""
    view = np.asarray(view_matrix, float).reshape(4, 4).T
    return (_flipped(tuple(projection)) @ view).T.astype('f4').tobytes()


@functools.lru_cache(maxsize=32)
def _flipped(projection):
    """The flipped projection of view_projection() (the same for every view of a camera)."""
    proj = np.asarray(projection, float).reshape(4, 4).T
    return np.diag([1.0, -1.0, 1.0, 1.0]) @ proj
