"""What counts in a graded episode, judged from the world itself (pure), and which uses of
the ROS graph are beyond MiRo's interface."""
import math

from hypothesis import given, strategies as st

from miro_ball.grading.kick_judge import KickJudge
from miro_ball.grading.watch import breaches, CLIENT, Endpoint, PUBLISHER, SUBSCRIPTION
from miro_ball.run.judge import KICK_DISTANCE_M

FOOT = (0.0, 0.0, 0.0)


def judged(path, start=1.0):
    """A judge fed (t, ball x, touching) steps after starting at ``start``."""
    judge = KickJudge()
    judge.start(start)
    for t, x, touching in path:
        judge.observe(t, (x, 0.0, 0.1), FOOT, touching)
    return judge


def test_a_ball_that_moves_untouched_is_no_kick():
    judge = judged([(1.1, 0.0, False), (1.2, 2.0, False), (1.3, 2.0, False)])
    assert not judge.kicked and judge.moved == 0.0


def test_a_kick_counts_from_the_first_touch():
    judge = judged([(1.1, 0.0, False), (1.2, 0.0, True), (1.5, 0.2, False),
                    (1.8, 0.2 + KICK_DISTANCE_M, False)])
    assert judge.kicked and judge.kick_time == 1.8 - 1.0


def test_a_ball_teleported_after_a_touch_counts_from_where_it_was_touched():
    judge = judged([(1.1, 0.5, True), (1.2, 0.5 + KICK_DISTANCE_M - 0.01, False)])
    assert not judge.kicked


@given(st.lists(st.tuples(st.floats(-10, 10), st.floats(-3, 3), st.booleans()), max_size=30),
       st.floats(0, 5))
def test_times_are_never_negative_nor_before_the_start(path, start):
    judge = judged(path, start)
    assert judge.elapsed >= 0.0
    assert judge.kick_time is None or judge.kick_time >= 0.0


def test_steps_before_the_start_and_garbage_are_ignored():
    judge = KickJudge()
    judge.observe(0.5, (0.0, 0.0), FOOT, True)
    judge.start(1.0)
    judge.observe(1.1, (math.nan, 0.0), FOOT, True)
    assert judge.touched_at is None and not judge.kicked


def test_a_fall_is_the_axle_dropping():
    judge = KickJudge()
    judge.start(0.0)
    judge.observe(0.1, (1.0, 0.0), (0.0, 0.0, 0.0), False)
    judge.observe(0.2, (1.0, 0.0), (0.0, 0.0, -0.03), False)
    assert judge.fell


def test_the_robot_may_be_looked_at_less_often_than_the_ball():
    judge = KickJudge()
    judge.start(0.0)
    judge.observe(0.002, (0.5, 0.0), (0.0, 0.0, 0.0), False)
    judge.observe(0.004, (0.5, 0.0), None, True)
    judge.observe(0.020, (0.6, 0.0), (0.1, 0.0, 0.0), False)
    judge.observe(0.022, (0.5 + KICK_DISTANCE_M, 0.0), None, False)
    assert judge.touch_time == 0.004 and judge.kick_time == 0.022
    assert judge.distance == 0.1 and not judge.fell


def ends(*rows):
    return [Endpoint(kind, name, '/student') for kind, name in rows]


def test_miros_own_interface_and_anything_of_ones_own_is_allowed():
    assert breaches(ends((PUBLISHER, '/miro/control/cmd_vel'),
                         (SUBSCRIPTION, '/miro/sensors/caml/compressed'),
                         (SUBSCRIPTION, '/clock'), (PUBLISHER, '/rosout'),
                         (PUBLISHER, '/parameter_events'),
                         (PUBLISHER, '/miro/kick_blue_ball/debug/caml'),
                         (CLIENT, '/student/get_parameters')), 'miro') == []


def test_each_way_beyond_miros_interface_is_named():
    said = breaches(ends((PUBLISHER, '/clock'), (PUBLISHER, '/miro/sensors/odom'),
                         (PUBLISHER, '/miro02/control/cmd_vel'),
                         (PUBLISHER, '/miro_sim/set_pose'),
                         (SUBSCRIPTION, '/miro_sim/ball'), (CLIENT, '/miro_sim/reset')), 'miro')
    assert len(said) == 6
    assert any('/clock' in s and 'clock of its own' in s for s in said)
    assert any('/miro/sensors/odom' in s and "faking the robot's sensors" in s for s in said)
    assert any('/miro02/control/cmd_vel' in s and "another robot's" in s for s in said)
    assert sum("the simulator's own" in s for s in said) == 3


class _Graph:
    """A node's graph API where listing one node's service clients fails."""

    def __init__(self, still_there):
        self.still_there = still_there

    def get_topic_names_and_types(self):
        return []

    def get_node_names_and_namespaces(self):
        return [('cheat', '/')] if self.still_there else []

    def get_client_names_and_types_by_node(self, name, namespace):
        raise RuntimeError('lookup failed')


def test_a_watch_that_can_not_look_fails_the_episode():
    from miro_ball.grading.watch import GraphWatch, verdict

    reasons = verdict(GraphWatch(_Graph(still_there=True)), 'miro')
    assert len(reasons) == 1 and 'graph watch failed' in reasons[0] and '/cheat' in reasons[0]


def test_a_node_that_left_while_it_was_looked_at_is_no_failure():
    from miro_ball.grading.watch import GraphWatch, verdict

    assert verdict(GraphWatch(_Graph(still_there=False)), 'miro') == []
