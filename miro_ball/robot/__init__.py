"""MiRo for students' scripts: one line to connect, then plain method calls.

In the spirit of the MDK's RobotInterface, on ROS 2 and the simulator's clock::

    from miro_ball.robot import Robot

    with Robot() as miro:                  # or Robot('miro02'); $MIRO_ROBOT_NAME, else 'miro'
        miro.drive(0.1, 0.0)               # m/s forward, rad/s turn (CCW +), until stop()
        miro.sleep(2.0)                    # simulated seconds
        miro.stop()
        print(miro.pose)                   # Pose(x, y, theta) on odometry
        gaze = miro.look_at(0.8, 0.0, 0.1) # point an eye at a point ahead; gaze.reachable
        image = miro.images['caml']        # the left eye's latest frame, RGB
        miro.drive_to(0.0, 0.0, 0.0)       # back to the start, facing as it did

No ROS knowledge needed: the Robot runs its own ROS node in a background thread (in the
robot's namespace, on simulated time) while the script's calls block as long as they take.
"""
from miro_ball.robot.readings import Pose, Sensors
from miro_ball.robot.robot import Robot

__all__ = ['Pose', 'Robot', 'Sensors']
