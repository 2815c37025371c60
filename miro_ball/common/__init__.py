"""Plumbing every node shares: parameters, rate-limited warnings, ROS isolation."""
