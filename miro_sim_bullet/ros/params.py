"""The simulator's ROS parameters: one dataclass drives declaration, checks and --help."""
from dataclasses import dataclass, field

from miro_ball.common.ros_params import check_ranges
from miro_ball.miro.camera_model import LENSES, PINHOLE
from miro_ball.miro.constants import CAM_HFOV_DEG_SIM, FRAME_SIZES
from miro_sim_bullet.physics.world import PHYSICS_DT_S

RENDERERS = ('auto', 'tiny', 'egl')


@dataclass(frozen=True)
class SimParams:
    world: str = field(default='miro',
                       metadata={'help': 'bundled world name or path to a .toml world file'})
    sound_folders: str = field(
        default='', metadata={'help': "folders (separated by ':') whose sound files "
                                      '/miro_sim/sound and the world file may play, besides the '
                                      "bundled sounds and the world file's own folder"})
    world_folders: str = field(
        default='', metadata={'help': "folders (separated by ':') whose world files, models and "
                                      'pictures clients may load, spawn and list (load_world, '
                                      'spawn_entity, get_available_worlds), besides the bundled '
                                      'ones; none by default'})
    real_time_factor: float = field(
        default=1.0, metadata={'help': 'simulated seconds per wall second; 0 = as fast as possible',
                               'range': (0.0, 1000.0)})
    paused: bool = field(default=False, metadata={
        'help': 'start paused (then set_simulation_state, step_simulation)'})
    step_count: int = field(
        default=10, metadata={'help': 'physics steps per ~/step call, the older alias of '
                                      'step_simulation (10 = one 20 ms tick at 2 ms)',
                              'range': (1, 100000)})
    physics_dt: float = field(default=PHYSICS_DT_S, metadata={'help': 'physics step, s',
                                                              'range': (0.0001, 0.02)})
    frame_width: int = field(default=640, metadata={'help': 'eye camera width: 1280, 640 or 320',
                                                   'range': (320, 1280)})
    frame_height: int = field(default=360,
                              metadata={'help': 'eye camera height: 720, 360 or 240',
                                        'range': (240, 720)})
    camera_rate: float = field(default=15.0,
                               metadata={'help': 'eye camera frames per simulated second',
                                         'range': (0.1, 100.0)})
    hfov_deg: float = field(default=CAM_HFOV_DEG_SIM,
                            metadata={'help': 'eye camera horizontal field of view, deg '
                                              '(pinhole lens)', 'range': (1.0, 179.0)})
    # Pinhole by default: the tutorial's Gazebo eyes are pinholes too (the MDK's
    # use_wideanglecamera_eyes=0), and a pinhole costs a third of the drawing.
    lens: str = field(default=PINHOLE,
                      metadata={'help': 'eye camera lens: pinhole (hfov_deg wide, no distortion) '
                                        "| miro (MiRo's wide-angle lens, 121 x 64 deg, "
                                        'equidistant distortion in camera_info)'})
    renderer: str = field(default='auto', metadata={'help': ' | '.join(RENDERERS)})
    eye_workers: bool = field(
        default=True, metadata={'help': 'running on its timer, draw and encode the eyes in '
                                        'helper processes while physics steps on (egl 1, '
                                        'tiny 2); false: in the simulator thread'})
    jpeg_quality: int = field(default=80,
                              metadata={'help': 'JPEG quality of sensors/cam?/compressed',
                                        'range': (1, 100)})
    # A running simulator is usually found in 30 ms, but now and then only at its next
    # Fast DDS announcement, which comes every 3 s (measured: 1.4 s and 1.9 s).
    peer_check_s: float = field(
        default=3.5, metadata={'help': 'wall seconds to look for another simulator (/clock '
                                       'publisher) on the ROS domain before starting, and '
                                       'refuse if there is one; 0 = do not look',
                               'range': (0.0, 10.0)})
    overhead_rate: float = field(
        default=0.0, metadata={'help': 'frames per simulated second of ~/overhead/compressed; '
                                       '0 = off', 'range': (0.0, 100.0)})

    def __post_init__(self):
        check_ranges(self)
        size = (self.frame_width, self.frame_height)
        if size not in FRAME_SIZES:
            raise ValueError(f"frame size {size[0]}x{size[1]} is not one of MiRo's: "
                             + ', '.join(f'{w}x{h}' for w, h in FRAME_SIZES))
        checks = (('world', self.world != '', 'a world name or a path'),
                  ('renderer', self.renderer in RENDERERS, ' or '.join(RENDERERS)),
                  ('lens', self.lens in LENSES, ' or '.join(LENSES)))
        for name, ok, rule in checks:
            if not ok:
                raise ValueError(f'parameter {name} must be {rule}, got {getattr(self, name)!r}')
