"""miro_sim: the rclpy node that owns a SimWorld and paces its time.

The world's ROS side is two kinds of interface the node makes and hands what they
need: each robot's (RobotInterface, MiRo's topics under /<name>/) and the
simulator's own (SimInterface: ground truth, the overhead view, set_pose, reset,
pause, step). The node itself publishes /clock from physics time and decides when
everything is published. Either a steady wall-clock timer advances the world
(real_time_factor 1.0 = real time, 0 = as fast as possible), or, when paused, the
~/step service or in-process code calls advance().

When the timer advances the world, the eyes of a camera instant are drawn and encoded in
a helper process (render.eye_pipeline) while physics steps on, and published as soon as
they are done: at the latest before the instant after next is asked for (IN_FLIGHT), so
at most two camera periods of simulated time after their own /clock. Stepped (advance(), ~/step) or
paused, every image is out before advance() returns, in the order a blocking renderer
gives: an instant's images, then its /clock.
"""
import argparse
import collections
import sys
import time
from pathlib import Path

import cv2
from rclpy.clock import Clock, ClockType
from rclpy.experimental import EventsExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter
from rosgraph_msgs.msg import Clock as ClockMsg

from miro_ball.common.cli import user_args
from miro_ball.common.clock_watch import ClockWatch
from miro_ball.common.files import folders_parameter
from miro_ball.common.lifecycle import run_node
from miro_ball.common.ros_params import declare, help_lines, LiveParams
from miro_ball.common.qos import profile
from miro_ball.common.throttle import Throttled
from miro_ball.miro.camera_model import CameraModel
from miro_ball.miro.interface import CLOCK, CLOCK_QOS, PLATFORM, robot_name, SIM_NODE_NAME, \
    TF, TF_STATIC, TF_TYPE
from miro_ball.miro.stream_kinds import BLOCK, CAMERA, Schedule, Timing
from miro_sim_bullet.control.codes import SimulationState
from miro_sim_bullet.physics.world import SimWorld
from miro_sim_bullet.render.cameras import Cameras
from miro_sim_bullet.render.eye_pipeline import EyePipeline, IN_FLIGHT
from miro_sim_bullet.render.renderer import RendererUnavailable
from miro_sim_bullet.ros import convert
from miro_sim_bullet.ros.domain_guard import refuse_shared_domain, SharedDomain
from miro_sim_bullet.ros.endpoints import Endpoints
from miro_sim_bullet.ros.params import SimParams
from miro_sim_bullet.ros.robot_interface import RobotInterface
from miro_sim_bullet.ros.scene import SCENE_RATE_HZ
from miro_sim_bullet.ros.scene_interface import SceneInterface
from miro_sim_bullet.ros.sim_interface import SimInterface
from miro_sim_bullet.ros.tf import TfInterface
from miro_sim_bullet.scene.world_file import bundled_worlds, load_world, world_uri
from miro_sim_bullet.scene.world_model import World, WorldError

try:  # simulation_interfaces is built at set-up (python -m miro_ball.build_interfaces)
    from miro_sim_bullet.ros.sim_control import ControlInterface
    from miro_sim_bullet.ros.step_action import StepAction
except ModuleNotFoundError as missing:
    if missing.name != 'simulation_interfaces':
        raise
    ControlInterface = StepAction = None

TYPE_CHECK_PERIOD_S = 1.0  # wall seconds between looks for control publishers of a wrong type
# The states a world runs or pauses in: pausing leaves the others as they are.
_RUNNABLE = (SimulationState.PLAYING, SimulationState.PAUSED, SimulationState.STOPPED)
# Made into the world, its robots, cameras and topics at start; the rest apply at run time.
FIXED_PARAMS = ('world', 'sound_folders', 'world_folders', 'physics_dt', 'frame_width',
                'frame_height', 'camera_rate', 'hfov_deg', 'lens', 'renderer', 'eye_workers',
                'peer_check_s')


