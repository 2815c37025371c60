"""miro_sim: the rclpy node that owns a SimWorld, paces its time and serves its ROS side.

Each robot of the world gets MiRo's interface under /<name>/ (RobotInterface).
This node publishes /clock from physics time, the simulator's own topics
(ground truth, the overhead view) and services (reset, pause, step), and takes
set_pose requests. Either a steady wall-clock timer advances the world
(real_time_factor 1.0 = real time, 0 = as fast as possible), or, when paused,
the ~/step service or in-process code calls advance().
"""
import argparse
import sys
import time

import rclpy
from geometry_msgs.msg import PointStamped, PoseStamped
from rclpy.clock import Clock, ClockType
from rclpy.experimental import EventsExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import QoSProfile, ReliabilityPolicy
from rclpy.signals import SignalHandlerOptions
from rosgraph_msgs.msg import Clock as ClockMsg
from sensor_msgs.msg import CompressedImage
from std_srvs.srv import SetBool, Trigger

from miro_ball.common.cli import user_args
from miro_ball.common.clock_watch import ClockWatch
from miro_ball.common.params import declare, help_lines, LiveParams
from miro_ball.common.qos import profile
from miro_ball.common.stopping import spin_until_stopped, StopRequest
from miro_ball.common.throttle import Throttled
from miro_ball.miro.camera import Intrinsics
from miro_ball.miro.interface import CLOCK, CLOCK_QOS, robot_name, SIM_NODE_NAME, SimTopics
from miro_sim_bullet.physics.world import SimWorld
from miro_sim_bullet.render.overhead import overhead_camera
from miro_sim_bullet.render.renderer import RendererUnavailable
from miro_sim_bullet.ros import convert
from miro_sim_bullet.ros.domain_guard import refuse_shared_domain, SharedDomain
from miro_sim_bullet.ros.params import SimParams
from miro_sim_bullet.ros.robot_interface import RobotInterface
from miro_sim_bullet.scene.world_file import WorldError, bundled_worlds


# ROS's default keeps 10 requests: a burst of 200 clients lost 190 answers.
SERVICE_QOS = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE)
# Made into the world, its robots, cameras and topics at start; the rest apply at run time.
FIXED_PARAMS = ('world', 'physics_dt', 'frame_width', 'frame_height',
                'camera_rate', 'hfov_deg', 'renderer', 'eye_workers', 'peer_check_s')


