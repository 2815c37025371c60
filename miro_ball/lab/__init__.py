"""The lab around the robot: the demo, closed-loop scenarios, monitors and benchmarks."""
