"""Off-screen camera images from a PyBullet client, with exact pinhole geometry.

Two back ends:

* ``egl``: our own OpenGL renderer (:mod:`gl_renderer`, moderngl on a headless EGL
  context: a GPU where there is one, else Mesa's llvmpipe). Draws any number of views
  (both eyes of every robot) in one pass; 2 ms per 640x360 stereo pair on llvmpipe here.
* ``tiny``: PyBullet's built-in TinyRenderer, always available, single-threaded.

'auto' picks ``egl`` when an EGL context can be made here (:func:`probe_egl`), else
``tiny`` with one log line saying why.
"""
import collections
import functools

import cv2
import numpy as np

from miro_sim_bullet.bullet import pybullet as p
from miro_sim_bullet.render.gl_renderer import ClientScene, egl_device, GlBackend, probe_egl, \
    view_projection

_FLAGS = p.ER_NO_SEGMENTATION_MASK
# TinyRenderer keeps shadow and light settings from the previous call (server-side state),
# so every call sets them; the light comes from above, slightly from the front-left.
_TINY_LIGHT_DIRECTION = (0.4, 0.3, 1.0)


class RendererUnavailable(RuntimeError):
    """The requested renderer cannot be used here; ``reason`` is one line for the user."""

    def __init__(self, reason):
        super().__init__(reason)
        self.reason = reason


def opengl_projection(intrinsics, x0=0, y0=0, width=None, height=None):
    """Column-major OpenGL projection matrix that renders the pixel window
    [x0, x0+width) x [y0, y0+height) of the image described by ``intrinsics``.

    A camera point (X right, Y down, Z forward) must land on u = fx X/Z + cx,
    v = fy Y/Z + cy, where pixel u covers [u - 0.5, u + 0.5]. OpenGL's window x of that
    point is then u + 0.5 - x0; its window y counts from the bottom row, and PyBullet flips
    rows so that row 0 of the returned image is the top, hence the signs below.
    """
    k = intrinsics
    w = k.width if width is None else width
    h = k.height if height is None else height
    cx = k.cx - x0
    cy = k.cy - y0
    n, f = k.near, k.far
    return (
        2.0 * k.fx / w, 0.0, 0.0, 0.0,
        0.0, 2.0 * k.fy / h, 0.0, 0.0,
        1.0 - 2.0 * (cx + 0.5) / w, 2.0 * (cy + 0.5) / h - 1.0, -(f + n) / (f - n), -1.0,
        0.0, 0.0, -2.0 * f * n / (f - n), 0.0,
    )


def view_matrix_from_pose(position, rotation_matrix):
    """OpenGL view matrix (column-major, 16 floats) of a camera link whose frame follows
    REP 103 (x forward, y left, z up). ``rotation_matrix`` maps link to world coordinates;
    a nested 3x3 or PyBullet's flat row-major 9-tuple both work."""
    rot = np.asarray(rotation_matrix, dtype=float).reshape(3, 3)
    eye = np.asarray(position, dtype=float)
    return p.computeViewMatrix(eye.tolist(), (eye + rot[:, 0]).tolist(), rot[:, 2].tolist())


# ------------------------------------------------------------------------- back ends

class _TinyBackend:
    kind = 'tiny'
    # TinyRenderer samples each pixel at its corner, not its centre (measured: images sit
    # half a pixel right of and above OpenGL's), so its projection is shifted back.
    pixel_shift = (0.5, -0.5)

    def __init__(self, client_id):
        self.client_id = client_id
        self.name = 'tiny'

    def render_views(self, views, intrinsics, rgba=False):
        projection = _projection(intrinsics, self.pixel_shift)
        return [self._shot(view, intrinsics.width, intrinsics.height, projection, rgba)
                for view in views]

    def _shot(self, view, width, height, projection, rgba):
        pixels = p.getCameraImage(
            width, height, viewMatrix=view, projectionMatrix=projection, shadow=0,
            lightDirection=_TINY_LIGHT_DIRECTION, flags=_FLAGS, renderer=p.ER_TINY_RENDERER,
            physicsClientId=self.client_id)[2]
        # A no-op on numpy-enabled pybullet; converts the flat list otherwise.
        image = np.asarray(pixels, dtype=np.uint8).reshape(height, width, 4)
        return image if rgba else cv2.cvtColor(image, cv2.COLOR_RGBA2RGB)

    def scene_changed(self):
        pass  # TinyRenderer reads the client's bodies on every call

    def close(self):
        pass


