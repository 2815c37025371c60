"""What counts in an episode, judged by the one judge from what the world says (pure), and
which uses of the ROS graph are beyond MiRo's interface."""
import math

import pytest
from hypothesis import given, strategies as st

from miro_ball.grading.watch import breaches, CLIENT, Endpoint, PUBLISHER, SUBSCRIPTION
from miro_ball.run.judge import BALL_HISTORY, Judge, KICK_DISTANCE_M, observe, SETTLE_S

ROBOT = 'miro'


def judged(path, start=1.0):
    """A judge started at ``start`` and fed (t, ball x, touching) ticks."""
    judge = Judge(start)
    for t, x, touching in path:
        if touching:
            judge.touch(ROBOT, t, (x, 0.0))
        judge.ball(t, (x, 0.0, 0.1))
    return judge


def test_a_ball_that_moves_untouched_is_no_kick():
    judge = judged([(1.1, 0.0, False), (1.2, 2.0, False), (1.3, 2.0, False)])
    assert not judge.kicked and judge.moved == 0.0 and judge.kicker is None


def test_a_kick_counts_from_the_first_touch_and_names_the_kicker():
    judge = judged([(1.1, 0.0, False), (1.2, 0.0, True), (1.5, 0.2, False),
                    (1.8, 0.2 + KICK_DISTANCE_M, False)])
    assert judge.kicked and judge.kick_time == 1.8 - 1.0 and judge.kicker == ROBOT
    assert judge.touch_time == 1.2 - 1.0


def test_a_ball_teleported_after_a_touch_counts_from_where_it_was_touched():
    judge = judged([(1.1, 0.5, True), (1.2, 0.5 + KICK_DISTANCE_M - 0.01, False)])
    assert not judge.kicked


def test_a_touch_heard_after_the_balls_next_positions_judges_as_if_in_time():
    """Over ROS a tick's touch may come after the ball's next ticks: the same kick time."""
    in_time = judged([(0.02, 0.0, True), (0.04, 0.2, False), (0.06, 0.4, False),
                      (0.08, 0.6, False)], start=0.0)
    late = Judge(0.0)
    for t, x in [(0.02, 0.0), (0.04, 0.2), (0.06, 0.4), (0.08, 0.6)]:
        late.ball(t, (x, 0.0))
    late.touch(ROBOT, 0.02, (0.0, 0.0))
    assert late.kick_time == in_time.kick_time == 0.06


def test_the_balls_history_is_bounded():
    judge = Judge(0.0)
    for tick in range(10 * BALL_HISTORY):
        judge.ball(tick * 0.02, (0.0, 0.0))
    assert len(judge.ball_history) == BALL_HISTORY


@given(st.lists(st.tuples(st.floats(-10, 10), st.floats(-3, 3), st.booleans()), max_size=30),
       st.floats(0, 5))
def test_times_are_never_negative_nor_before_the_start(path, start):
    judge = judged(path, start)
    assert judge.elapsed >= 0.0
    assert judge.kick_time is None or judge.kick_time >= 0.0
    assert judge.touch_time is None or judge.touch_time > 0.0


def test_what_came_before_the_start_and_garbage_are_ignored():
    judge = Judge(1.0)
    judge.touch(ROBOT, 0.5, (0.0, 0.0))
    judge.touch(ROBOT, 1.0, (0.0, 0.0))  # the step that ended at the start
    judge.touch(ROBOT, math.nan, (0.0, 0.0))
    judge.touch(ROBOT, 1.1, (math.inf, 0.0))
    judge.ball(1.1, (math.nan, 0.0))
    judge.robot(ROBOT, 1.1, (0.0, math.nan, 0.0))
    judge.clock(math.nan)
    assert judge.touched_at is None and not judge.kicked and judge.robots == {}
    assert judge.elapsed == 0.0


def test_the_start_is_when_everything_was_first_seen_however_late_it_was_heard():
    judge = Judge(2.0)
    assert judge.first_seen is None
    judge.ball(2.02, (0.5, 0.0))
    judge.robot('a', 2.02, (0.0, 0.0, 0.0))
    judge.clock(2.3)  # heard later, behind a busy machine
    judge.robot('b', 2.04, (1.0, 0.0, 0.0))
    judge.robot('b', 2.3, (1.1, 0.0, 0.0))
    assert judge.first_seen == pytest.approx(0.04) and judge.elapsed == pytest.approx(0.3)
    assert judge.robots['b'].start == (1.0, 0.0, 0.0)


