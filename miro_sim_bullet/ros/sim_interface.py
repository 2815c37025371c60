"""The simulator's own ROS interface under /miro_sim/ (SimTopics), beside each robot's.

Ground truth of every movable object and robot in the 'world' frame, the overhead
view, the sounds played and stopped, and the older set_pose topic and reset, pause and
step services: thin aliases of the standard's set_entity_state, reset_simulation,
set_simulation_state and step_simulation (sim_control), kept for old scripts. What these
do to time (a reset starts the schedule over, a step advances it) belongs to the node that
paces the world, so the services call the functions it hands in.
"""
from geometry_msgs.msg import PointStamped, PoseStamped
from rclpy.clock import Clock, ClockType
from rclpy.qos import QoSProfile, ReliabilityPolicy
from sensor_msgs.msg import CompressedImage
from std_msgs.msg import String
from std_srvs.srv import SetBool, Trigger

from miro_ball.common.qos import profile
from miro_ball.miro.interface import SimTopics, TRUTH_QOS
from miro_sim_bullet.acoustics.loading import SoundLoads
from miro_sim_bullet.render.overhead import overhead_camera
from miro_sim_bullet.render.eye_images import jpeg_bytes
from miro_sim_bullet.ros import convert
from miro_sim_bullet.ros.endpoints import send_if_listened
from miro_sim_bullet.scene.world_checks import load_sounds
from miro_sim_bullet.scene.world_model import WorldError

# ROS's default keeps 10 requests: a burst of 200 clients lost 190 answers.
SERVICE_QOS = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE)
OVERHEAD_FRAME = 'overhead'
LOADED_PERIOD_S = 0.02  # wall seconds between looks for sound files read