class SimNode(Node):
    """MiRo-E robots in PyBullet behind MiRo's topics; see docs for the topic table.

    robot names the world's robot when its file names none, as --robot does (default
    $MIRO_ROBOT_NAME, else 'miro'); ValueError in one line if it can not be a ROS name.
    guard_domain, as the command line simulator does: refuse to start (SharedDomain) when
    another node publishes /clock on the ROS domain, and say so once, in one line, when
    one appears later.
    privileged=False offers MiRo's own interface and /clock only: no ground truth, scene,
    overhead view, set_pose, reset, pause, step or parameter services. A grader that runs
    untrusted code beside it places, paces and judges the world in-process (miro_ball's
    grading host); nothing on the ROS graph can.
    """

    def __init__(self, *, context=None, parameter_overrides=None, robot=None,
                 guard_domain=False, privileged=True):
        overrides = list(parameter_overrides or [])
        if not privileged:
            overrides.append(Parameter('start_type_description_service', value=False))
        super().__init__(SIM_NODE_NAME, context=context, parameter_overrides=overrides,
                         start_parameter_services=privileged)
        unnamed_robot = robot_name(robot)
        self.params = p = declare(self, SimParams)
        self._live = LiveParams(self, (p,), self._apply, fixed=FIXED_PARAMS)
        self.warn = Throttled(self.get_logger().warning)
        self.said = Throttled(self.get_logger().info)  # what clients ask often (a reset)
        # The world file is read first: a typo in its name is said at once, not after the
        # look for another simulator (peer_check_s).
        self.sound_folders = folders = folders_parameter('sound_folders', p.sound_folders)
        self.world_folders = folders_parameter('world_folders', p.world_folders)
        world = load_world(p.world, folders)
        self.world_uri = world_uri(p.world) if p.world in bundled_worlds() \
            else str(Path(p.world).resolve())
        # Before the look for another simulator: two started together see each other.
        self.pub_clock = self.create_publisher(ClockMsg, CLOCK, profile(CLOCK_QOS))
        if guard_domain:  # before the world is built: a refusal costs no time
            refuse_shared_domain(self, p.peer_check_s)
            self._clock_watch = ClockWatch(self, own=1)
        self.robot_name = unnamed_robot
        self.sim = SimWorld(world, physics_dt=p.physics_dt, robot_name=unnamed_robot)
        self._make_cameras()
        self.camera = CameraModel(p.frame_width, p.frame_height, p.lens, p.hfov_deg)
        # The standard's simulation state (control.codes.SimulationState): playing, paused,
        # stopped (reset and paused), no world, a world loading, quitting.
        self.state = SimulationState.PAUSED if p.paused else SimulationState.PLAYING
        self.frames_published = 0
        # Seconds spent drawing and encoding each camera instant (summed over helper processes).
        self.render_seconds = []
        # Wall seconds per stage of the loop in this thread (the benchmark's profile).
        self.stage_seconds = collections.Counter()
        ros = Endpoints.of(self)
        self.robots = {}  # name -> RobotInterface
        self._robot_endpoints = {}  # name -> the Endpoints its interface was made with
        self._sync_robots()
        self.sim_interface = self.scene = self.control = self.step_action = None
        if privileged:
            self.sim_interface = SimInterface(ros, self.sim, self.cameras,
                                              reset=lambda: self.reset(0), pause=self.pause,
                                              step=self.step_count, warn=self.warn,
                                              sound_folders=folders)
            self.scene = SceneInterface(ros, self.sim)
            if ControlInterface is not None:
                self.control = ControlInterface(ros, self, self.warn, self.get_logger().error)
                self.step_action = StepAction(self, self.context)
        # Called after every physics step with the world: an in-process judge sees each
        # contact, however brief.
        self.step_observers = []
        self.get_logger().info(
            f'world {self.sim.description.source}; robots {", ".join(self.robots)}; renderer '
            f'{self.cameras.renderer.name}; cameras {p.frame_width}x{p.frame_height} @ '
            f'{p.camera_rate:g} Hz; real-time factor {p.real_time_factor:g}')
        self.tf = self._tf_endpoints = None
        self._make_tf()
        missing = [(row.name, row.type) for row in next(iter(self.robots.values())).missing_types]
        if self.tf is None:
            missing.append((f'{TF} and {TF_STATIC}', TF_TYPE))
        if privileged and ControlInterface is None:
            missing.append(('the standard control services (get_entities, spawn_entity, ...)',
                            'simulation_interfaces'))
        for name, type_name in missing:
            self.get_logger().warning(
                f'{name} not published: its type {type_name} is not installed (build it: '
                'python -m miro_ball.build_interfaces)')
        # When the eyes and each kind of the robots' sensor streams are due; /clock and the
        # ground truth go with the platform tick.
        self.schedule = Schedule(
            [PLATFORM, CAMERA, *(kind for i in self.robots.values() for kind in i.streams)],
            Timing(self.sim.dt, self.sim.ticks_per_platform_tick, p.camera_rate))
        self._restart_schedule()
        # The progress line's real-time factor counts the steps taken, not the clock's
        # change: a reset between two lines made it negative.
        self.steps_taken = 0
        self._progress = (time.monotonic(), 0)
        self.timer = self._make_timer()
        # A Twist on control/cmd_vel (the MDK's is TwistStamped) is not heard at all: say so.
        self._wrong_types_said = set()
        self._type_check = self.create_timer(TYPE_CHECK_PERIOD_S, self._check_control_types,
                                             clock=Clock(clock_type=ClockType.STEADY_TIME))

    def _robot_lookup(self, name):
        # The world's robots are made anew by a reset: looked up each time.
        return lambda: self.sim.robots[name]

    def _make_cameras(self):
        self.cameras = Cameras(self.sim, self.params.renderer, log=self.get_logger().info)
        self.eyes = EyePipeline(self.cameras, self.params.eye_workers,
                                log=self.get_logger().info, warn=self.get_logger().warning)

    def _sync_robots(self):
        """A RobotInterface for each robot of the world, and none for a robot gone."""
        for name in [name for name in self.robots if name not in self.sim.robots]:
            del self.robots[name]
            self._robot_endpoints.pop(name).destroy()
        for name in self.sim.robots:
            if name not in self.robots:
                ros = self._robot_endpoints[name] = Endpoints.owned(self)
                self.robots[name] = RobotInterface(name, ros, self._robot_lookup(name),
                                                   self.warn)

    def _make_tf(self):
        """/tf and /tf_static for the robots there are now (made again when they change:
        /tf_static keeps one message, which must hold every robot's fixed frames)."""
        if self._tf_endpoints is not None:
            self._tf_endpoints.destroy()
        self._tf_endpoints = Endpoints.owned(self)
        try:
            self.tf = TfInterface(self._tf_endpoints, self.sim, convert.stamp(self.sim.time))
        except ValueError:
            self.tf = None

    def _make_timer(self):
        # Free-running, the simulator steps whenever the executor is free (period 0);
        # paused, such a timer would keep a core busy doing nothing: it looks in at 200 Hz.
        free = self.params.real_time_factor == 0 and not self.params.paused
        period = 0.0 if free else 0.005
        return self.create_timer(period, self._on_timer,
                                 clock=Clock(clock_type=ClockType.STEADY_TIME))

    def _apply(self, params):
        """A set_parameters change that passed the checks (pause, speed, image quality)."""
        old, self.params = self.params, params
        if (params.real_time_factor, params.paused) != (old.real_time_factor, old.paused):
            self.destroy_timer(self.timer)
            self.timer = self._make_timer()
        self.paused = params.paused
        self._restart_schedule(keep_time=True)
        if params.paused:
            self._publish_eyes(wait=True)  # nothing drawn is held back while paused
        if old.paused and not params.paused:
            # The overhead view shows the instant the run resumes (an episode's first video
            # frame is its start, whatever steps placed robot and ball before).
            self._next_overhead = min(self._next_overhead, self.sim.time)

    def _check_control_types(self):
        """Warn once for each publisher of the wrong type on a robot's control topic."""
        for interface in self.robots.values():
            for topic, wanted in interface.controls:
                for info in self.get_publishers_info_by_topic(topic):
                    said = (topic, info.topic_type, info.node_namespace, info.node_name)
                    if info.topic_type == wanted or said in self._wrong_types_said:
                        continue
                    self._wrong_types_said.add(said)
                    node = f'{info.node_namespace.rstrip("/")}/{info.node_name}'
                    self.get_logger().warning(
                        f'{node} publishes {info.topic_type} on {topic}, which takes '
                        f'{wanted} only: the robot does not hear it')

    # -- what the simulator's services do to time ---------------------------------------------
    @property
    def paused(self):
        """Whether the world stands still: in any state but PLAYING."""
        return self.state != SimulationState.PLAYING

    @paused.setter
    def paused(self, paused):
        """Run or pause the world there is (the parameter's change does; in-process code may,
        as the benchmark does). A stopped world stays stopped while paused; with no world,
        one loading or a quit asked for, the state stays what it is."""
        if self.state not in _RUNNABLE:
            return
        if not paused:
            self.state = SimulationState.PLAYING
        elif self.state == SimulationState.PLAYING:
            self.state = SimulationState.PAUSED

    def act(self, action):
        """'play', 'pause', 'stop' (reset and pause) or 'quit' (a program ends as on Ctrl+C,
        exit code 0; in-process, the spin ends with SystemExit(0) at the next turn)."""
        if action == 'quit':
            self.state = SimulationState.QUITTING
            self.get_logger().info('quitting, as asked')
            if hasattr(self, 'request_stop'):  # run as a program (lifecycle.run_node)
                self.request_stop()
            return
        if action == 'stop':
            self.reset(0)
        self.pause(action != 'play')
        if action == 'stop':
            self.state = SimulationState.STOPPED

    def reset(self, scope):
        """ResetSimulation's scope (bits: 1 time, 2 state, 4 spawned; 0 or all three: the
        world as loaded, time zero, rewound when no body came or went since it was built:
        SimWorld.reset): the schedule follows the time."""
        self._publish_eyes(wait=True)  # the instants before the reset come first
        bits = scope & 0b111
        if bits in (0, 0b111):
            self.sim.reset()
        else:
            if bits & 0b100:
                self.sim.remove_spawned()
            if bits & 0b010:
                self.sim.reset_state()
            if bits & 0b001:
                self.sim.reset_time()
        self._rebuilt(keep_time=not bits & 0b001 and bits not in (0, 0b111))
        self.said('reset', f'world reset (scope {scope})')

    def _rebuilt(self, keep_time):
        """The world was reset (rewound or rebuilt) or another loaded: what was said of the
        one before goes, the interfaces follow its entities, the schedule its time."""
        if self.sim_interface is not None:
            self.sim_interface.forget_touches()
        if self.scene is not None:
            self.scene.world_reset()
        if self.control is not None:
            self.control.forget()
        self.world_changed()
        self._restart_schedule(keep_time=keep_time)

    def world_changed(self):
        """Robots or objects came or went: their interfaces follow."""
        if set(self.robots) != set(self.sim.robots):
            # Images drawn while the world ran go out first: a deleted robot's, published
            # once its topics had ended, raised InvalidHandle in the simulator's next turn.
            self._publish_eyes(wait=True)
            self._sync_robots()
            self._make_tf()
        if self.sim_interface is not None:
            self.sim_interface.sync_objects()

    def load(self, world, uri):
        """Another world (a World) in place of this one, the node's interfaces with it; the
        state is LOADING_WORLD meanwhile, and paused after (as it was, if it fails)."""
        before, self.state = self.state, SimulationState.LOADING_WORLD
        try:
            self._publish_eyes(wait=True)
            self.eyes.close()
            self.cameras.close()
            self.sim.load(world)  # built once, here
            self._make_cameras()
            self.world_uri = uri
            self._rebuilt(keep_time=False)
            if self.sim_interface is not None:
                self.sim_interface.world_loaded(self.cameras)
            before = SimulationState.PAUSED
        finally:
            self.state = before
        self.pause(True)
        if uri or world.robots:  # not unload()'s empty world
            self.get_logger().info(f'world {world.source} loaded; robots '
                                   f'{", ".join(self.robots) or "none"}; paused')

    def unload(self):
        """No world: nothing in it, nothing to step, until load()."""
        self.load(World(name='', source='(no world)', robots=()), '')
        self.state = SimulationState.NO_WORLD
        self.get_logger().info('world unloaded: no world until load_world')

    def pause(self, paused):
        """Pause or run; whether paused now. Through the parameter, so that it always says
        whether the simulator is paused."""
        self.set_parameters([Parameter('paused', value=paused)])
        return self.paused

    def step(self, steps):
        """(done, message): ``steps`` physics steps, only while paused (and not stopped:
        a step leaves the stop, as the standard's state machine says)."""
        if not self.paused:
            return False, ('stepping works only while paused: set the simulation state to '
                           'paused first')
        if self.state in (SimulationState.NO_WORLD, SimulationState.LOADING_WORLD):
            return False, 'no world is loaded'
        if self.state == SimulationState.STOPPED:  # a step leaves the stop
            self.state = SimulationState.PAUSED
        self.advance(steps)
        return True, f'stepped {steps}; time {self.sim.time:.3f} s'

    def step_count(self):
        """The old ~/step service: step_count physics steps."""
        return self.step(self.params.step_count)

    # -- time ---------------------------------------------------------------------------------
    def _restart_schedule(self, keep_time=False):
        self._anchor = (time.monotonic(), self.sim.time)
        if not keep_time:
            self.schedule.restart()
            self._next_overhead = 0.0
            self._next_scene = 0.0

    def _on_timer(self):
        if self.state == SimulationState.QUITTING:
            raise SystemExit(0)
        if self.step_action is not None and self.step_action.serve():
            return
        if self.paused:
            if self.eyes.pending:  # paused by in-process code, not by the parameter
                self._publish_eyes(wait=True)
            return
        rtf = self.params.real_time_factor
        if rtf == 0:
            self._advance(self.sim.ticks_per_platform_tick, overlap=True)  # no bursts
        else:
            wall0, sim0 = self._anchor
            behind = sim0 + (time.monotonic() - wall0) * rtf - self.sim.time
            if behind > 0.25:  # can't keep up: carry on from here instead of catching up
                self._anchor = (time.monotonic(), self.sim.time)
                behind = 0.1
            if behind > 0:
                self._advance(max(1, int(behind / self.sim.dt)), overlap=True)
        self._publish_eyes(wait=False)
        self._report_progress()

    def _report_progress(self):
        wall, steps = self._progress
        now = time.monotonic()
        if now - wall >= 10.0:
            self.get_logger().info(
                f'sim time {self.sim.time:.1f} s, real-time factor '
                f'{(self.steps_taken - steps) * self.sim.dt / (now - wall):.2f}, '
                f'{self.frames_published} camera frames')
            self._progress = (now, self.steps_taken)

    def advance(self, steps):
        """Step physics, publishing /clock, sensors and ground truth each platform tick and
        the cameras at camera_rate, all stamped with simulated time; every image drawn is
        published before this returns."""
        self._advance(steps, overlap=False)
        self._publish_eyes(wait=True)

    def _advance(self, steps, overlap):
        """advance(); with ``overlap``, the eyes are drawn while physics steps on and some
        may still be on their way when this returns."""
        sim = self.sim
        spent = self.stage_seconds
        clock = time.perf_counter
        # A robot's microphones are worked out only while someone wants its BLOCK streams.
        listening = [name for name, interface in self.robots.items()
                     if interface.wants(BLOCK)]
        for _ in range(steps):
            started = clock()
            sim.step(listening=listening)
            self.steps_taken += 1
            spent['physics'] += clock() - started
            if self.sim_interface is not None:
                self.sim_interface.look_for_touches()
            for observe in self.step_observers:
                observe(sim)
            due = self.schedule.due(sim.step_index)
            # Images of an instant go out before its /clock when drawn here, so a controller
            # on sim time has them when its timer fires for that instant.
            if CAMERA in due:
                due.remove(CAMERA)
                # The instants before the previous one are out before the next is asked for.
                self._publish_eyes(wait=True, leave=IN_FLIGHT - 1)
                self._submit_eyes(overlap)
            if due:
                self._publish_eyes(wait=False)
                started = clock()
                self._publish_streams(due)
                spent['sensor topics'] += clock() - started
            if self.scene is not None and sim.time >= self._next_scene:
                started = clock()
                self.scene.publish()
                self._next_scene += 1.0 / SCENE_RATE_HZ
                spent['scene'] += clock() - started
            rate = self.params.overhead_rate
            if rate > 0 and self.sim_interface is not None and sim.time >= self._next_overhead:
                started = clock()
                self.sim_interface.publish_overhead(convert.stamp(sim.time),
                                                    self.params.jpeg_quality)
                self._next_overhead += 1.0 / rate
                spent['overhead'] += clock() - started

    # -- publishing ---------------------------------------------------------------------------
    def _publish_streams(self, kinds):
        """The sensor streams of the kinds due now, after /clock on a platform tick, and
        then the ground truth."""
        when = convert.stamp(self.sim.time)
        platform_tick = PLATFORM in kinds
        if platform_tick:
            self.pub_clock.publish(ClockMsg(clock=when))
        for kind in kinds:
            for interface in self.robots.values():
                interface.publish_streams(kind, when)
        if platform_tick and self.tf is not None:
            self.tf.publish(when)
        if platform_tick and self.sim_interface is not None:
            self.sim_interface.publish_ground_truth(when)
            if self.control is not None:
                self.control.tick()

    def _submit_eyes(self, overlap):
        """Ask for every eye someone subscribes to, of every robot, drawn together."""
        when = convert.stamp(self.sim.time)
        drawn = []
        for interface in self.robots.values():
            for eye, side, wants in interface.wanted_eyes():
                if wants.jpeg or wants.raw:
                    drawn.append((interface, eye, side, wants))
                else:  # only camera_info: no image to draw
                    interface.publish_eye(eye, (None, None), when, self.camera)
        if drawn:
            if overlap:
                self.eyes.start_workers()  # once, when eyes are first wanted
            started = time.perf_counter()
            views = self.cameras.eye_views([(i.robot, side) for i, _, side, _ in drawn])
            self.eyes.submit((when, [(i, eye) for i, eye, _, _ in drawn]), views, self.camera,
                             [wants for *_, wants in drawn], self.params.jpeg_quality,
                             overlap)
            self.stage_seconds['eyes: submit'] += time.perf_counter() - started
            self._publish_eyes(wait=False)  # drawn here: out before this instant's /clock

    def _publish_eyes(self, wait, leave=0):
        """Publish the instants whose eyes are done (``wait``: all but ``leave``)."""
        started = time.perf_counter()
        for (when, eyes), frames, seconds in self.eyes.finished(wait, leave):
            for (interface, eye), frame in zip(eyes, frames):
                interface.publish_eye(eye, frame, when, self.camera)
            self.frames_published += len(eyes)
            # The stages themselves: 'draw: <stage>' are parts of 'draw'.
            self.render_seconds.append(sum(v for k, v in seconds.items() if ':' not in k))
        self.stage_seconds['eyes: wait and publish'] += time.perf_counter() - started

    def destroy_node(self):
        if self.step_action is not None:
            self.step_action.close()
        self.eyes.close()
        self.cameras.close()
        self.sim.close()
        super().destroy_node()


