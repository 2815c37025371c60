"""The simulator on ROS: message conversion, one interface per robot, the pacing node."""
