"""The simulator on the executor its process spins on (make_executor: rclpy's experimental
EventsExecutor), free-running as `-p real_time_factor:=0` runs it: time, sensors, every
eye frame, commands and services all flow."""
import math
import time

import pytest
from geometry_msgs.msg import TwistStamped
from rclpy.parameter import Parameter
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import CompressedImage, JointState
from std_srvs.srv import SetBool, Trigger

from miro_ball.miro.interface import EYES, RobotTopics, SimTopics, default_robot_name
from miro_sim_bullet.render.eye_pipeline import IN_FLIGHT
from miro_sim_bullet.ros.node import make_executor, SimNode
from rostools import Probe, spin_until

T = RobotTopics(default_robot_name())
SIM = SimTopics()


@pytest.fixture
def running(ros_context):
    executor = make_executor(ros_context)
    node = SimNode(context=ros_context, parameter_overrides=[
        Parameter('real_time_factor', value=0.0), Parameter('world', value='miro'),
        Parameter('frame_width', value=320), Parameter('frame_height', value=240)])
    executor.add_node(node)
    probe = Probe(ros_context, executor)
    yield node, executor, probe
    executor.shutdown(timeout_sec=1.0)
    node.destroy_node()


def stamp_s(msg):
    return msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9


def test_free_running_simulator_delivers_everything(running):
    node, executor, probe = running
    clock = probe.watch(Clock, '/clock')
    kinematics = probe.watch(JointState, T.kinematic_joints)
    eyes = {eye: probe.watch(CompressedImage, T.eye_compressed(eye)) for eye in EYES}
    drive = probe.publisher(TwistStamped, T.cmd_vel)
    x0 = node.sim.robot.pose()[0]

    def driving_for(seconds):
        start = node.sim.time

        def done():
            command = TwistStamped()
            command.twist.linear.x = 0.2
            drive.publish(command)
            return node.sim.time - start >= seconds
        return done

    assert spin_until(executor, lambda: all(len(f) >= 2 for f in eyes.values()), 60)
    assert spin_until(executor, driving_for(2.0), 120)
    # Time: /clock every 20 ms of simulated time, in order.
    times = [c.clock.sec + c.clock.nanosec * 1e-9 for c in clock]
    assert times == sorted(times) and len(times) >= 100
    assert all(d == pytest.approx(0.02, abs=1e-6) for d in
               (b - a for a, b in zip(times[-50:], times[-49:])))
    assert len(kinematics) >= 100
    # Every frame the simulator rendered arrived, both eyes of each instant.
    node.paused = True
    assert spin_until(executor, lambda: sum(map(len, eyes.values())) == node.frames_published,
                      10)
    left, right = ([stamp_s(m) for m in eyes[eye]] for eye in EYES)
    assert left == right
    assert all(d == pytest.approx(1 / 15, abs=0.002) for d in
               (b - a for a, b in zip(left[1:], left[2:])))
    # The robot drove forward on its commands.
    assert node.sim.robot.pose()[0] - x0 > 0.2


def test_services_answer_while_free_running(running):
    node, executor, probe = running
    assert spin_until(executor, lambda: node.sim.time > 0.2, 60)
    assert probe.call(executor, SetBool, SIM.pause, SetBool.Request(data=True)).success
    paused_at = node.sim.time
    for _ in range(20):
        executor.spin_once(timeout_sec=0.01)
    assert node.sim.time == paused_at
    assert probe.call(executor, Trigger, SIM.reset, Trigger.Request()).success
    assert node.sim.time == 0.0
    assert probe.call(executor, Trigger, SIM.step, Trigger.Request()).success
    assert node.sim.time == pytest.approx(node.params.step_count * node.sim.dt)
    assert probe.call(executor, SetBool, SIM.pause, SetBool.Request(data=False)).success
    assert spin_until(executor, lambda: node.sim.time > 0.5, 60)
    assert math.isfinite(node.sim.robot.pose()[0])


def test_a_paused_free_running_simulator_leaves_the_cpu_to_others(running):
    """A grader pauses it while the next controller starts: that controller needs the core."""
    node, executor, _ = running
    assert spin_until(executor, lambda: node.sim.time > 0.1, 60)
    node.pause(True)
    wall, cpu = time.monotonic(), time.thread_time()
    while time.monotonic() - wall < 0.5:
        executor.spin_once(timeout_sec=0.05)
    assert time.thread_time() - cpu < 0.25 * (time.monotonic() - wall)
    node.pause(False)
    resumed_at = node.sim.time
    assert spin_until(executor, lambda: node.sim.time > resumed_at + 0.1, 60)


def test_eyes_drawn_beside_physics_come_at_most_two_camera_periods_late(running):
    node, executor, probe = running
    eyes = {eye: probe.watch(CompressedImage, T.eye_compressed(eye)) for eye in EYES}
    late = []  # simulated seconds between an image's instant and its publication
    for interface in node.robots.values():
        def recording(eye, frame, when, camera, publish=interface.publish_eye):
            late.append(node.sim.time - (when.sec + when.nanosec * 1e-9))
            publish(eye, frame, when, camera)
        interface.publish_eye = recording
    assert spin_until(executor, lambda: node.sim.time >= 2.0
                      and all(len(f) >= 10 for f in eyes.values()), 120)
    assert node.eyes.drawing_in_workers  # the helper process took the eyes
    # None came before its instant, some after it (drawn while physics stepped on), none
    # more than IN_FLIGHT camera periods after it: the helper may have two instants at once,
    # and instant t is out before t + 2 is asked for (a period is the gap to the next
    # instant, on a physics step: 34 steps of 2 ms at 15 Hz, 0.068 s).
    assert min(late) >= -1e-9 and max(late) > 0
    period = math.ceil(1 / node.params.camera_rate / node.sim.dt - 1e-9) * node.sim.dt
    assert max(late) <= IN_FLIGHT * period + 1e-9
    # Paused, nothing is held back: every image drawn is out.
    assert probe.call(executor, SetBool, SIM.pause, SetBool.Request(data=True)).success
    assert node.eyes.pending == 0
    assert spin_until(executor, lambda: sum(map(len, eyes.values())) == node.frames_published,
                      10)
    left, right = ([stamp_s(m) for m in eyes[eye]] for eye in EYES)
    assert left == right and left == sorted(left)