def parse_args(argv):
    """The command line without the ROS arguments; --help lists the ROS parameters too."""
    parser = argparse.ArgumentParser(
        prog='miro_sim', formatter_class=argparse.RawDescriptionHelpFormatter,
        description="MiRo-E simulator on PyBullet with MiRo's ROS 2 topics, headless.",
        epilog='\n'.join(help_lines(SimParams))
        + f'\n\nbundled worlds: {", ".join(bundled_worlds())}')
    parser.add_argument('--world', help='bundled world name or path to a .toml file '
                        '(same as -p world:=...)')
    parser.add_argument('--robot', metavar='NAME',
                        help="name of the world's robot when its file names none (its topics "
                             'are /NAME/...); default $MIRO_ROBOT_NAME, else miro')
    return parser.parse_args(argv)


def make_executor(context=None):
    """What the simulator spins on: rclpy's EventsExecutor (experimental in Jazzy; the
    simulator's use of it is covered by test/test_sim_executor.py). It takes fewer and
    cheaper turns than SingleThreadedExecutor: real-time factor 5.7 instead of 4.9 for the
    default world with both eyes subscribed (BENCHMARKS.md)."""
    return EventsExecutor(context=context)


def main(argv=None):
    argv = sys.argv if argv is None else argv
    args = parse_args(user_args(argv, SIM_NODE_NAME, (SimParams,)))
    # OpenCV's pool of one thread per core spun for 20-30 ms a simulated second on the
    # other core, which the eye worker and the controllers need.
    cv2.setNumThreads(1)
    overrides = [] if args.world is None else [Parameter('world', value=args.world)]
    # A bad start (world, renderer, parameter, another simulator) is said in one line.
    # Errors once running are not the user's: spin_until_stopped logs their tracebacks.
    return run_node(SIM_NODE_NAME, lambda: SimNode(parameter_overrides=overrides,
                                                    robot=args.robot, guard_domain=True),
                    argv, make_executor=make_executor,
                    bad_start=(WorldError, RendererUnavailable, SharedDomain))