def test_start_forgets_the_episode_before():
    judge = judged([(1.1, 0.0, True), (1.2, 1.0, False)])
    assert judge.kicked
    judge.start(2.0)
    assert not judge.kicked and judge.touched_at is None and judge.elapsed == 0.0


def test_a_fall_is_the_axle_dropping_and_says_which_robot():
    judge = Judge(0.0)
    judge.robot('a', 0.1, (0.0, 0.0, 0.0))
    judge.robot('b', 0.1, (1.0, 0.0, 0.0))
    judge.robot('b', 0.2, (1.0, 0.0, -0.03))
    assert judge.fell and judge.robots['b'].fell and not judge.robots['a'].fell


def test_the_distance_is_every_robots_over_the_floor():
    judge = Judge(0.0)
    for t, x in [(0.02, 0.0), (0.04, 0.1), (0.06, 0.3)]:
        judge.robot('a', t, (x, 0.0, 0.0))
        judge.robot('b', t, (0.0, x, 0.0))
    assert judge.distance == 2 * 0.3 and not judge.fell


def test_the_episode_is_over_after_the_settle_time_a_fall_or_the_limit():
    judge = judged([(0.02, 0.0, True), (0.04, KICK_DISTANCE_M, False)], start=0.0)
    assert judge.over(60.0) is None  # kicked at 0.04: it settles first
    judge.clock(0.04 + SETTLE_S)
    assert judge.over(60.0) == 'kicked'
    assert judge.over(60.0, settle_s=5.0) is None
    assert judge.over(1.0, settle_s=5.0) == 'kicked'  # the limit cuts the settling short
    quiet = Judge(0.0)
    quiet.clock(10.0)
    assert quiet.over(10.0) == 'limit' and quiet.over(20.0) is None
    quiet.robot(ROBOT, 10.0, (0.0, 0.0, 0.0))
    quiet.robot(ROBOT, 10.02, (0.0, 0.0, -0.05))
    assert quiet.over(20.0) == 'fell'


class TouchingWorld:
    """What observe() reads of a world (a SimWorld's names), the ball touched from step 3
    on; counts the contact checks asked."""

    ticks_per_platform_tick = 10

    def __init__(self):
        self.step_index, self.dt, self.asked = 0, 0.002, 0
        self.robots = {ROBOT: type('Robot', (), {'ground_truth': lambda _: (0, 0, 0, 0)})()}

    @property
    def time(self):
        return self.step_index * self.dt

    def touching(self, name):
        self.asked += 1
        return self.step_index >= 3

    def ball_position(self):
        return (self.step_index * 0.01, 0.0, 0.05)


def test_observe_asks_for_contacts_until_the_first_touch_only():
    """After each physics step observe() asks whether a robot touches the ball, until the
    judge has its touch: any later one counts for nothing, and asking was a tenth of a
    learning step's Python."""
    judge, world = Judge(0.0), TouchingWorld()
    for step in range(1, 50):
        world.step_index = step
        observe(judge, world, ROBOT)
    assert world.asked == 3 and judge.touch_time == 3 * world.dt
    assert judge.touched_at == (0.03, 0.0) and judge.kicked  # the ball went on 0.46 m


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


def test_the_demo_summary_says_kicked_once_and_how_a_run_without_its_kick_ended():
    from types import SimpleNamespace

    from miro_ball.lab import summary

    def said(judge, outcome):
        monitor = SimpleNamespace(judge=judge, robots={}, frames=0)
        return [line for line in summary(outcome, monitor, 1.0, None, []).splitlines()
                if line.startswith(('  kicked:', '  ended:'))]

    kicked = judged([(1.1, 0.0, False), (1.2, 0.0, True), (1.8, KICK_DISTANCE_M, False)])
    assert said(kicked, 'kicked') == ['  kicked:               yes']
    assert said(kicked, 'interrupted') == ['  kicked:               yes',
                                          '  ended:                interrupted (Ctrl+C)']
    untouched = judged([(1.1, 0.0, False)])
    assert said(untouched, 'limit') == ['  kicked:               no',
                                        '  ended:                at the time limit']
    assert said(untouched, 'node miro_sim exited with code 1')[1] == \
        '  ended:                node miro_sim exited with code 1'
