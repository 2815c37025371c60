"""MiRo's demo mode: the animal (docs/demo_mode.md). Pure parts, then node.py for ROS."""
