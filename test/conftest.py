"""Shared fixtures. ROS tests run in their own rclpy Context on a ROS domain
chosen per test process, discovery limited to this host, so parallel runs and
other ROS processes on the machine never see each other's topics."""
import os

import pytest

from miro_ball.common.isolation import limit_discovery, private_domain

limit_discovery()
os.environ['ROS_DOMAIN_ID'] = str(private_domain())


@pytest.fixture(scope='session', autouse=True)
def shared_memory_janitor():
    """Tests kill ROS processes on purpose: their Fast DDS files go at the end of the run."""
    from miro_ball.common.shm import SharedMemoryJanitor

    janitor = SharedMemoryJanitor()
    yield janitor
    janitor.clean()


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


@pytest.fixture
def make_sim(ros_context, executor):
    """make_sim(name=value, ..., robot=None): a simulator node in-process, paused (the test
    steps it, rostools.advance_ticks), with those parameters and the world's unnamed robot
    named robot (as --robot does); destroyed after the test."""
    from rclpy.parameter import Parameter

    from miro_sim_bullet.ros.node import SimNode

    made = []

    def make(robot=None, **params):
        params = {'paused': True, 'world': 'miro', **params}
        made.append(SimNode(context=ros_context, robot=robot, parameter_overrides=[
            Parameter(name, value=value) for name, value in params.items()]))
        executor.add_node(made[-1])
        return made[-1]
    yield make
    for node in made:
        executor.remove_node(node)
        node.destroy_node()


@pytest.fixture
def paused_sim(make_sim):
    """The simulator node in-process on the default world, paused."""
    return make_sim()
