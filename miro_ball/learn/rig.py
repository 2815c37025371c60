"""The simulator's own world in this process, seen and driven as the controller contract
says: Percepts out, Action in, one 20 ms platform tick at a time. No ROS, no DDS, no child
processes.

The same SimWorld (robot model, worlds, physics, microphones) and the same Cameras
(renderer, MiRo's lens) as the ROS simulator. What the simulator's topics would carry is
taken here from the robot's own tick (its ``sensors``), and an Action reaches the robot as
the simulator's control topics hand it over, so that what is learnt here behaves the same
there. A snapshot of the built world makes a reset cheap: restored, not rebuilt (unless
the world holds a non-finite value). An Action takes the control topics' own path to the
robot (physics.commands): what they would ignore (a NaN, a wrong length) never reaches it.
"""
import logging

import numpy as np

from miro_ball.common.ros_params import values_of
from miro_ball.common.throttle import Throttled
from miro_ball.controller.contract import Eye, Percepts
from miro_ball.controller.detectors import check_names
from miro_ball.learn.action_parts import parts
from miro_ball.learn.eyes import check_options, RigEyes
from miro_ball.miro.camera_model import CameraModel, PINHOLE
from miro_ball.miro.constants import CAM_HFOV_DEG_SIM
from miro_ball.miro.hearing import locate
from miro_sim_bullet.physics.commands import take
from miro_sim_bullet.physics.world import SimWorld
from miro_sim_bullet.render.cameras import Cameras
from miro_sim_bullet.ros.params import SimParams


