"""MiRo-E simulator on PyBullet speaking MiRo's ROS 2 interface (miro_sim)."""
from miro_sim_bullet.ros.node import main

main()
