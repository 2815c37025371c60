"""The grading host's simulator: MiRo's interface and nothing else on the ROS graph, and a
world reset between episodes that runs as a fresh simulator's would."""
import pytest

from miro_ball.grading.host import observe, place
from miro_ball.grading.kick_judge import KickJudge
from miro_ball.miro.interface import CLOCK, default_robot_name, RobotTopics, SENSOR
from rostools import Probe, drain

NAME = default_robot_name()
ROBOT, BALL = (0.0, 0.0, 0.0), (0.5, 0.02)  # the ball straight ahead, a little off-centre


def graph(probe, executor):
    drain(executor, rounds=100)
    node = probe.node
    services = {name for name, _ in node.get_service_names_and_types()}
    published = {topic for topic, _ in node.get_topic_names_and_types()
                 if any(info.node_name == 'miro_sim'
                        for info in node.get_publishers_info_by_topic(topic))}
    return services, published


@pytest.mark.parametrize('privileged', [True, False])
def test_the_unprivileged_simulator_offers_miros_interface_only(make_sim, ros_context,
                                                                executor, privileged):
    make_sim(privileged=privileged)
    probe = Probe(ros_context, executor)
    services, published = graph(probe, executor)
    sim_services = {s for s in services if s.startswith('/miro_sim/')}
    if privileged:  # the simulator of the lab: its services and ground truth
        assert '/miro_sim/reset' in sim_services and '/miro_sim/set_parameters' in services
        return
    assert sim_services == set()
    assert published <= {CLOCK, '/rosout', '/parameter_events',
                         *RobotTopics(NAME).all(SENSOR)}
    assert CLOCK in published and RobotTopics(NAME).odom in published


def episode(node, steps=1500):
    """Drive straight at the ball for ``steps`` physics steps; what the judge saw and where
    the ball ended."""
    sim = node.sim
    node.reset()
    place(sim, NAME, ROBOT, BALL)
    judge = KickJudge()
    judge.start(sim.time)
    node.step_observers[:] = [lambda world: observe(judge, world, NAME)]
    for _ in range(steps // sim.ticks_per_platform_tick):
        sim.robots[NAME].set_cmd_vel(0.3, 0.0)
        node.advance(sim.ticks_per_platform_tick)
    return (judge.kicked, judge.kick_time, judge.touch_time, round(judge.distance, 9),
            tuple(round(v, 9) for v in sim.ball_position()))


def test_a_reset_simulator_runs_an_episode_as_a_fresh_one(make_sim):
    fresh = episode(make_sim(privileged=False))
    reused = make_sim(privileged=False)
    episode(reused, steps=123)  # an episode before: the next one must not know of it
    assert episode(reused) == fresh
    kicked, kick_time, touch_time, *_ = fresh
    assert kicked and 0 < touch_time < kick_time
