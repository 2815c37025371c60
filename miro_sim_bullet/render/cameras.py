"""The cameras of a simulated world: any robot's eyes and any camera pose, drawn from
the world's PyBullet client (physics knows nothing of them)."""
import cv2

from miro_sim_bullet.render.eye_workers import EyeWorkers
from miro_sim_bullet.render.renderer import Renderer, view_matrix_from_pose


class Cameras:
    """Images of ``world`` (a SimWorld) with a Renderer of ``kind`` ('auto', 'tiny' or
    'egl'; RendererUnavailable if 'egl' can not be had). eye_workers: with TinyRenderer,
    the eyes are drawn in two helper processes, each with its own copy of the world.
    ``renderer`` tells what draws (name, device); ``eye_workers`` is None or the workers.
    """

    def __init__(self, world, kind='auto', log=print, eye_workers=False):
        self.world = world
        self.renderer = Renderer(world.client, kind=kind, log=log,
                                 pictures=world.description.pictures)
        self._generation = world.generation  # the bodies the renderer has read
        self.eye_workers = None
        self._plans = {}  # CameraModel -> its render plan (the lens maps take ~20 ms)
        if eye_workers and self.renderer.kind == 'tiny':
            self.eye_workers = EyeWorkers(world.description, world.dt, world.robot_name)
            log('eyes rendered in 2 worker processes')

    def _current(self):
        """The renderer, after it has read the bodies of a rebuilt (reset) world."""
        if self._generation != self.world.generation:
            self.renderer.scene_changed()
            self._generation = self.world.generation
        return self.renderer

    def render_eyes(self, requests, camera):
        """RGB images, one per (robot, side) in requests (side +1 left, -1 right), all of
        this instant, as the eyes' CameraModel ``camera`` sees: a pinhole is drawn as it
        is, a distorting lens drawn wider and resampled through it."""
        return self.render_views(
            [view_matrix_from_pose(*robot.eye_pose(side)) for robot, side in requests], camera)

    def render_views(self, views, camera):
        """RGB images through CameraModel ``camera`` from OpenGL view matrices."""
        if camera not in self._plans:
            self._plans[camera] = camera.render_plan()
        drawn, maps = self._plans[camera]
        if self.eye_workers is None:
            images = self._current().render_many(views, drawn)
        else:
            images = self.eye_workers.render(self.world.snapshot(), views, drawn)
        if maps is None:
            return images
        return [cv2.remap(image, *maps, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE)
                for image in images]

    def render_view(self, position, rotation, intrinsics):
        """RGB image from any camera pose (x forward, y left, z up)."""
        return self._current().render(view_matrix_from_pose(position, rotation), intrinsics)

    def close(self):
        """Stop the workers and release the renderer. Idempotent."""
        if self.eye_workers is not None:
            self.eye_workers.close()
            self.eye_workers = None
        self.renderer.close()
