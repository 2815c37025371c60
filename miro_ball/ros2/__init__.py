"""The ros2 command line's everyday verbs for a pip install (python -m miro_ball.ros2)."""