class WorldRig:
    """A world (SimWorld or what SimWorld takes: a bundled name, a path, a World) with eyes
    of ``eyes`` = (width, height) pixels through ``lens`` (None: no image is ever drawn)
    and, for each robot, the detectors named in ``detectors`` run on its eyes' images.
    ``hears``: the microphones are worked out and each robot's latest block kept.

    The eyes as the ROS door has them (learn.eyes): ``camera_rate`` (Hz; None: drawn at
    each look()), ``jpeg_quality`` (1-100; None: uncompressed), ``latency_s`` (at most one
    camera period) and ``detection`` (the detectors' DetectionParams, default its defaults;
    controller.params.detection_params gives a controller host's). The defaults keep the
    cheap eyes that replay exactly; ValueError in one line for an option the eyes can not
    have, or any of the first three without eyes."""

    def __init__(self, world='miro', eyes=None, lens=PINHOLE, detectors=(), hears=False,
                 renderer='auto', camera_rate=None, jpeg_quality=None, latency_s=0.0,
                 detection=None):
        if eyes is None and (camera_rate, jpeg_quality, latency_s) != (None, None, 0):
            raise ValueError('camera_rate, jpeg_quality and latency_s are options of the '
                             'eyes: give eyes=(w, h)')
        # Checked before a build (the lens and the renderer in the simulator's words): a
        # refusal after one left its PyBullet world connected, one more each try.
        check_options(camera_rate, jpeg_quality, latency_s, detection)
        values_of(SimParams, {'lens': lens, 'renderer': renderer})
        detectors = tuple(detectors)
        check_names(detectors)
        built = not isinstance(world, SimWorld)
        self.sim = SimWorld(world) if built else world
        try:
            self.camera = None if eyes is None else CameraModel(*eyes, lens, CAM_HFOV_DEG_SIM)
            self.renderer = renderer
            self.cameras = None
            self.eyes = None
            if eyes is not None:
                self.eyes = RigEyes(self.sim, self._cameras(), self.camera, detectors,
                                    camera_rate, jpeg_quality, latency_s, detection)
        except BaseException:  # whatever else fails (no EGL...): the world is not left open
            if built:
                self.sim.close()
            raise
        self.hears = hears
        self.heard = {}  # robot -> the latest MicBlock
        self._warn = Throttled(logging.getLogger(__name__).warning)

    # -- time ---------------------------------------------------------------------------------
    @property
    def t(self):
        return self.sim.time

    def check_open(self):
        """RuntimeError once closed (PyBullet's own error says only 'Not connected to
        physics server', or a TypeError)."""
        if self.sim.client is None:
            raise RuntimeError('the environment is closed')

    def restore(self):
        """The world as it was built: bodies, robots' platforms, time; no rebuild (but of a
        world holding a non-finite value: SimWorld.rewind)."""
        self.check_open()
        self.sim.rewind()
        if self.eyes is not None:
            self.eyes.restart()
        self.heard.clear()

    def tick(self, observe=None):
        """One platform tick (its physics steps); ``observe(sim)`` after each physics step
        (a judge sees every contact, however brief)."""
        self.check_open()
        sim = self.sim
        listening = sim.robots if self.hears else ()
        # Eyes on the simulator's camera schedule are drawn at the physics step it says.
        eyes = self.eyes if self.eyes is not None and self.eyes.scheduled else None
        for _ in range(sim.ticks_per_platform_tick):
            sim.step(listening=listening)
            if observe is not None:
                observe(sim)
            if eyes is not None:
                eyes.after_step()
        if self.hears:
            for name, robot in sim.robots.items():
                if robot.heard is not None:
                    self.heard[name] = robot.heard

    def look(self):
        """Draw every robot's eyes now (one pass for all) and run their detectors, once a
        frame: the motion detector compares each frame with its eye's previous one. With a
        camera_rate the eyes are drawn at their instants instead, as tick() steps through
        them: nothing to do here."""
        self.check_open()
        if self.eyes is not None:
            self.eyes.look()

    def _cameras(self):
        self.check_open()
        if self.cameras is None:
            self.cameras = Cameras(self.sim, self.renderer, log=lambda _: None)
        return self.cameras

    def view(self, position, rotation, intrinsics):
        """An RGB picture from any camera pose (x forward, y left, z up)."""
        return self._cameras().render_view(position, rotation, intrinsics)

    def overhead(self):
        """An RGB picture of the whole world from straight above."""
        from miro_sim_bullet.render.overhead import overhead_camera

        image = self.view(*overhead_camera(self.sim.description))
        return np.ascontiguousarray(image[..., :3])

    # -- the contract -------------------------------------------------------------------------
    def percepts(self, name):
        """Robot ``name``'s Percepts now: its latest tick's readings, its eyes' latest
        images in and the detectors' results in them (each Eye's stamp: the simulated time
        its images are of)."""
        self.check_open()
        robot = self.sim.robots[name]
        sensors = robot.sensors
        eyes = (Eye(None),) * 2 if self.eyes is None else self.eyes.seen(name)
        heard = self.heard.get(name)
        sound = None if heard is None else locate(heard.samples, sensors.kinematic_positions)
        return Percepts(
            t=self.t, eyes=tuple(eyes), cliff=tuple(sensors.cliff), sonar=sensors.sonar,
            touch_head=sensors.touch_head, touch_body=sensors.touch_body,
            light=tuple(sensors.light), joints=tuple(sensors.kinematic_positions), sound=sound)

    def act(self, name, action):
        """Hand robot ``name`` each part of ``action`` that is set, by the path and checks of
        its control topics (physics.commands: the wheels through the MDK's cmd_vel formula,
        as the controller host sends them). A part they would ignore (a wrong length, a
        non-finite number) is dropped with a rate-limited warning, the robot keeping what
        it was told before; returns {part: why} of those dropped."""
        self.check_open()
        refused = take(self.sim.robots[name], **parts(action)).refused
        for part, why in refused.items():
            self._warn(part, f'{name}: action {part} ignored: {why}')
        return refused

    def close(self):
        """Free the world and the renderers; a second close() does nothing."""
        if self.cameras is not None:
            self.cameras.close()
            self.cameras = None
        self.sim.close()

