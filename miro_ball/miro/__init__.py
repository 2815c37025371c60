"""What MiRo is: its numbers, its drive formula, its cameras and its ROS names.

Shared by the simulator, the controller and every client; imports neither
rclpy nor PyBullet.
"""
