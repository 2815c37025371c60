"""kick_blue_ball for ROS 2: find the blue ball in MiRo's eyes and kick it.

Importing this package (or its pure modules: constants, kinematics, detection,
behaviour) never imports rclpy.
"""
