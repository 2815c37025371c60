"""How each of MiRo's sensor streams is made from a simulated robot: the simulator's half of
the interface table (miro.interface.ROBOT_INTERFACE), by row key.

A producer is ``make(robot, when, name, **fields) -> message``: robot is the MiroRobot as it
is now (its platform tick's ``sensors``, what its microphones ``heard``, its speaker, ...),
when the stamp (None for a LATCHED stream, made once), name the robot's name (for frame
ids), fields the row's placeholder (``part='head'``). The message may be its serialised
bytes, or None for nothing this time. The simulator publishes every SENSOR row of the table
for every robot when its kind (miro.stream_kinds) says it is due and someone subscribes;
the eyes (CAMERA) are drawn by the eye pipeline instead. Adding a sensor of any kind is a
row in the table and a producer here (docs/development.md, "Adding a sensor").
"""
import array
import functools

import numpy as np
from std_msgs.msg import Int16MultiArray, MultiArrayDimension, String, UInt16, \
    UInt16MultiArray, UInt32

from miro_ball.common.messages import message_class
from miro_ball.miro.body import MOVABLE
from miro_ball.miro.constants import UPSTREAM_FLAG_SIMULATOR, WHEEL_MAX_SPEED_M_PER_S
from miro_ball.miro.interface import frame_id, PLATFORM, ROBOT_INTERFACE, SENSOR, TOPIC
from miro_ball.miro.urdf import urdf
from miro_sim_bullet.ros import convert
from miro_sim_bullet.physics.speaker import BUFFER_SAMPLES as SPEAKER_BUFFER_SAMPLES
from miro_sim_bullet.ros.refill import prefix, Refill

PRODUCERS = {
    'kinematic_joints': lambda r, when, name: convert.kinematic_joints(r.sensors, when, name),
    'odom': lambda r, when, name: convert.odometry(r.sensors, when, name),
    'body_pose': lambda r, when, name: convert.body_pose(r.sensors),
    'body_vel': lambda r, when, name: convert.odometry(r.sensors, when, name).twist.twist,
    'wheel_speed_cmd': lambda r, when, name: convert.floats(r.sensors.wheel_speed_cmd),
    'wheel_speed_opto': lambda r, when, name: convert.floats(r.sensors.wheel_speed_opto),
    'cliff': lambda r, when, name: convert.floats(r.sensors.cliff),
    'sonar': lambda r, when, name: convert.sonar(r.sensors, when, name),
    'imu': lambda r, when, name, part: convert.imu(getattr(r.sensors, f'imu_{part}'), when,
                                                   frame_id(name, f'imu_{part}')),
    'battery': lambda r, when, name: convert.battery(r.sensors, when, name),
    'light': lambda r, when, name: convert.floats(r.sensors.light),
    'touch': lambda r, when, name, part: UInt16(data=getattr(r.sensors, f'touch_{part}')),
    'sensor_flags': lambda r, when, name: UInt32(data=UPSTREAM_FLAG_SIMULATOR),
    'joint_states': lambda r, when, name: _joint_states().fill(
        when, (*r.sensors.joint_positions, *r.sensors.joint_velocities)),
    'robot_description': lambda r, when, name: String(data=urdf()),
    'stream_state': lambda r, when, name: UInt16MultiArray(
        data=[r.speaker.free, SPEAKER_BUFFER_SAMPLES]),
    'mics': lambda r, when, name: r.heard and _mics(r.heard.samples),
}


def _mics(samples):
    """sensors/mics' bytes of one block, int16 (channels, samples), channel by channel."""
    return _mics_prefix(*samples.shape) + samples.astype('<i2').tobytes()


@functools.cache
def _mics_prefix(channels, count):
    """sensors/mics' bytes before its samples, its layout [channels, samples] (serialised
    once: building the message took ~10 us a block, 40 blocks a second a robot)."""
    zeros = np.zeros((channels, count), '<i2')
    msg = Int16MultiArray(data=array.array('h', zeros.tobytes()))
    msg.layout.dim = [MultiArrayDimension(label='channels', size=channels,
                                          stride=channels * count),
                      MultiArrayDimension(label='samples', size=count, stride=count)]
    return prefix(msg, zeros.tobytes())


@functools.cache
def _joint_states():
    """joint_states' bytes, refilled each tick (the same names for every robot): a
    message of 24 numbers at 50 Hz for every robot."""
    count = len(MOVABLE)
    return Refill(lambda stamp, values: convert.joint_states(values[:count], values[count:],
                                                             stamp), 2 * count)


@functools.cache  # on first use: miro2_msg may not be built, and then it is never called
def _package_parts():
    """[(field of SensorsPackage, producer, placeholder fields)]: every 50 Hz row whose topic
    is sensors/<field> fills that field, so the package holds what the separate topics of
    the tick hold, by construction."""
    fields = message_class(TOPIC['package'].type).get_fields_and_field_types()
    return [(relative.split('/', 1)[1], PRODUCERS[row.key], holes)
            for row in ROBOT_INTERFACE if row.direction == SENSOR and row.kind == PLATFORM
            and row.key in PRODUCERS for holes, relative in row.names()
            if relative.startswith('sensors/') and relative.split('/', 1)[1] in fields]


def sensors_package(r, when, name):
    """sensors/package: the tick's readings in one stamped message. The simulator models no
    motor electronics, so the two motor fields are ideal: the back-EMF estimate is the
    measured wheel speed, the PWM effort the commanded speed as a fraction of full speed.
    No DIP switch is set."""
    msg = message_class(TOPIC['package'].type)()
    msg.header.stamp, msg.header.frame_id = when, frame_id(name, 'base_link')
    for field, make, holes in _package_parts():
        setattr(msg, field, make(r, when, name, **holes))
    msg.wheel_speed_back_emf = convert.floats(r.sensors.wheel_speed_opto)
    msg.wheel_effort_pwm = convert.floats(
        np.clip(np.asarray(r.sensors.wheel_speed_cmd) / WHEEL_MAX_SPEED_M_PER_S, -1.0, 1.0))
    return msg


PRODUCERS['package'] = sensors_package
