"""MiRo-E simulator on PyBullet speaking MiRo's ROS 2 interface (miro_sim)."""
