"""How each of MiRo's sensor streams is made from a simulated robot: the simulator's half of
the interface table (miro.interface.ROBOT_INTERFACE), by row key.

A producer is ``make(robot, when, name, **fields) -> message``: robot is the MiroRobot as it
is now (its platform tick's ``sensors``, its speaker, ...), when the stamp, name the robot's
name (for frame ids), fields the row's placeholder (``part='head'``). The simulator publishes
every SENSOR row of the table that has a producer, at the row's rate, for every robot; the
eyes (rate CAMERA) are drawn by the eye pipeline instead. Adding a stream is a row in the
table and a producer here (docs/development.md).
"""
from std_msgs.msg import UInt16, UInt32

from miro_ball.miro.constants import UPSTREAM_FLAG_SIMULATOR
from miro_ball.miro.interface import frame_id
from miro_sim_bullet.ros import convert

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
}
