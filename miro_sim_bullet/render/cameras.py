"""The cameras of a simulated world: any robot's eyes and any camera pose, drawn from
the world's PyBullet client (physics knows nothing of them)."""
import cv2

from miro_sim_bullet.render.renderer import Renderer, view_matrix_from_pose


class Cameras:
    """Images of ``world`` (a SimWorld) with a Renderer of ``kind`` ('auto', 'tiny' or
    'egl'; RendererUnavailable if 'egl' can not be had). ``renderer`` tells what draws
    (name, device). Drawing the eyes while the world steps on is render.eye_pipeline's.
    """

    def __init__(self, world, kind='auto', log=print):
        self.world = world
        self.renderer = Renderer(world.client, kind=kind, log=log,
                                 pictures=world.description.pictures)
        self._generation = world.generation  # the bodies the renderer has read
        self._plans = {}  # CameraModel -> its render plan (the lens maps take ~20 ms)

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
        return self.render_views(self.eye_views(requests), camera)

    @staticmethod
    def eye_views(requests):
        """OpenGL view matrices of the eyes (robot, side) of this instant."""
        return [view_matrix_from_pose(*robot.eye_pose(side)) for robot, side in requests]

    def render_views(self, views, camera, rgba=False):
        """RGB images (RGBA with ``rgba``: cheaper to read back) through CameraModel
        ``camera`` from OpenGL view matrices."""
        if camera not in self._plans:
            self._plans[camera] = camera.render_plan()
        drawn, maps = self._plans[camera]
        images = self._current().render_many(views, drawn, rgba=rgba)
        if maps is None:
            return images
        return [cv2.remap(image, *maps, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE)
                for image in images]

    def render_view(self, position, rotation, intrinsics):
        """RGB image from any camera pose (x forward, y left, z up)."""
        return self._current().render(view_matrix_from_pose(position, rotation), intrinsics)

    def close(self):
        """Release the renderer. Idempotent."""
        self.renderer.close()
