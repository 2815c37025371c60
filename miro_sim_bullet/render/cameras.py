"""The cameras of a simulated world: any robot's eyes and any camera pose, drawn from
the world's PyBullet client (physics knows nothing of them)."""
import cv2

from miro_sim_bullet.render.renderer import Renderer, view_matrix_from_pose


class LensPlans(dict):
    """CameraModel -> its render plan (the pinhole intrinsics to draw, and the maps that
    resample through its lens or None), each made once: the lens maps take ~20 ms."""

    def __missing__(self, camera):
        plan = self[camera] = camera.render_plan()
        return plan


def through_lens(images, maps):
    """Images drawn as a plan's pinhole, resampled through its lens (maps None: as drawn)."""
    if maps is None:
        return images
    return [cv2.remap(image, *maps, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE)
            for image in images]


class Cameras:
    """Images of ``world`` (a SimWorld) with a Renderer of ``kind`` ('auto', 'tiny' or
    'egl'; RendererUnavailable if 'egl' can not be had). ``renderer`` tells what draws
    (name, device). Drawing the eyes while the world steps on is render.eye_pipeline's;
    helper_setup() and helper_state() are what its helper processes need to draw alike.
    """

    def __init__(self, world, kind='auto', log=print):
        self.world = world
        # A shape changes colour at run time only as a robot's LEDs do (set_illum).
        self.renderer = Renderer(world.client, kind=kind, log=log,
                                 pictures=world.description.pictures,
                                 colour_key=lambda: [tuple(robot.illum)
                                                     for robot in world.robots.values()])
        self._generation = world.generation  # the bodies the renderer has read
        self._plans = LensPlans()

    def _current(self):
        """The renderer, after it has read the bodies of a rebuilt (reset) world, with the
        robots' drawn-only parts (tail, eyelids, ears, LEDs) posed as they are now."""
        for robot in self.world.robots.values():
            robot.pose_drawn()
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
        drawn, maps = self._plans[camera]
        return through_lens(self._current().render_many(views, drawn, rgba=rgba), maps)

    def render_view(self, position, rotation, intrinsics):
        """RGB image from any camera pose (x forward, y left, z up)."""
        return self._current().render(view_matrix_from_pose(position, rotation), intrinsics)

    # -- for helper processes -----------------------------------------------------------------
    def helper_setup(self):
        """(generation, setup): what a process needs to draw this world as this renderer
        does, picklable, and the world build it is of. egl: the scene's layout (no PyBullet
        needed); tiny: the world's description, to build a copy of it."""
        renderer = self._current()
        world = self.world
        if renderer.kind == 'egl':
            return self._generation, ('egl', renderer.layout)
        return self._generation, ('tiny', world.description, world.dt, world.robot_name)

    def helper_state(self):
        """What changes between instants, for helper_setup()'s drawing: egl the moving
        instances' rows, tiny a snapshot of the world."""
        renderer = self._current()
        return renderer.moving_rows() if renderer.kind == 'egl' else self.world.snapshot()

    def close(self):
        """Release the renderer. Idempotent."""
        self.renderer.close()
