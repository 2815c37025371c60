"""A tree of frames from /tf and /tf_static: where any frame is in any other.

What tf2's buffer does for a client, in plain Python for the newest transforms only (no
history: the simulator's tree moves at 50 Hz and a student asks "where is it now").
Transforms are (xyz, quaternion x, y, z, w) of a child in its parent; every input is
checked (finite, a turn of some length, names of a bounded size) and a frame has one
parent. Pure: the GUI, client_tf and the tests use it.
"""
import math

import numpy as np

from miro_ball.miro.rotations import MIN_NORM, quaternion_matrix

MAX_FRAMES = 5000  # far beyond a world of robots (~30 frames each)
MAX_DEPTH = 64  # no tree of ours is deeper than ~8: a longer chain is a loop or garbage
MAX_NAME = 256


class TfError(ValueError):
    """No such frame, no path between two frames, or a transform that cannot be taken."""


def _matrix(xyz, q):
    t = np.eye(4)
    t[:3, :3] = quaternion_matrix(q)
    t[:3, 3] = xyz
    return t


class TfTree:
    """The newest transform of every frame (child -> (parent, 4x4 matrix in the parent))."""

    def __init__(self):
        self.parent = {}
        self._in_parent = {}

    def __contains__(self, frame):
        return frame in self.parent or frame in self.parent.values()

    def set(self, parent, child, xyz, quaternion):
        """Take one transform; TfError (one line) when it cannot be taken."""
        for name in (parent, child):
            if not isinstance(name, str) or not name or len(name) > MAX_NAME:
                raise TfError(f'frame name {str(name)[:40]!r} is not a name of 1 to '
                              f'{MAX_NAME} characters')
        parent, child = parent.lstrip('/'), child.lstrip('/')
        if parent == child:
            raise TfError(f'{child!r} cannot be its own parent')
        values = [float(v) for v in (*xyz, *quaternion)]
        if len(values) != 7 or not all(math.isfinite(v) for v in values):
            raise TfError(f'the transform of {child!r} is not 3 + 4 finite numbers')
        q = np.array(values[3:])
        norm = np.linalg.norm(q)
        if norm < MIN_NORM:
            raise TfError(f'the rotation of {child!r} is all zeros')
        if child not in self.parent and len(self.parent) >= MAX_FRAMES:
            raise TfError(f'more than {MAX_FRAMES} frames: {child!r} not taken')
        self.parent[child] = parent
        self._in_parent[child] = _matrix(values[:3], q / norm)

    def set_message(self, transforms):
        """Take a TFMessage's transforms; returns the one-line reasons of those refused."""
        refused = []
        for t in transforms:
            v, r = t.transform.translation, t.transform.rotation
            try:
                self.set(t.header.frame_id, t.child_frame_id, (v.x, v.y, v.z),
                         (r.x, r.y, r.z, r.w))
            except (TfError, TypeError, ValueError, AttributeError) as err:
                refused.append(str(err))
        return refused

    def _chain(self, frame):
        """[(frame, 4x4 in its parent)] from ``frame`` up to its root, and the root."""
        chain = []
        while frame in self.parent:
            if len(chain) >= MAX_DEPTH:
                raise TfError(f'the frames above {frame!r} go round in a loop')
            chain.append(self._in_parent[frame])
            frame = self.parent[frame]
        return chain, frame

    def in_root(self, frame):
        """(4x4 of ``frame`` in its tree's root, the root's name)."""
        chain, root = self._chain(frame)
        t = np.eye(4)
        for step in reversed(chain):
            t = t @ step
        return t, root

    def lookup(self, target, source):
        """4x4 transform of ``source`` expressed in ``target`` (its points to target's)."""
        for name in (target, source):
            if name not in self:
                raise TfError(f'no frame {name!r}')
        target_in_root, target_root = self.in_root(target)
        source_in_root, source_root = self.in_root(source)
        if target_root != source_root:
            raise TfError(f'{source!r} and {target!r} are in two trees (roots '
                          f'{source_root!r}, {target_root!r})')
        return np.linalg.inv(target_in_root) @ source_in_root

    def transform_point(self, target, source, point):
        """A point given in ``source``, in ``target``."""
        t = self.lookup(target, source)
        return t[:3, :3] @ np.asarray(point, float) + t[:3, 3]

    def frames(self):
        """Every frame named, children and roots."""
        return set(self.parent) | set(self.parent.values())
