"""Shared fixtures. ROS tests run in their own rclpy Context on a ROS domain
chosen per test process, discovery limited to this host, so parallel runs and
other ROS processes on the machine never see each other's topics."""
import os

import pytest

from miro_ball.common.isolation import limit_discovery, private_domain

limit_discovery()
os.environ['ROS_DOMAIN_ID'] = str(private_domain())


@pytest.fixture
def ros_context():
    """A fresh, initialised rclpy Context (never the global one)."""
    import rclpy
    from rclpy.context import Context

    context = Context()
    rclpy.init(context=context, domain_id=int(os.environ['ROS_DOMAIN_ID']))
    yield context
    rclpy.try_shutdown(context=context)


@pytest.fixture
def executor(ros_context):
    """A SingleThreadedExecutor on the test's own context."""
    from rclpy.executors import SingleThreadedExecutor

    ex = SingleThreadedExecutor(context=ros_context)
    yield ex
    ex.shutdown(timeout_sec=1.0)
