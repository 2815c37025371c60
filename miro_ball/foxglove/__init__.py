"""The live ROS graph for the Foxglove app (python -m miro_ball.foxglove)."""
