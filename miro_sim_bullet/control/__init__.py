"""The pure logic behind the standard simulation_interfaces services (no ROS, no physics)."""
