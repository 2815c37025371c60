"""The simulator's ROS parameters: one dataclass drives declaration, checks and --help."""
from dataclasses import dataclass, field

from miro_ball.miro.constants import CAM_HFOV_DEG_SIM, FRAME_SIZES
from miro_ball.miro.interface import check_name, default_robot_name

RENDERERS = ('auto', 'tiny', 'egl')


@dataclass(frozen=True)
class SimParams:
    robot_name: str = field(
        default_factory=default_robot_name,
        metadata={'help': "name of the world's robot when its file names none (topic prefix "
                          "/<robot_name>/); default $MIRO_ROBOT_NAME, else miro"})
    world: str = field(default='miro',
                       metadata={'help': 'bundled world name or path to a .toml world file'})
    real_time_factor: float = field(
        default=1.0, metadata={'help': 'simulated seconds per wall second; 0 = as fast as possible'})
    paused: bool = field(default=False, metadata={'help': 'start paused (use ~/pause, ~/step)'})
    step_count: int = field(default=20, metadata={'help': 'physics steps per ~/step call'})
    physics_dt: float = field(default=0.001, metadata={'help': 'physics step, s'})
    frame_width: int = field(default=640, metadata={'help': 'eye camera width: 1280, 640 or 320'})
    frame_height: int = field(default=360,
                              metadata={'help': 'eye camera height: 720, 360 or 240'})
    camera_rate: float = field(default=15.0,
                               metadata={'help': 'eye camera frames per simulated second'})
    hfov_deg: float = field(default=CAM_HFOV_DEG_SIM,
                            metadata={'help': 'eye camera horizontal field of view, deg'})
    renderer: str = field(default='auto', metadata={'help': ' | '.join(RENDERERS)})
    eye_workers: bool = field(
        default=True, metadata={'help': 'with TinyRenderer, render eyes in 2 worker processes'})
    jpeg_quality: int = field(default=80,
                              metadata={'help': 'JPEG quality of sensors/cam?/compressed'})
    overhead_rate: float = field(
        default=0.0, metadata={'help': 'frames per simulated second of ~/overhead/compressed; '
                                       '0 = off'})

    def __post_init__(self):
        size = (self.frame_width, self.frame_height)
        if size not in FRAME_SIZES:
            raise ValueError(f"frame size {size[0]}x{size[1]} is not one of MiRo's: "
                             + ', '.join(f'{w}x{h}' for w, h in FRAME_SIZES))
        check_name(self.robot_name, 'robot_name')
        checks = (('world', self.world != '', 'a world name or a path'),
                  ('renderer', self.renderer in RENDERERS, ' or '.join(RENDERERS)),
                  ('camera_rate', 0 < self.camera_rate <= 100, 'in (0, 100] Hz'),
                  ('physics_dt', 0.0001 <= self.physics_dt <= 0.02, 'in [0.0001, 0.02] s'),
                  ('real_time_factor', 0 <= self.real_time_factor <= 1000, 'in [0, 1000]'),
                  ('hfov_deg', 0 < self.hfov_deg < 180, 'in (0, 180)'),
                  ('step_count', 1 <= self.step_count <= 100000, 'in 1..100000'),
                  ('jpeg_quality', 1 <= self.jpeg_quality <= 100, 'in 1..100'),
                  ('overhead_rate', 0 <= self.overhead_rate <= 100, 'in [0, 100] Hz'))
        for name, ok, rule in checks:
            if not ok:
                raise ValueError(f'parameter {name} must be {rule}, got {getattr(self, name)!r}')
