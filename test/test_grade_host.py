"""The grading host's simulator: MiRo's interface and nothing else on the ROS graph, and a
world reset between episodes that runs as a fresh simulator's would."""
import pytest

from miro_ball.grading.host import observe, place
from miro_ball.miro.interface import CLOCK, default_robot_name, RobotTopics, SENSOR, \
    SIM_ACTION_NODE_NAME, SIM_NODE_NAME, TF, TF_STATIC
from miro_ball.run.judge import Judge
from miro_ball.run.monitor import Monitor, unmatched
from rostools import drain, Probe, spin_until

NAME = default_robot_name()
ROBOT, BALL = (0.0, 0.0, 0.0), (0.5, 0.02)  # the ball straight ahead, a little off-centre


def graph(probe, executor, privileged):
    """(services, topics the simulator publishes) once what both kinds offer is seen."""
    node = probe.node
    spin_until(executor, lambda: all(node.get_publishers_info_by_topic(topic) for topic in
                                     (CLOCK, RobotTopics(NAME).odom)))
    if privileged:
        spin_until(executor, lambda: node.get_service_names_and_types_by_node(
            SIM_NODE_NAME, '/'), what="the simulator's services")
    # What the simulator's nodes serve: the graph's whole list holds other tests' clients of
    # the standard services too, for a while after their contexts ended.
    services = set()
    for name, namespace in node.get_node_names_and_namespaces():
        if name in (SIM_NODE_NAME, SIM_ACTION_NODE_NAME):
            services |= {service for service, _ in
                         node.get_service_names_and_types_by_node(name, namespace)}
    published = {topic for topic, _ in node.get_topic_names_and_types()
                 if any(info.node_name == 'miro_sim'
                        for info in node.get_publishers_info_by_topic(topic))}
    return services, published


@pytest.mark.parametrize('privileged', [True, False])
def test_the_unprivileged_simulator_offers_miros_interface_only(make_sim, ros_context,
                                                                executor, privileged):
    make_sim(privileged=privileged)
    probe = Probe(ros_context, executor)
    services, published = graph(probe, executor, privileged)
    sim_services = {s for s in services if s.startswith('/miro_sim/')}
    if privileged:  # the simulator of the lab: its services and ground truth
        assert '/miro_sim/reset' in sim_services and '/miro_sim/set_parameters' in services
        return
    assert sim_services == set()
    # /tf holds the robot's pose as sensors/odom does: a robot's own frames, no ground truth
    assert published <= {CLOCK, TF, TF_STATIC, '/rosout', '/parameter_events',
                         *RobotTopics(NAME).all(SENSOR)}
    assert CLOCK in published and RobotTopics(NAME).odom in published


def verdict(judge):
    return (judge.kicked, judge.kick_time, judge.touch_time, judge.kicker, judge.fell,
            round(judge.distance, 9))


def episode(node, steps=1500, started=lambda t: None, each_tick=lambda: None):
    """Drive straight at the ball for ``steps`` physics steps, judged as the grading host
    judges; (the judge, where the ball ended). started(t) when judging starts, each_tick()
    after each platform tick."""
    sim = node.sim
    node.reset(0)  # the whole world as loaded
    place(sim, NAME, ROBOT, BALL)
    judge = Judge(sim.time)
    started(sim.time)
    node.step_observers[:] = [lambda world: observe(judge, world, NAME)]
    for _ in range(steps // sim.ticks_per_platform_tick):
        sim.robots[NAME].set_cmd_vel(0.3, 0.0)
        node.advance(sim.ticks_per_platform_tick)
        each_tick()
    return judge, tuple(round(v, 9) for v in sim.ball_position())


def test_a_reset_simulator_runs_an_episode_as_a_fresh_one(make_sim):
    judge, ball = episode(make_sim(privileged=False))
    fresh = verdict(judge), ball
    reused = make_sim(privileged=False)
    episode(reused, steps=123)  # an episode before: the next one must not know of it
    judge, ball = episode(reused)
    assert (verdict(judge), ball) == fresh
    assert judge.kicked and 0 < judge.touch_time < judge.kick_time


def test_the_grader_and_the_demo_judge_an_episode_alike(make_sim, ros_context, executor):
    """The host's judge fed in-process and a Monitor's fed the simulator's ground truth
    topics (as the lab run, the scenario bench and the closed-loop tests are) say the same."""
    node = make_sim()
    probe = Probe(ros_context, executor)
    monitor = Monitor(probe.node, [NAME], debug_frames=False)
    spin_until(executor, lambda: not unmatched(monitor.truth) and
               node.sim_interface.pub_touches.get_subscription_count())

    def deliver():
        spin_until(executor, lambda: monitor.caught_up(node.sim.time))
        drain(executor)  # the tick's touch, published before its ball and its robot

    grader, _ = episode(node, started=monitor.restart, each_tick=deliver)
    demo = monitor.judge
    assert grader.kicked and grader.kicker == NAME
    assert verdict(demo) == pytest.approx(verdict(grader), abs=1e-9)
