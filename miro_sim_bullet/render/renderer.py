"""Off-screen camera images from a PyBullet client, with exact pinhole geometry.

Two back ends:

* ``egl``: PyBullet's eglRenderer plugin on Mesa (llvmpipe on a CPU-only machine), about
  5x faster than TinyRenderer at 320x240 to 1280x720 once its shadow pass is off.
* ``tiny``: PyBullet's built-in TinyRenderer, always available, single-threaded.

Facts about the EGL plugin that shape this module (pybullet 3.2.7, measured):

* It calls ``exit(1)`` inside ``loadPlugin`` when EGL is unusable, so it is probed in a
  child process first (:func:`probe_egl`).
* It makes its GL context current in the thread that loads it and never re-binds it:
  rendering from another thread segfaults, and bodies created from another thread are
  invisible to it. So a Renderer renders only in the thread that created it (and raises
  elsewhere); build the world in that thread too.
* It only sees bodies created after it was loaded, so a Renderer must be created on an empty
  client (``resetSimulation`` afterwards is fine).
* Several live instances in one process share one current context and clobber each other
  (wrong shapes, then a segfault once one of them is unloaded). Hence at most one EGL
  Renderer is open per process; a second one falls back to TinyRenderer (``kind='auto'``) or
  is refused (``kind='egl'``). Sequential create/close cycles work.
* It always renders a 4096x4096 shadow map (~11 ms per image on llvmpipe; ``shadow=0`` is
  ignored). By default this module clears the plugin's private ``useShadowMap`` flag in
  memory, after checking the symbol in the .so's ELF symbol table (:func:`_set_shadow_pass`).
* Its pbuffer is 1024x768; larger images are stretched, so they are rendered as tiles with
  off-axis projections and stitched.
"""
import collections
import ctypes
import functools
import importlib.util
import math
import mmap
import os
import struct
import subprocess
import sys
import threading

import cv2
import numpy as np
import pybullet as p


EGL_MAX_WIDTH = 1024
EGL_MAX_HEIGHT = 768
_EGL_POSTFIX = '_eglRendererPlugin'
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


# --------------------------------------------------------------------------- EGL probe

# Runs in a child process: the plugin exits the process when EGL is unusable.
_PROBE_SCRIPT = """\
import sys
import pybullet as p
p.connect(p.DIRECT)
if p.loadPlugin(sys.argv[1], sys.argv[2]) < 0:
    sys.exit('loadPlugin returned -1')
rgba = p.getCameraImage(8, 8, flags=p.ER_NO_SEGMENTATION_MASK,
                        renderer=p.ER_BULLET_HARDWARE_OPENGL)[2]
if len(rgba) != 8 and len(rgba) != 8 * 8 * 4:
    sys.exit('unexpected image from the plugin')
print('EGL_PROBE_OK', flush=True)
"""
_probe_lock = threading.Lock()
_probe_result = None


def egl_plugin_path():
    """Path of PyBullet's eglRenderer plugin, or None if this wheel has none."""
    spec = importlib.util.find_spec('eglRenderer')
    return spec.origin if spec is not None else None


def _fix_egl_environ(env):
    """Make ``env`` usable for the plugin: EGL_PLATFORM=device breaks its first
    eglGetDisplay; every other value (or none) works, so only that one is removed."""
    if env.get('EGL_PLATFORM') == 'device':
        del env['EGL_PLATFORM']
    return env


def probe_egl(timeout=60.0):
    """(ok, one-line reason): whether the eglRenderer plugin loads and renders here.

    Decided once per process in a child process, since a failing plugin exits its process.
    """
    global _probe_result
    with _probe_lock:
        if _probe_result is None:
            _probe_result = _run_probe(timeout)
        return _probe_result


