"""Stereo rendering speed per available renderer: ``python -m miro_ball.lab.render_bench``.

Prints the median milliseconds per stereo pair (two render() calls, 6 cm baseline) for a
small scene (ground, a few boxes, a ball) at the MiRo camera sizes.
"""
import argparse
import math
import statistics
import time

import numpy as np
import pybullet as p

from miro_ball.miro.camera import Intrinsics
from miro_sim_bullet.render.renderer import Renderer, probe_egl, view_matrix_from_pose

SIZES = ((640, 360), (320, 240), (1280, 720))
HFOV_DEG = 120.0
BASELINE = 0.06
WARMUP_PAIRS = 3


def build_scene(client):
    def body(shape, rgba, position, **size):
        visual = p.createVisualShape(shape, rgbaColor=rgba, physicsClientId=client, **size)
        p.createMultiBody(0, -1, visual, basePosition=position, physicsClientId=client)

    body(p.GEOM_BOX, (0.6, 0.6, 0.6, 1), (0, 0, -0.05), halfExtents=(5, 5, 0.05))
    for i, rgba in enumerate(((1, 0, 0, 1), (0, 1, 0, 1), (1, 0.5, 0, 1))):
        body(p.GEOM_BOX, rgba, (1.5, -0.6 + 0.6 * i, 0.1), halfExtents=(0.1, 0.1, 0.1))
    body(p.GEOM_SPHERE, (0, 0, 1, 1), (0.8, 0.1, 0.05), radius=0.05)


def stereo_views(step):
    """Left and right eye view matrices; the head pans slowly so frames differ."""
    yaw = 0.2 * math.sin(0.1 * step)
    c, s = math.cos(yaw), math.sin(yaw)
    rotation = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    centre = np.array([0.0, 0.0, 0.3])
    left = rotation[:, 1] * BASELINE / 2
    return [view_matrix_from_pose(centre + side, rotation) for side in (left, -left)]


def time_pairs(renderer, intrinsics, pairs):
    times = []
    for step in range(WARMUP_PAIRS + pairs):
        views = stereo_views(step)
        start = time.perf_counter()
        for view in views:
            renderer.render(view, intrinsics)
        times.append(time.perf_counter() - start)
    return 1000.0 * statistics.median(times[WARMUP_PAIRS:])


def bench(kind, shadow_pass, pairs):
    client = p.connect(p.DIRECT)
    try:
        renderer = Renderer(client, kind, log=lambda _: None, egl_shadow_pass=shadow_pass)
        try:
            build_scene(client)
            results = [time_pairs(renderer, Intrinsics.from_hfov(w, h, HFOV_DEG), pairs)
                       for w, h in SIZES]
            return renderer.name, results
        finally:
            renderer.close()
    finally:
        p.disconnect(client)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--pairs', type=int, default=30, help='timed stereo pairs per size')
    args = parser.parse_args()
    ok, reason = probe_egl()
    print(f'EGL probe: {reason}')
    configs = [('tiny', False)] + ([('egl', True), ('egl', False)] if ok else [])
    print(f'median ms per stereo pair over {args.pairs} pairs, hfov {HFOV_DEG:g} deg')
    print(f'{"renderer":32}' + ''.join(f'{f"{w}x{h}":<12}' for w, h in SIZES))
    for kind, shadow_pass in configs:
        name, results = bench(kind, shadow_pass, args.pairs)
        print(f'{name:32}' + ''.join(f'{ms:<12.1f}' for ms in results), flush=True)


if __name__ == '__main__':
    main()
