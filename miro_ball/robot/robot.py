"""Robot: one MiRo for a script, in the spirit of the MDK's RobotInterface."""
import atexit
import math

from geometry_msgs.msg import TwistStamped
from sensor_msgs.msg import JointState

from miro_ball.common.messages import drive_command
from miro_ball.common.robots import missing_robot
from miro_ball.miro.constants import JOINT_NAMES, PLATFORM_TICK_S
from miro_ball.miro.gaze import look_at
from miro_ball.miro.interface import check_name, robot_name, RobotTopics
from miro_ball.miro.kc import clamp_joints, EYE_FRAMES, FOOT, KinematicChain, WORLD
from miro_ball.miro.pose_controller import PoseController
from miro_ball.robot.connection import Connection, node_name
from miro_ball.robot.held_command import HeldCommand
from miro_ball.robot.readings import Eyes, READINGS, Readings

FRAMES = {'foot': FOOT, 'odom': WORLD}  # look_at's frames: the robot's own, odometry's
# At rest: moved less than this in a platform tick (20 ms).
REST_M, REST_RAD = 1e-4, math.radians(0.05)


class Robot:
    """A MiRo in the simulator (or any robot with MiRo's topics), on simulated time.

    ``Robot()`` connects to the robot named by $MIRO_ROBOT_NAME, else 'miro';
    ``Robot('miro02')`` to another. It waits (``timeout`` wall seconds) for the robot's
    first readings and raises TimeoutError if none come. ``close()`` it when done, or use
    ``with Robot() as miro:``; it stops the wheels on the way out.

    Reading: ``pose`` (x, y, theta on odometry), ``joints`` (tilt, lift, yaw, pitch, rad),
    ``sensors`` (cliff, sonar, light, touch, battery), ``images`` and ``cameras`` (each
    eye's latest frame, RGB, and its camera model), ``now`` (simulated seconds).
    Doing: ``drive``, ``stop``, ``sleep``, ``set_head``, ``look_at``, ``drive_to``.
    """

    def __init__(self, name=None, timeout=10.0):
        self.name = robot_name() if name is None else check_name(name)
        self._ros = Connection(self.name, node_name())
        self._readings = Readings(self._ros)
        self._eyes = Eyes(self._ros)
        topics = RobotTopics()
        self._cmd_vel = self._ros.publisher(TwistStamped, topics.cmd_vel)
        self._head = self._ros.publisher(JointState, topics.kinematic_targets)
        self._wheels = HeldCommand(self._send)
        self._ros.node.create_timer(PLATFORM_TICK_S, self._wheels.repeat)
        # Every reading, not just the pose: they come on topics of their own, in any order
        # (the tutorial's first line of battery found none, once in a full run).
        heard = self._readings.latest
        if not self._ros.wait_until(lambda: heard.keys() >= READINGS.keys() and self.now > 0,
                                    'the robot', wall_timeout=timeout):
            said = missing_robot(self._ros.node, self.name, timeout)
            self._ros.close()
            raise TimeoutError(said)
        atexit.register(self.close)

    def __repr__(self):
        return f'Robot({self.name!r})'

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def close(self):
        """Stop the wheels and disconnect (again: nothing)."""
        atexit.unregister(self.close)
        if self._ros.context.ok():
            self.stop()
            self._ros.close()

    # -- reading -----------------------------------------------------------------------------
    @property
    def now(self):
        """Simulated seconds."""
        return self._ros.now()

    @property
    def pose(self):
        """Pose(x, y, theta): where odometry has the robot (m, m, rad)."""
        return self._readings.latest['pose']

    @property
    def joints(self):
        """(tilt, lift, yaw, pitch) of the neck as the robot reports them, rad."""
        return self._readings.latest['joints']

    @property
    def sensors(self):
        """The latest Sensors: cliff, sonar, light, touch_head, touch_body, battery."""
        return self._readings.sensors()

    @property
    def images(self):
        """{'caml': image, 'camr': image}: each eye's latest frame, RGB (height, width, 3).
        The first call starts the eyes and waits for their first frames."""
        self._start_eyes()
        return self._eyes.images()

    @property
    def cameras(self):
        """{'caml': CameraModel, 'camr': CameraModel} from the eyes' camera_info: pixels to
        directions and the floor (miro_ball.miro.camera_model)."""
        self._start_eyes()
        return dict(self._eyes.cameras)

    def _start_eyes(self):
        self._eyes.subscribe()
        self._ros.wait_until(self._eyes.ready, "the eyes' first frames")

    # -- doing -------------------------------------------------------------------------------
    def drive(self, forward, turn):
        """Drive on at ``forward`` m/s turning ``turn`` rad/s (counter-clockwise +) until
        the next drive() or stop(). Each wheel does at most 0.4 m/s."""
        forward, turn = float(forward), float(turn)
        if not (math.isfinite(forward) and math.isfinite(turn)):
            raise ValueError(f'drive needs finite speeds, got ({forward}, {turn})')
        self._wheels.hold(forward, turn)

    def stop(self):
        """Stop the wheels."""
        self._wheels.release()

    def sleep(self, seconds):
        """Wait ``seconds`` of simulated time (while the simulator is paused, so is this)."""
        elapsed = self._ros.stopwatch()
        self._ros.wait_until(lambda: elapsed() >= seconds, f'{seconds:g} simulated s')

    def set_head(self, lift, yaw, pitch):
        """Move the neck to these angles (rad), held to MiRo's limits: lift 8..60 degrees
        (more: head lower), yaw -55..55 (more: left), pitch -22..8 (more: nose down)."""
        msg = JointState(name=list(JOINT_NAMES),
                         position=list(clamp_joints(self.joints[0], lift, yaw, pitch)))
        msg.header.stamp = self._ros.node.get_clock().now().to_msg()
        self._head.publish(msg)

    def look_at(self, x, y, z, frame='foot', eye=None):
        """Turn the head so that an eye looks at point (x, y, z) (m): in the robot's own
        frame ('foot': x ahead, y left, z up from the floor under the wheels) or in
        odometry's ('odom'). eye: 'caml', 'camr' or None (whichever turns the head less).
        Returns the Gaze (miro_ball.miro.gaze): ``reachable``, ``error_deg``, ``reason``.
        The head gets there at its own speed (up to half a second)."""
        if frame not in FRAMES or (eye is not None and eye not in EYE_FRAMES):
            raise ValueError(f"frame must be 'foot' or 'odom' and eye 'caml', 'camr' or None, "
                             f'got {frame!r}, {eye!r}')
        kc = KinematicChain(self.joints, self.pose)
        gaze = look_at(kc, (x, y, z), FRAMES[frame], EYE_FRAMES.get(eye))
        self.set_head(*gaze.joints[1:])
        return gaze

    def drive_to(self, x, y, theta, timeout=30.0, position_tolerance=0.02,
                 heading_tolerance=math.radians(3.0)):
        """Drive to (x, y) on odometry and turn to heading theta (rad), then stop. True when
        there within the tolerances (m, rad), False when ``timeout`` simulated seconds
        ran out first. Keep the way clear: it drives straight at the goal."""
        controller = PoseController((x, y, theta), position_tolerance, heading_tolerance)
        count = self._readings.count
        elapsed = self._ros.stopwatch()

        def next_pose():
            heard = count['pose']
            self._ros.wait_until(lambda: count['pose'] > heard, 'odometry')

        def at_rest():
            """Until MiRo has stopped moving (or the time is up)."""
            before = self.pose
            while elapsed() < timeout:
                next_pose()
                now = self.pose
                if math.dist(before[:2], now[:2]) < REST_M and \
                        abs(math.remainder(now[2] - before[2], math.tau)) < REST_RAD:
                    return
                before = now
        try:
            while elapsed() < timeout:
                command = controller.command(self.pose)
                if controller.arrived:
                    # Arrived while moving: the stop reaches the wheels a moment later (more
                    # on a busy machine), so it counts once MiRo is at rest; if it coasted
                    # out of the tolerances meanwhile, it drives back.
                    self.stop()
                    at_rest()
                    command = controller.command(self.pose)
                    if controller.arrived:
                        return True
                self.drive(*command)
                next_pose()  # a platform tick later
            return False
        finally:
            self.stop()

    def _send(self, forward, turn):
        self._cmd_vel.publish(drive_command(self._ros.node, self.name, forward, turn))