def _run_probe(timeout):
    path = egl_plugin_path()
    if path is None:
        return False, 'this pybullet has no eglRenderer plugin'
    env = _fix_egl_environ(dict(os.environ))
    try:
        done = subprocess.run(
            [sys.executable, '-c', _PROBE_SCRIPT, path, _EGL_POSTFIX], env=env,
            stdin=subprocess.DEVNULL, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return False, f'EGL probe timed out after {timeout:g} s'
    except OSError as exc:
        return False, f'EGL probe could not start: {exc}'
    if done.returncode == 0 and 'EGL_PROBE_OK' in done.stdout:
        return True, 'EGL works: ' + _gl_renderer_name(done.stdout)
    last = _last_line(done.stderr) or _last_line(done.stdout) or 'no output'
    return False, f'EGL plugin unusable (exit status {done.returncode}): {last}'


def _gl_renderer_name(stdout):
    for line in stdout.splitlines():
        if line.startswith('GL_RENDERER='):
            return line.partition('=')[2].strip()
    return 'unknown GL renderer'


def _last_line(text):
    lines = [line.strip() for line in text.splitlines() if line.strip()]
    return lines[-1] if lines else ''


# ------------------------------------------------------ shadow-map switch (memory poke)

_SHADOW_SYMBOL = b'useShadowMap'
# ELF64 little-endian records (Elf64_Ehdr, Elf64_Shdr, Elf64_Phdr, Elf64_Sym).
_ELF_HEADER = struct.Struct('<16sHHIQQQIHHHHHH')
_ELF_SECTION = struct.Struct('<IIQQQQIIQQ')
_ELF_PROGRAM = struct.Struct('<IIQQQQQQ')
_ELF_SYMBOL = struct.Struct('<IBBHQQ')
_Header = collections.namedtuple('_Header', 'ident type machine version entry phoff shoff'
                                 ' flags ehsize phentsize phnum shentsize shnum shstrndx')
_Section = collections.namedtuple('_Section',
                                  'name type flags addr offset size link info align entsize')
_Segment = collections.namedtuple('_Segment',
                                  'type flags offset vaddr paddr filesz memsz align')
_SHT_PROGBITS, _SHT_SYMTAB = 1, 2
_SHF_WRITE, _SHF_ALLOC = 0x1, 0x2
_STT_OBJECT = 1
_PT_LOAD = 1
_SHN_LORESERVE = 0xff00


class _PatchError(Exception):
    """The shadow-map flag could not be located or verified; the plugin stays stock."""


def _set_shadow_pass(path, enabled):
    """Set the plugin's private ``bool useShadowMap`` (GLInstancingRenderer.cpp).

    The flag is a file-local global in the loaded .so, shared by every plugin instance and
    kept across unload/reload (PyBullet does not unmap the library), so it is written on
    every load. Nothing is written unless: the .symtab has exactly one 1-byte object of
    that name in a writable, allocated PROGBITS section, initialised to 1 in the file; the
    library is mapped once at a base found in /proc/self/maps; the address falls in a
    read-write mapping of that same file; and the byte there is 0 or 1.
    """
    path = os.path.realpath(path)
    value, load_vaddr = _shadow_symbol(path)
    address = _runtime_address(path, value, load_vaddr)
    cell = ctypes.c_uint8.from_address(address)
    if cell.value not in (0, 1):
        raise _PatchError(f'useShadowMap holds {cell.value}, not a bool')
    cell.value = int(enabled)


@functools.lru_cache(maxsize=4)
def _shadow_symbol(path):
    """(st_value, p_vaddr of the segment at file offset 0) for useShadowMap in ``path``."""
    with open(path, 'rb') as f:
        header = _Header._make(_read_table(f, _ELF_HEADER, 0, 1)[0])
        if header.ident[:4] != b'\x7fELF' or header.ident[4:6] != b'\x02\x01':
            raise _PatchError('not a 64-bit little-endian ELF file')
        if (header.shentsize, header.phentsize) != (_ELF_SECTION.size, _ELF_PROGRAM.size):
            raise _PatchError('unexpected ELF header entry sizes')
        sections = [_Section._make(row) for row in
                    _read_table(f, _ELF_SECTION, header.shoff, header.shnum)]
        segments = [_Segment._make(row) for row in
                    _read_table(f, _ELF_PROGRAM, header.phoff, header.phnum)]
        value, shndx = _find_object(f, sections, _SHADOW_SYMBOL)
        _check_flag_section(f, sections, shndx, value)
    heads = [seg for seg in segments if seg.type == _PT_LOAD and seg.offset == 0]
    if len(heads) != 1:
        raise _PatchError('no single PT_LOAD segment at file offset 0')
    return value, heads[0].vaddr


def _read_bytes(f, offset, size):
    f.seek(offset)
    data = f.read(size)
    if len(data) != size:
        raise _PatchError('truncated ELF file')
    return data


def _read_table(f, layout, offset, count):
    return list(layout.iter_unpack(_read_bytes(f, offset, layout.size * count)))


def _find_object(f, sections, name):
    """(st_value, st_shndx) of the only 1-byte STT_OBJECT symbol ``name`` in .symtab."""
    symtabs = [s for s in sections if s.type == _SHT_SYMTAB]
    if len(symtabs) != 1 or symtabs[0].entsize != _ELF_SYMBOL.size:
        raise _PatchError('no usable .symtab (stripped plugin?)')
    symtab = symtabs[0]
    if symtab.link >= len(sections):
        raise _PatchError('.symtab links to a missing string table')
    names = _read_bytes(f, sections[symtab.link].offset, sections[symtab.link].size)
    found = []
    for st_name, info, _, shndx, value, size in _ELF_SYMBOL.iter_unpack(
            _read_bytes(f, symtab.offset, symtab.size)):
        if info & 0xf == _STT_OBJECT and names[st_name:st_name + len(name) + 1] == name + b'\0':
            found.append((value, shndx, size))
    if len(found) != 1:
        raise _PatchError(f'{len(found)} symbols named {name.decode()}, expected 1')
    value, shndx, size = found[0]
    if size != 1:
        raise _PatchError(f'{name.decode()} is {size} bytes, expected a 1-byte bool')
    return value, shndx


def _check_flag_section(f, sections, shndx, value):
    """The flag must live in initialised writable data and start out as true."""
    if shndx == 0 or shndx >= min(len(sections), _SHN_LORESERVE):
        raise _PatchError('useShadowMap is not in a regular section')
    section = sections[shndx]
    wanted = _SHF_WRITE | _SHF_ALLOC
    if section.type != _SHT_PROGBITS or section.flags & wanted != wanted:
        raise _PatchError('useShadowMap is not in writable initialised data')
    if not section.addr <= value < section.addr + section.size:
        raise _PatchError('useShadowMap lies outside its section')
    if _read_bytes(f, section.offset + value - section.addr, 1) != b'\x01':
        raise _PatchError('useShadowMap is not initialised to true in the file')


def _runtime_address(path, value, load_vaddr):
    maps = _mappings_of(path)
    heads = [m for m in maps if m[3] == 0]
    if len(heads) != 1:
        raise _PatchError(f'{len(heads)} mappings of the plugin at file offset 0, expected 1')
    address = heads[0][0] - (load_vaddr & ~(mmap.PAGESIZE - 1)) + value
    if not any(start <= address < end and perms.startswith('rw')
               for start, end, perms, _ in maps):
        raise _PatchError('useShadowMap is not in a read-write mapping of the plugin')
    return address


def _mappings_of(path):
    """[(start, end, perms, file offset)] of ``path`` (a real path) in this process."""
    found = []
    with open('/proc/self/maps') as maps:
        for line in maps:
            fields = line.split(maxsplit=5)
            if len(fields) == 6 and fields[5].rstrip('\n') == path:
                start, end = (int(x, 16) for x in fields[0].split('-'))
                found.append((start, end, fields[1], int(fields[2], 16)))
    return found


# ------------------------------------------------------------------------- back ends

@functools.lru_cache(maxsize=1)
def _egl_library():
    lib = ctypes.CDLL('libEGL.so.1')
    lib.eglGetCurrentContext.restype = ctypes.c_void_p
    lib.eglGetCurrentContext.argtypes = []
    return lib


def _current_egl_context():
    """This thread's current EGL context (None if none): the plugin's, while it lives."""
    return _egl_library().eglGetCurrentContext()


class _TinyBackend:
    kind = 'tiny'
    max_size = None
    # TinyRenderer samples each pixel at its corner, not its centre (measured: images sit
    # half a pixel right of and above OpenGL's), so its projection is shifted back.
    pixel_shift = (0.5, -0.5)

    def __init__(self, client_id):
        self.client_id = client_id
        self.name = 'tiny'

    def shot(self, width, height, view, projection):
        return p.getCameraImage(
            width, height, viewMatrix=view, projectionMatrix=projection, shadow=0,
            lightDirection=_TINY_LIGHT_DIRECTION, flags=_FLAGS, renderer=p.ER_TINY_RENDERER,
            physicsClientId=self.client_id)[2]

    def close(self):
        pass


class _EglBackend:
    """The eglRenderer plugin loaded on one client; at most one per process (see above)."""

    kind = 'egl'
    max_size = (EGL_MAX_WIDTH, EGL_MAX_HEIGHT)
    pixel_shift = (0.0, 0.0)
    owner = None  # the open _EglBackend of this process, if any

    def __init__(self, client_id, shadow_pass, log):
        path = egl_plugin_path()
        if path is None:
            raise RendererUnavailable('this pybullet has no eglRenderer plugin')
        # llvmpipe would use every core; one rasterizer thread is as fast once the shadow
        # pass is gone and leaves the other core to physics.
        os.environ.setdefault('LP_NUM_THREADS', '1')
        if os.environ.get('EGL_PLATFORM') == 'device':
            log('EGL_PLATFORM=device breaks the EGL plugin: unsetting it')
            _fix_egl_environ(os.environ)
        self.client_id = client_id
        self.plugin_id = p.loadPlugin(path, _EGL_POSTFIX, physicsClientId=client_id)
        if self.plugin_id < 0:
            raise RendererUnavailable('loadPlugin(eglRenderer) returned -1')
        self.thread = threading.get_ident()
        self.context = _current_egl_context()
        _EglBackend.owner = self
        self.name = self._configure_shadow_pass(path, shadow_pass, log)

    @staticmethod
    def _configure_shadow_pass(path, shadow_pass, log):
        try:
            _set_shadow_pass(path, shadow_pass)
        except (_PatchError, OSError) as exc:
            if not shadow_pass:
                log(f'EGL shadow pass stays on (+~11 ms per image): {exc}')
            return 'egl (stock, shadow pass on)'
        return 'egl (stock, shadow pass on)' if shadow_pass else 'egl'

    @classmethod
    def busy(cls):
        """Whether an EGL back end still holds the plugin in this process."""
        return cls.owner is not None and cls.owner._plugin_alive()

    def _plugin_alive(self):
        if self.thread == threading.get_ident():
            # Unloading or disconnecting destroys the plugin's context, even without close(),
            # and a client id can be reused after a disconnect, so the context is the test.
            return _current_egl_context() == self.context
        return bool(p.getConnectionInfo(self.client_id)['isConnected'])

    def _check_context(self):
        if _EglBackend.owner is not self or _current_egl_context() != self.context:
            raise RuntimeError('EGL renderer used outside the thread that created it, or after'
                               ' it was closed or its client disconnected')

    def shot(self, width, height, view, projection):
        self._check_context()
        return p.getCameraImage(
            width, height, viewMatrix=view, projectionMatrix=projection, flags=_FLAGS,
            renderer=p.ER_BULLET_HARDWARE_OPENGL, physicsClientId=self.client_id)[2]

    def close(self):
        if _EglBackend.owner is not self:
            return  # closed before, or superseded after its client was disconnected
        _EglBackend.owner = None
        if self._plugin_alive():
            p.unloadPlugin(self.plugin_id, physicsClientId=self.client_id)


# -------------------------------------------------------------------------- Renderer

@functools.lru_cache(maxsize=32)
def _tile_plan(intrinsics, max_size, pixel_shift):
    """((x0, y0, width, height, projection), ...) covering the image in tiles no larger
    than ``max_size`` (None: one tile), as even as possible. ``pixel_shift`` is how far
    (du, dv) the rasterizer draws everything from where OpenGL would; it is undone."""
    max_w, max_h = max_size or (intrinsics.width, intrinsics.height)
    columns = _split(intrinsics.width, math.ceil(intrinsics.width / max_w))
    rows = _split(intrinsics.height, math.ceil(intrinsics.height / max_h))
    du, dv = pixel_shift
    return tuple((x0, y0, w, h, opengl_projection(intrinsics, x0 + du, y0 + dv, w, h))
                 for y0, h in rows for x0, w in columns)


def _split(total, parts):
    edges = [i * total // parts for i in range(parts + 1)]
    return [(a, b - a) for a, b in zip(edges, edges[1:])]


class Renderer:
    """Camera images of one PyBullet client.

    ``kind``: 'auto' (EGL when :func:`probe_egl` succeeds and no other EGL Renderer is open,
    else TinyRenderer), 'egl' (raise :class:`RendererUnavailable` if it cannot be used) or
    'tiny'. Create it before adding bodies to the client, and with EGL build the world and
    render in the thread that created it. ``egl_shadow_pass=True`` keeps the EGL plugin's
    stock 4096x4096 shadow-map pass (about 11 ms per image on llvmpipe; the images lose cast
    shadows without it). ``log`` receives one line describing the choice. ``kind`` and
    ``name`` tell what is in use ('tiny' or 'egl'; e.g. 'egl (stock, shadow pass on)').
    """

    def __init__(self, client_id, kind='auto', log=print, egl_shadow_pass=False):
        if kind not in ('auto', 'egl', 'tiny'):
            raise ValueError(f"kind must be 'auto', 'egl' or 'tiny', not {kind!r}")
        if kind != 'tiny' and p.getNumBodies(physicsClientId=client_id) > 0:
            raise ValueError('create the Renderer before adding bodies: the EGL plugin does'
                             ' not see bodies that existed when it was loaded')
        self.client_id = client_id
        self._backend, note = self._choose(kind, egl_shadow_pass, log)
        self.kind = self._backend.kind
        self.name = self._backend.name
        log(f'camera renderer: {self.name} ({note})')
        if not p.isNumpyEnabled():
            log('pybullet was built without numpy: images cost ~30 ms more each at 640x360')

    def _choose(self, kind, egl_shadow_pass, log):
        """(back end, why it was chosen)."""
        if kind == 'tiny':
            return _TinyBackend(self.client_id), 'requested'
        ok, reason = probe_egl()
        if ok and _EglBackend.busy():
            ok, reason = False, ('another EGL Renderer is open in this process'
                                 ' (the plugin supports one at a time)')
        if not ok:
            if kind == 'egl':
                raise RendererUnavailable(reason)
            return _TinyBackend(self.client_id), reason
        backend = _EglBackend(self.client_id, egl_shadow_pass, log)
        return backend, f'{reason}, LP_NUM_THREADS={os.environ["LP_NUM_THREADS"]}'

    def render(self, view_matrix, intrinsics):
        """RGB image (height, width, 3) uint8 seen through ``intrinsics`` from
        ``view_matrix`` (column-major world-to-camera matrix as from computeViewMatrix)."""
        plan = _tile_plan(intrinsics, self._backend.max_size, self._backend.pixel_shift)
        if len(plan) == 1:
            _, _, w, h, projection = plan[0]
            return self._tile_rgb(view_matrix, w, h, projection)
        image = np.empty((intrinsics.height, intrinsics.width, 3), np.uint8)
        for x0, y0, w, h, projection in plan:
            self._tile_rgb(view_matrix, w, h, projection, out=image[y0:y0 + h, x0:x0 + w])
        return image

    def _tile_rgb(self, view, width, height, projection, out=None):
        pixels = self._backend.shot(width, height, view, projection)
        # A no-op on numpy-enabled pybullet; converts the flat list otherwise.
        rgba = np.asarray(pixels, dtype=np.uint8).reshape(height, width, 4)
        return cv2.cvtColor(rgba, cv2.COLOR_RGBA2RGB, dst=out)

    def close(self):
        """Unload the EGL plugin (call before disconnecting the client). Idempotent."""
        self._backend.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc_info):
        self.close()
