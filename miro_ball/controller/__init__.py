"""kick_blue_ball: detection and behaviours (pure), their parameters, and the ROS node."""
