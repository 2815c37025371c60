"""The eyes drawn in helper processes while the world steps on are the eyes the simulator
would have drawn itself at that instant, byte for byte, and none is lost if a helper dies."""
import math
import os
import signal

import pytest

from miro_ball.miro.camera_model import CameraModel
from miro_sim_bullet.physics.world import SimWorld
from miro_sim_bullet.render.cameras import Cameras
from miro_sim_bullet.render.eye_images import EyeWants
from miro_sim_bullet.render.eye_pipeline import EyePipeline
from miro_sim_bullet.render.renderer import probe_egl
from miro_sim_bullet.scene.world_model import Shape

RENDERERS = ['tiny', pytest.param('egl', marks=pytest.mark.skipif(
    not probe_egl()[0], reason='EGL unavailable: ' + probe_egl()[1]))]
WANTS = [EyeWants(jpeg=True, raw=True), EyeWants(jpeg=True, raw=False)]


@pytest.fixture(params=RENDERERS)
def moving_world(request):
    """(a SimWorld whose robot drives and turns its head, Cameras, EyePipeline with workers
    up, warnings given)"""
    world = SimWorld('miro')
    cameras = Cameras(world, request.param, log=lambda *_: None)
    warnings = []
    pipeline = EyePipeline(cameras, use_workers=True, log=lambda *_: None,
                           warn=warnings.append)
    pipeline.start_workers()
    world.robot.set_kinematic_targets([0.0, math.radians(50), math.radians(20), 0.0])
    world.robot.set_cmd_vel(0.2, 0.5)
    world.run(0.5)
    yield world, cameras, pipeline, warnings
    pipeline.close()
    cameras.close()
    world.close()


def eyes_now(world, cameras, pipeline, camera, overlap, tag):
    views = cameras.eye_views([(world.robot, +1), (world.robot, -1)])
    pipeline.submit(tag, views, camera, WANTS, 80, overlap=overlap)


@pytest.mark.parametrize('lens', ['pinhole', 'miro'])
def test_eyes_drawn_while_the_world_steps_on_are_those_of_their_instant(moving_world, lens):
    world, cameras, pipeline, warnings = moving_world
    camera = CameraModel(320, 240, lens=lens)
    done = []
    for instant in range(3):
        # Drawn in this thread an instant is done at once, after those asked for before.
        eyes_now(world, cameras, pipeline, camera, overlap=False, tag=('here', instant))
        assert pipeline.pending == 0
        eyes_now(world, cameras, pipeline, camera, overlap=True, tag=('worker', instant))
        assert pipeline.pending == 1
        world.run(0.3)  # robot, head and ball move on while the worker draws
        done += pipeline.finished()
    done += pipeline.finished(wait=True)
    assert [tag for tag, _, _ in done] == [(where, k) for k in range(3)
                                           for where in ('here', 'worker')]
    here, away = done[0::2], done[1::2]
    for (_, ours, _), (_, theirs, seconds) in zip(here, away):
        assert ours == theirs  # JPEG and raw bytes of both eyes
        assert seconds['draw'] > 0 and seconds['encode'] > 0
    jpeg, raw = here[0][1][1]
    assert jpeg and raw is None  # the right eye: JPEG only, as asked
    assert len(here[0][1][0][1]) == 320 * 240 * 3
    assert here[0][1] != here[1][1]  # the instants differ: the test can tell them apart
    assert not warnings and pipeline.drawing_in_workers


def test_a_worker_that_dies_loses_no_instant(moving_world):
    world, cameras, pipeline, warnings = moving_world
    camera = CameraModel(320, 240)
    eyes_now(world, cameras, pipeline, camera, overlap=False, tag='reference')
    eyes_now(world, cameras, pipeline, camera, overlap=True, tag='up')  # waits for them
    (_, reference, _), (_, up, _) = pipeline.finished(wait=True)
    assert up == reference and pipeline.drawing_in_workers
    processes = pipeline.workers.processes
    for process in processes:  # stopped, they can not answer: the next instant stays in flight
        os.kill(process.pid, signal.SIGSTOP)
    eyes_now(world, cameras, pipeline, camera, overlap=True, tag='lost')
    assert pipeline.pending == 1
    for process in processes:
        os.kill(process.pid, signal.SIGKILL)
        process.wait()
    world.run(0.2)
    eyes_now(world, cameras, pipeline, camera, overlap=True, tag='after')
    done = pipeline.finished(wait=True)
    assert [tag for tag, _, _ in done] == ['lost', 'after']
    assert done[0][1] == reference  # drawn here from the state the worker was sent
    assert done[1][1] != reference
    assert len(warnings) == 1 and 'eye worker' in warnings[0]
    assert not pipeline.drawing_in_workers and pipeline.pending == 0


def test_eyes_of_a_world_that_spawned_a_shape_between_instants_are_its_own(moving_world):
    """A spawn while an instant is being drawn: the next instants are drawn (two at once)
    from the world with the crate in it, as the simulator would draw them itself. The
    TinyRenderer's copy, built anew from the world's description, numbers its bodies
    otherwise: its ball and robot were posed by body id, a crate took the ball's place."""
    world, cameras, pipeline, warnings = moving_world
    camera = CameraModel(160, 120)
    eyes_now(world, cameras, pipeline, camera, overlap=True, tag='before')
    x, y, yaw = world.robot.pose()
    world.spawn_shape(Shape(kind='box', position=(x + 0.4 * math.cos(yaw),
                                                  y + 0.4 * math.sin(yaw), 0.1),
                            size=(0.2, 0.2, 0.2), colour=(1.0, 0.0, 0.0), name='crate'))
    eyes_now(world, cameras, pipeline, camera, overlap=True, tag='spawned')
    assert pipeline.pending == 2
    eyes_now(world, cameras, pipeline, camera, overlap=False, tag='here')
    done = pipeline.finished(wait=True)
    assert [tag for tag, _, _ in done] == ['before', 'spawned', 'here']
    assert done[1][1] == done[2][1] != done[0][1]
    assert not warnings and pipeline.drawing_in_workers
