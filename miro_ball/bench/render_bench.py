"""Renderer comparison: ``python -m miro_ball.bench.render_bench``.

Milliseconds to render the eyes of one camera instant in the same scene (a bundled world
after 0.5 s, the robots' eyes from their own poses, the head panning between instants)
with each renderer: ours (egl), TinyRenderer (tiny), ours through MiRo's wide-angle lens
(egl-miro-lens: drawn wider and resampled) and, for reference, PyBullet's own eglRenderer
plugin as PyBullet ships it (pybullet-egl). Each renderer lives in a process
of its own (the plugin must), and they take turns batch by batch, so that a busy moment
of the machine hits all of them alike. Figures are medians over all instants.
"""
import argparse
import math
import multiprocessing
import statistics
import time

BATCH = 10  # instants per turn
CASES = (('miro', 1), ('football_pitch', 3))  # world, robots whose eyes are rendered
SIZES = ((640, 360), (320, 240), (1280, 720))
HFOV_DEG = 120.0
MIRO_LENS = 'egl-miro-lens'
KINDS = ('egl', 'tiny', MIRO_LENS, 'pybullet-egl')


def _pybullet_egl(sim):
    """A render function on PyBullet's stock eglRenderer plugin, loaded on sim's client.

    The plugin only sees bodies created after it is loaded, so the world is rebuilt."""
    import importlib.util

    import cv2
    import numpy as np

    from miro_sim_bullet.bullet import pybullet as p
    from miro_sim_bullet.render.renderer import opengl_projection

    spec = importlib.util.find_spec('eglRenderer')
    if spec is None or p.loadPlugin(spec.origin, '_eglRendererPlugin',
                                    physicsClientId=sim.client) < 0:
        raise RuntimeError('no eglRenderer plugin')
    sim.rebuild()  # the plugin sees the bodies made after it was loaded

    def render(views, intrinsics):
        w, h = intrinsics.width, intrinsics.height
        projection = opengl_projection(intrinsics)
        return [cv2.cvtColor(np.asarray(p.getCameraImage(
            w, h, viewMatrix=view, projectionMatrix=projection,
            flags=p.ER_NO_SEGMENTATION_MASK, renderer=p.ER_BULLET_HARDWARE_OPENGL,
            physicsClientId=sim.client)[2], np.uint8).reshape(h, w, 4), cv2.COLOR_RGBA2RGB)
            for view in views]
    return render


def _serve(connection, kind, world):
    """Worker: builds the world with its renderer, then times batches on request."""
    from miro_ball.miro.camera_model import CameraModel, MIRO, PINHOLE
    from miro_sim_bullet.physics.world import SimWorld
    from miro_sim_bullet.render.cameras import Cameras
    from miro_sim_bullet.render.renderer import view_matrix_from_pose

    sim = SimWorld(world)
    lens = MIRO if kind == MIRO_LENS else PINHOLE
    cameras = None if kind == 'pybullet-egl' else Cameras(sim, 'egl' if lens == MIRO else kind,
                                                          log=lambda _: None)
    try:
        if cameras is None:
            plugin = _pybullet_egl(sim)
            def render(views, camera):
                return plugin(views, camera.intrinsics)
        else:
            render = cameras.render_views
        sim.run(0.5)
        connection.send(('ready', kind if cameras is None else cameras.renderer.name))
        turn = 0
        while (job := connection.recv()) is not None:
            (width, height), robots = job
            camera = CameraModel(width, height, lens, HFOV_DEG)
            render([], camera)  # the lens's resampling maps are made once, before timing
            times = []
            for _ in range(BATCH):
                turn += 1
                views = [view_matrix_from_pose(*_panned(robot.eye_pose(side), turn))
                         for robot in list(sim.robots.values())[:robots] for side in (1, -1)]
                start = time.perf_counter()
                render(views, camera)
                times.append(time.perf_counter() - start)
            connection.send(times)
    finally:
        if cameras is not None:
            cameras.close()
        sim.close()


def _panned(pose, turn):
    """The eye pose turned about the vertical by a small angle that changes per instant,
    so consecutive frames differ as they would with a moving head."""
    import numpy as np
    position, rotation = pose
    a = 0.3 * math.sin(0.2 * turn)
    yaw = np.array([[math.cos(a), -math.sin(a), 0.0], [math.sin(a), math.cos(a), 0.0],
                    [0.0, 0.0, 1.0]])
    return position, yaw @ rotation


class Contender:
    """One renderer in a worker process of its own."""

    def __init__(self, kind, world):
        context = multiprocessing.get_context('spawn')
        self.connection, child = context.Pipe()
        self.process = context.Process(target=_serve, args=(child, kind, world), daemon=True)
        self.process.start()
        child.close()
        try:
            _, self.name = self.connection.recv()
        except EOFError:
            self.process.join()
            raise RuntimeError(f'{kind} could not start (exit status '
                               f'{self.process.exitcode})') from None
        self.kind = kind

    def time_batch(self, size, robots):
        self.connection.send((size, robots))
        return self.connection.recv()

    def close(self):
        try:
            self.connection.send(None)
        except OSError:
            pass
        self.process.join(timeout=10)
        if self.process.is_alive():
            self.process.kill()


def compare(world, robots, sizes, kinds, batches, report=print):
    """{(kind, size): median ms per instant}: the kinds take turns, batch by batch."""
    contenders = []
    try:
        for kind in kinds:
            try:
                contenders.append(Contender(kind, world))
            except RuntimeError as exc:
                report(f'  {kind}: left out: {exc}')
        samples = {(c.kind, size): [] for c in contenders for size in sizes}
        for _ in range(batches):
            for size in sizes:
                for contender in contenders:
                    samples[contender.kind, size] += contender.time_batch(size, robots)
        return {key: 1000 * statistics.median(times) for key, times in samples.items()}
    finally:
        for contender in contenders:
            contender.close()


def print_table(results, sizes, kinds, label, report=print):
    report(f'{label}: median ms per camera instant (all eyes rendered)')
    report(f'{"renderer":<14}' + ''.join(f'{f"{w}x{h}":>11}' for w, h in sizes))
    for kind in kinds:
        if (kind, sizes[0]) in results:
            report(f'{kind:<14}' + ''.join(f'{results[kind, size]:>11.1f}' for size in sizes))


def main(argv=None):
    parser = argparse.ArgumentParser(prog='python -m miro_ball.bench.render_bench',
                                     description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('--batches', type=int, default=6,
                        help=f'turns per renderer and size, {BATCH} instants each (default 6)')
    parser.add_argument('--kinds', default=','.join(KINDS),
                        help=f'comma-separated renderers (default {",".join(KINDS)})')
    args = parser.parse_args(argv)
    kinds = [k for k in args.kinds.split(',') if k]
    if not 1 <= args.batches <= 1000:
        parser.error('--batches must be in 1..1000')
    if not kinds or any(k not in KINDS for k in kinds):
        parser.error(f'--kinds must be a comma-separated subset of {",".join(KINDS)}')
    for world, robots in CASES:
        results = compare(world, robots, SIZES, kinds, args.batches)
        print_table(results, SIZES, kinds, f'{world}, {2 * robots} eyes')


if __name__ == '__main__':
    main()