class SimInterface:
    """The topics and services of the simulator itself.

    ros: Endpoints; world: the SimWorld; cameras: its Cameras (the overhead view);
    reset(): back to the start; pause(bool) -> whether now paused; step() ->
    (done, message); warn(kind, message): a rate-limited warning; sound_folders: where
    /miro_sim/sound may take files from, besides the bundled sounds (scene.sounds).
    """

    def __init__(self, ros, world, cameras, *, reset, pause, step, warn, sound_folders=()):
        self.world, self.cameras = world, cameras
        self._reset, self._pause, self._step, self._warn = reset, pause, step, warn
        self.sound_folders = sound_folders
        self.loads = SoundLoads()
        self.overhead = overhead_camera(world.description)
        t = SimTopics()
        self.pub_ball = ros.publisher(PointStamped, t.ball, profile(TRUTH_QOS))
        # A robot's every touch of a tick would be 10 messages; its first is what counts.
        self.pub_touches = ros.publisher(PointStamped, t.touches, 10 * len(world.robots))
        self._touches = {}  # robot name -> (simulated s, ball x, y, z) of this tick's first
        self._ros = ros
        self.pub_objects = {}  # name -> publisher of its ground truth (sync_objects())
        self.sync_objects()
        self.pub_overhead = ros.publisher(CompressedImage, t.overhead, 2)
        self.sub_set_pose = ros.subscription(PoseStamped, t.set_pose, self._on_set_pose, 10)
        self.sub_sound = ros.subscription(String, t.sound, self._on_sound, 10)
        self.sub_sound_off = ros.subscription(String, t.sound_off, self._on_sound_off, 10)
        self.loaded_timer = ros.timer(LOADED_PERIOD_S, self._play_loaded,
                                      clock=Clock(clock_type=ClockType.STEADY_TIME))
        self.srvs = [
            ros.service(Trigger, t.reset, self._on_reset, qos_profile=SERVICE_QOS),
            ros.service(SetBool, t.pause, self._on_pause, qos_profile=SERVICE_QOS),
            ros.service(Trigger, t.step, self._on_step, qos_profile=SERVICE_QOS),
        ]

    def sync_objects(self):
        """A ground-truth publisher for every movable object and robot there is now (they
        come and go at run time: spawned, deleted, another world loaded)."""
        wanted = {*self.world.objects, *self.world.robots}
        for name in [name for name in self.pub_objects if name not in wanted]:
            self._ros.destroy_publisher(self.pub_objects.pop(name))
        for name in sorted(wanted - set(self.pub_objects)):
            self.pub_objects[name] = self._ros.publisher(
                PoseStamped, SimTopics().object_pose(name), profile(TRUTH_QOS))

    def world_loaded(self, cameras):
        """Another world was loaded: its overhead view, drawn by its cameras."""
        self.cameras = cameras
        self.overhead = overhead_camera(self.world.description)
        self.sync_objects()

    # -- requests -----------------------------------------------------------------------------
    def _on_set_pose(self, msg):
        try:
            name, position, orientation = convert.pose_request(msg)
            self.world.set_object_pose(name, position, orientation)
        except ValueError as err:
            self._warn('set_pose', f'set_pose ignored: {err}')
        except KeyError:
            self._warn('set_pose_name', f'set_pose ignored: no object or robot named '
                       f'{msg.header.frame_id!r} (header.frame_id); there are '
                       f'{", ".join(self.pub_objects)}')

    def _on_sound(self, msg):
        """Tones and noise play at once; a file plays once read, off this thread."""
        try:
            for sound in load_sounds(msg.data, SimTopics().sound, self.sound_folders):
                if sound.kind == 'file':
                    self.loads.ask(sound)
                else:
                    self.world.acoustics.add_sound(sound)
        except (WorldError, ValueError) as err:
            self._warn('sound', f'sound ignored: {err}')

    def _play_loaded(self):
        # ``samples`` stays alive while the sound's source is made: the source takes it from
        # the bank instead of reading the file again here.
        for sound, samples, error in self.loads.ready():
            try:
                if error is not None:
                    raise error
                self.world.acoustics.add_sound(sound)
            except ValueError as err:
                self._warn('sound', f'sound {sound.name!r} ignored: {err}')

    def _on_sound_off(self, msg):
        if msg.data not in self.world.acoustics.sounds:
            self._warn('sound_off', f'sound_off ignored: no sound {msg.data[:64]!r} plays; '
                       f'there are {", ".join(self.world.acoustics.sounds) or "none"}')
        self.world.acoustics.remove_sound(msg.data)

    def _on_reset(self, request, response):
        self._reset()
        response.success, response.message = True, 'world reset to its initial state'
        return response

    def _on_pause(self, request, response):
        paused = self._pause(bool(request.data))
        response.success, response.message = True, 'paused' if paused else 'running'
        return response

    def _on_step(self, request, response):
        response.success, response.message = self._step()
        return response

    # -- publishing ---------------------------------------------------------------------------
    def look_for_touches(self):
        """After each physics step: which robots touch the ball (only while the touches are
        listened to: a contact query per robot and step)."""
        world = self.world
        if world.ball_id is None or not self.pub_touches.get_subscription_count():
            return
        for name in world.robots:
            if name not in self._touches and world.touching(name):
                self._touches[name] = (world.time, world.ball_position())

    def forget_touches(self):
        """The world was reset: the touches before it are not of the new one."""
        self._touches.clear()

    def publish_ground_truth(self, when):
        """Every movable object's and robot's pose, and the ball's centre, stamped when;
        first the touches of the tick that ends now."""
        world = self.world
        for name, (t, ball) in self._touches.items():
            msg = convert.point(ball, convert.stamp(t))
            msg.header.frame_id = name
            self.pub_touches.publish(msg)
        self._touches.clear()
        for name, (position, orientation) in world.object_poses().items():
            send_if_listened(self.pub_objects[name],
                             lambda: convert.pose(position, orientation, when))
        for name, robot in world.robots.items():
            send_if_listened(self.pub_objects[name],
                             lambda: convert.robot_pose(*robot.ground_truth(), when))
        if world.ball_id is not None:
            send_if_listened(self.pub_ball, lambda: convert.point(world.ball_position(), when))

    def publish_overhead(self, when, jpeg_quality):
        """The view from above, drawn only while someone subscribes."""
        if self.pub_overhead.get_subscription_count():
            rgb = self.cameras.render_view(*self.overhead)
            self.pub_overhead.publish(convert.compressed_image(jpeg_bytes(rgb, jpeg_quality),
                                                               when, OVERHEAD_FRAME))