class SimNode(Node):
    """MiRo-E robots in PyBullet behind MiRo's topics; see README for the topic table.

    robot names the world's robot when its file names none, as --robot does (default
    $MIRO_ROBOT_NAME, else 'miro'); ValueError in one line if it can not be a ROS name.
    guard_domain, as the command line simulator does: refuse to start (SharedDomain) when
    another node publishes /clock on the ROS domain, and say so once, in one line, when
    one appears later.
    """

    def __init__(self, *, context=None, parameter_overrides=None, robot=None,
                 guard_domain=False):
        super().__init__(SIM_NODE_NAME, context=context,
                         parameter_overrides=parameter_overrides)
        unnamed_robot = robot_name(robot)
        self.params = p = declare(self, SimParams)
        self._live = LiveParams(self, (p,), self._apply, fixed=FIXED_PARAMS)
        self.warn = Throttled(self.get_logger().warning)
        # Before the look for another simulator: two started together see each other.
        self.pub_clock = self.create_publisher(ClockMsg, CLOCK, profile(CLOCK_QOS))
        if guard_domain:  # before the world is built: a refusal costs no time
            refuse_shared_domain(self, p.peer_check_s)
            self._clock_watch = ClockWatch(self, own=1)
        self.sim = SimWorld(p.world, physics_dt=p.physics_dt, renderer=p.renderer,
                            log=self.get_logger().info, eye_workers=p.eye_workers,
                            robot_name=unnamed_robot)
        self.intrinsics = Intrinsics.from_hfov(p.frame_width, p.frame_height, p.hfov_deg)
        self.overhead = overhead_camera(self.sim.description)
        self.paused = p.paused
        self.frames_published = 0
        self.render_seconds = []  # wall time of each camera instant (all eyes)
        self.robots = {name: RobotInterface(self, name) for name in self.sim.robots}
        self._make_sim_interface()
        self.get_logger().info(
            f'world {self.sim.description.source}; robots {", ".join(self.robots)}; renderer '
            f'{self.sim.renderer.name}; cameras {p.frame_width}x{p.frame_height} @ '
            f'{p.camera_rate:g} Hz; real-time factor {p.real_time_factor:g}')
        self._restart_schedule()
        self._progress = (time.monotonic(), 0.0)
        self.timer = self._make_timer()

    def _make_timer(self):
        period = 0.005 if self.params.real_time_factor > 0 else 0.0
        return self.create_timer(period, self._on_timer,
                                 clock=Clock(clock_type=ClockType.STEADY_TIME))

    def _apply(self, params):
        """A set_parameters change that passed the checks (pause, speed, image quality)."""
        old, self.params = self.params, params
        if params.real_time_factor != old.real_time_factor:
            self.destroy_timer(self.timer)
            self.timer = self._make_timer()
        self.paused = params.paused
        self._restart_schedule(keep_time=True)

    def _make_sim_interface(self):
        t = SimTopics()
        self.pub_ball = self.create_publisher(PointStamped, t.ball, 10)
        names = [*self.sim.objects, *self.sim.robots]
        self.pub_objects = {name: self.create_publisher(PoseStamped, t.object_pose(name), 10)
                            for name in names}
        self.pub_overhead = self.create_publisher(CompressedImage, t.overhead, 2)
        self.create_subscription(PoseStamped, t.set_pose, self._on_set_pose, 10)
        self.srvs = [
            self.create_service(Trigger, t.reset, self._on_reset, qos_profile=SERVICE_QOS),
            self.create_service(SetBool, t.pause, self._on_pause, qos_profile=SERVICE_QOS),
            self.create_service(Trigger, t.step, self._on_step, qos_profile=SERVICE_QOS),
        ]

    # -- the simulator's own interface --------------------------------------------------------
    def _on_set_pose(self, msg):
        try:
            name, position, orientation = convert.pose_request(msg)
            self.sim.set_object_pose(name, position, orientation)
        except ValueError as err:
            self.warn('set_pose', f'set_pose ignored: {err}')
        except KeyError:
            self.warn('set_pose_name', f'set_pose ignored: no object or robot named '
                      f'{msg.header.frame_id!r} (header.frame_id); there are '
                      f'{", ".join(self.pub_objects)}')

    def _on_reset(self, request, response):
        self.sim.reset()
        self._restart_schedule()
        self.get_logger().info('world reset')
        response.success, response.message = True, 'world reset to its initial state'
        return response

    def _on_pause(self, request, response):
        # Through the parameter, so that it always says whether the simulator is paused.
        self.set_parameters([Parameter('paused', value=bool(request.data))])
        response.success, response.message = True, 'paused' if self.paused else 'running'
        return response

    def _on_step(self, request, response):
        if not self.paused:
            response.success, response.message = False, 'step works only while paused'
            return response
        self.advance(self.params.step_count)
        response.success = True
        response.message = f'stepped {self.params.step_count}; time {self.sim.time:.3f} s'
        return response

    # -- time ---------------------------------------------------------------------------------
    def _restart_schedule(self, keep_time=False):
        self._anchor = (time.monotonic(), self.sim.time)
        if not keep_time:
            self._next_frame = 0
            self._next_overhead = 0.0

    def _frame_step(self, index):
        return round(index / self.params.camera_rate / self.sim.dt)

    def _on_timer(self):
        if self.paused:
            return
        rtf = self.params.real_time_factor
        if rtf == 0:
            self.advance(self.sim.ticks_per_platform_tick)  # one tick: no bursts of frames
        else:
            wall0, sim0 = self._anchor
            behind = sim0 + (time.monotonic() - wall0) * rtf - self.sim.time
            if behind > 0.25:  # can't keep up: carry on from here instead of catching up
                self._anchor = (time.monotonic(), self.sim.time)
                behind = 0.1
            if behind > 0:
                self.advance(max(1, int(behind / self.sim.dt)))
        self._report_progress()

    def _report_progress(self):
        wall, sim_time = self._progress
        now = time.monotonic()
        if now - wall >= 10.0:
            self.get_logger().info(
                f'sim time {self.sim.time:.1f} s, real-time factor '
                f'{(self.sim.time - sim_time) / (now - wall):.2f}, '
                f'{self.frames_published} camera frames')
            self._progress = (now, self.sim.time)

    def advance(self, steps):
        """Step physics, publishing /clock, sensors and ground truth each platform tick and
        the cameras at camera_rate, all stamped with simulated time."""
        sim = self.sim
        for _ in range(steps):
            sim.step()
            # Images of an instant go out before its /clock, so a controller on sim time
            # has them when its timer fires for that instant.
            if sim.step_index >= self._frame_step(self._next_frame):
                self._publish_cameras()
                while self._frame_step(self._next_frame) <= sim.step_index:
                    self._next_frame += 1
            if sim.step_index % sim.ticks_per_platform_tick == 0:
                self._publish_tick()
            rate = self.params.overhead_rate
            if rate > 0 and sim.time >= self._next_overhead:
                self._publish_overhead()
                self._next_overhead += 1.0 / rate

    # -- publishing ---------------------------------------------------------------------------
    def _publish_tick(self):
        when = convert.stamp(self.sim.time)
        self.pub_clock.publish(ClockMsg(clock=when))
        for interface in self.robots.values():
            interface.publish_tick(when)
        for name, (position, orientation) in self.sim.object_poses().items():
            self.pub_objects[name].publish(convert.pose(position, orientation, when))
        for name, robot in self.sim.robots.items():
            self.pub_objects[name].publish(convert.robot_pose(*robot.ground_truth(), when))
        ball = self.sim.ball_position()
        if ball is not None:
            self.pub_ball.publish(convert.point(ball, when))

    def _publish_overhead(self):
        if self.pub_overhead.get_subscription_count():
            rgb = self.sim.render_view(*self.overhead)
            self.pub_overhead.publish(convert.jpeg(rgb, convert.stamp(self.sim.time),
                                                   'overhead', self.params.jpeg_quality))

    def _publish_cameras(self):
        wanted = [(interface, eye, side) for interface in self.robots.values()
                  for eye, side in interface.wanted_eyes()]
        if not wanted:
            return
        when = convert.stamp(self.sim.time)
        started = time.perf_counter()
        images = self.sim.render_eyes([(i.robot, side) for i, _, side in wanted],
                                      self.intrinsics)
        for (interface, eye, _), rgb in zip(wanted, images):
            interface.publish_eye(eye, rgb, when, self.intrinsics, self.params.jpeg_quality)
        self.frames_published += len(wanted)
        self.render_seconds.append(time.perf_counter() - started)

    def destroy_node(self):
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
    args = parse_args(user_args(argv, SIM_NODE_NAME))
    overrides = [] if args.world is None else [Parameter('world', value=args.world)]
    # Ctrl+C and SIGTERM end the spin with the context still up (see stopping.py).
    stop = StopRequest()
    rclpy.init(args=argv, signal_handler_options=SignalHandlerOptions.NO)
    node = None
    try:
        node = SimNode(parameter_overrides=overrides, robot=args.robot, guard_domain=True)
        executor = make_executor()
        executor.add_node(node)
        spin_until_stopped(executor, stop)
    except (WorldError, RendererUnavailable, ValueError, SharedDomain) as err:
        print(f'{SIM_NODE_NAME}: error: {err}', file=sys.stderr)
        sys.exit(2)
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()