class _GlBackend:
    """:class:`gl_renderer.GlBackend` behind the same interface as _TinyBackend. Its GL
    context is made at the first image: a simulator whose eyes are drawn in helper
    processes needs only the scene's layout and rows here (and saves ~35 MB)."""

    kind = 'egl'

    def __init__(self, client_id, pictures=(), colour_key=None):
        self.client_id, self.pictures = client_id, tuple(pictures)
        self.colour_key = colour_key
        self.scene = ClientScene(client_id, self.pictures, colour_key)
        self.gl = None
        self.seconds = collections.Counter()
        self.name = 'egl'
        self.device = egl_device()

    def render_views(self, views, intrinsics, rgba=False):
        if self.gl is None:
            self.gl = GlBackend(self.scene.layout, self.seconds)
        return draw_rows(self.gl, self.scene.moving_rows(), views, intrinsics, rgba)

    def scene_changed(self):
        self.scene = ClientScene(self.client_id, self.pictures, self.colour_key)
        if self.gl is not None:
            self.gl.set_layout(self.scene.layout)

    def close(self):
        if self.gl is not None:
            self.gl.close()
            self.gl = None


def draw_rows(gl, moving_rows, views, intrinsics, rgba=False):
    """Images from a GlBackend of its layout with ``moving_rows``, from OpenGL view matrices
    through pinhole ``intrinsics``: what the egl renderer draws, also where no PyBullet
    client is (render.eye_workers)."""
    projection = _projection(intrinsics, (0.0, 0.0))
    return gl.render_views(moving_rows, [view_projection(view, projection) for view in views],
                           intrinsics.width, intrinsics.height, components=4 if rgba else 3)


@functools.lru_cache(maxsize=32)
def _projection(intrinsics, pixel_shift):
    """The OpenGL projection of ``intrinsics`` for a rasterizer that draws everything
    ``pixel_shift`` (du, dv) away from where OpenGL would; the shift is undone."""
    return opengl_projection(intrinsics, *pixel_shift)


class Renderer:
    """Camera images of one PyBullet client.

    ``kind``: 'auto' (egl when :func:`probe_egl` succeeds, else TinyRenderer), 'egl'
    (raise :class:`RendererUnavailable` if it cannot be used) or 'tiny'. Call
    :meth:`scene_changed` whenever bodies were added or the client was reset. ``log``
    receives one line describing the choice (with egl, the GL device that renders).
    ``kind`` and ``name`` tell what is in use ('tiny' or 'egl'); ``device`` is the
    GL_RENDERER string (None with TinyRenderer). ``pictures`` (World.pictures) are drawn
    by egl; TinyRenderer draws the textured bodies SimWorld made of them. ``colour_key``:
    egl reads the shapes' colours again only when its value changes (gl_renderer.ClientScene;
    None: at every instant).
    """

    def __init__(self, client_id, kind='auto', log=print, pictures=(), colour_key=None):
        if kind not in ('auto', 'egl', 'tiny'):
            raise ValueError(f"kind must be 'auto', 'egl' or 'tiny', not {kind!r}")
        self.client_id = client_id
        self.pictures = tuple(pictures)
        self.colour_key = colour_key
        self._backend, note = self._choose(kind)
        self.kind = self.name = self._backend.kind
        self.device = getattr(self._backend, 'device', None)
        # Wall seconds per stage of drawing (upload, draw calls, read back), egl only.
        self.seconds = getattr(self._backend, 'seconds', {})
        log(f'camera renderer: {self.name} ({note})')
        if not p.isNumpyEnabled():
            log('pybullet was built without numpy: images cost ~30 ms more each at 640x360')

    def _choose(self, kind):
        """(back end, why it was chosen)."""
        if kind == 'tiny':
            return _TinyBackend(self.client_id), 'requested'
        ok, reason = probe_egl()
        if ok:
            backend = _GlBackend(self.client_id, self.pictures, self.colour_key)
            return backend, f'rendering on {backend.device}'
        if kind == 'egl':
            raise RendererUnavailable(reason)
        return _TinyBackend(self.client_id), f'{reason}; falling back to TinyRenderer'

    def scene_changed(self):
        """The client's bodies were rebuilt or added to: read them again."""
        self._backend.scene_changed()

    @property
    def layout(self):
        """egl: the gl_renderer.SceneLayout drawn (what stays between frames)."""
        return self._backend.scene.layout

    def moving_rows(self):
        """egl: the rows of the moving instances now (what changes between frames)."""
        return self._backend.scene.moving_rows()

    def render(self, view_matrix, intrinsics):
        """RGB image (height, width, 3) uint8 seen through ``intrinsics`` from
        ``view_matrix`` (column-major world-to-camera matrix as from computeViewMatrix)."""
        return self._backend.render_views([view_matrix], intrinsics)[0]

    def render_many(self, view_matrices, intrinsics, rgba=False):
        """One RGB image (RGBA with ``rgba``) per view matrix, all of this instant (egl
        draws them together)."""
        if not view_matrices:
            return []
        return self._backend.render_views(list(view_matrices), intrinsics, rgba)

    def close(self):
        """Release the GL context. Idempotent."""
        self._backend.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc_info):
        self.close()
