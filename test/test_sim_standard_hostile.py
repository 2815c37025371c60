"""The standard simulator services against a hostile or clumsy client, in-process.

Each request gets the standard's result code and one line, never an exception of ours
(answered 'a bug'), a hang or a world left broken: after it, the world still steps and
every entity's state is finite.
"""
import math
import os
import threading
import time
from types import SimpleNamespace

import pytest
from action_msgs.msg import GoalStatus
from geometry_msgs.msg import PoseStamped, TwistStamped
from nav_msgs.msg import Odometry
from sensor_msgs.msg import CompressedImage
from rclpy.action import ActionClient, GoalResponse
from rclpy.qos import QoSProfile
from simulation_interfaces import msg as si
from simulation_interfaces import srv
from simulation_interfaces.action import SimulateSteps

from fuzzmsg import hostile
from miro_ball.miro.interface import RobotTopics
from miro_sim_bullet.physics.sensors import GRAVITY
from miro_sim_bullet.ros import step_action
from miro_sim_bullet.ros.step_action import MAX_GOALS, StepAction
from miro_sim_bullet.scene.world_model import MAX_SHAPES, Shape
from rostools import advance_ticks, Probe, spin_until

OK = si.Result.RESULT_OK
FAILED = si.Result.RESULT_OPERATION_FAILED
MIRO_URDF = 'package://miro_ball/robots/miro.urdf'
BOX = 'package://miro_ball/worlds/models/box.toml'


def serve(node, kind, **fields):
    """The response of the simulator's ``kind`` service to a request of ``fields``."""
    request = fields.pop('request', None) or kind.Request(**fields)
    service = next(s for s in node.control.services if s.srv_type is kind)
    response = service.callback(request, kind.Response())
    message = response.result.error_message if hasattr(response, 'result') else ''
    assert 'a bug' not in message and '\n' not in message, message
    return response


def ok(response):
    assert response.result.result == OK, response.result.error_message
    return response


def still_works(node):
    """The world steps, and every entity's state is finite numbers."""
    states = ok(serve(node, srv.GetEntitiesStates))
    for name, state in zip(states.entities, states.states):
        p, q, v = state.pose.position, state.pose.orientation, state.twist.linear
        values = (p.x, p.y, p.z, q.x, q.y, q.z, q.w, v.x, v.y, v.z)
        assert all(math.isfinite(x) for x in values), (name, values)
    before = node.sim.time
    ok(serve(node, srv.StepSimulation, steps=1))
    assert node.sim.time > before
    return list(states.entities)


def pose(x=0.0, y=0.0, z=0.0, q=(0.0, 0.0, 0.0, 1.0), frame=''):
    stamped = PoseStamped()
    stamped.header.frame_id = frame
    stamped.pose.position.x, stamped.pose.position.y, stamped.pose.position.z = x, y, z
    o = stamped.pose.orientation
    o.x, o.y, o.z, o.w = q
    return stamped


def entity_state(stamped, linear=(0.0, 0.0, 0.0), angular=(0.0, 0.0, 0.0)):
    state = si.EntityState(header=stamped.header, pose=stamped.pose)
    t = state.twist
    t.linear.x, t.linear.y, t.linear.z = linear
    t.angular.x, t.angular.y, t.angular.z = angular
    return state


def aimed(request):
    """The same hostile request, aimed at something that exists: the ball, or a box file."""
    if hasattr(request, 'entity') and not request.entity:
        request.entity = 'ball'
    if isinstance(request, srv.SpawnEntity.Request) and not (request.uri or
                                                             request.resource_string):
        request.uri, request.allow_renaming = BOX, True
    return request


def test_every_service_answers_every_hostile_request(paused_sim):
    """Every field of every request, one at a time: NaN, inf, 1e308, integer limits, empty,
    10 kB and NUL strings, 1000-long lists; entity requests also aimed at the ball."""
    node = paused_sim
    for service in list(node.control.services):
        kind = service.srv_type
        for request in hostile(kind.Request):
            for sent in (request, aimed(request)):
                serve(node, kind, request=sent)
                if node.state == si.SimulationState.STATE_STOPPED:  # asked for: go on
                    node.act('play')
                    node.act('pause')
                if node.state == si.SimulationState.STATE_NO_WORLD:
                    ok(serve(node, srv.LoadWorld, uri='miro'))
    assert 'ball' in still_works(node)


def test_numbers_that_would_poison_physics_are_refused(paused_sim):
    """A NaN twist made every body NaN a step later; a quaternion of 1e308s overflowed to
    a zero rotation; both left the world answering 'SVD did not converge' for good."""
    node = paused_sim
    invalid = srv.SetEntityState.Response.INVALID_POSE
    for linear, angular in (((math.nan, 0, 0), (0, 0, 0)), ((0, 0, 0), (0, 0, math.inf)),
                            ((1e308, 0, 0), (0, 0, 0)), ((0, 0, 0), (0, 0, 1e6))):
        set_ = serve(node, srv.SetEntityState, entity='ball',
                     state=entity_state(pose(z=0.2), linear, angular))
        assert set_.result.result == invalid and 'twist' in set_.result.error_message
    huge = (1e308, 1e308, 0.0, 0.0)
    ok(serve(node, srv.SetEntityState, entity='ball', state=entity_state(pose(z=0.2, q=huge))))
    q = ok(serve(node, srv.GetEntityState, entity='ball')).state.pose.orientation
    assert (q.x, q.y) == pytest.approx((2 ** -0.5, 2 ** -0.5))
    ok(serve(node, srv.SpawnEntity, name='tilted', uri=MIRO_URDF,
             initial_pose=pose(x=-0.6, y=0.6, q=huge)))
    node.advance(100)
    still_works(node)


def test_a_pose_in_an_entity_frame_is_checked_in_the_world_frame(paused_sim):
    node = paused_sim
    ok(serve(node, srv.SetEntityState, entity='ball', state=entity_state(pose(x=900.0))))
    beyond = serve(node, srv.SetEntityState, entity='ball',
                   state=entity_state(pose(x=900.0, frame='ball')))
    assert beyond.result.result == srv.SetEntityState.Response.INVALID_POSE
    garbage = serve(node, srv.SetEntityState, entity='ball',
                    state=entity_state(pose(frame='no_such_frame')))
    assert garbage.result.result == si.Result.RESULT_NOT_FOUND
    wall = next(n for n in still_works(node) if n.startswith(('ring', 'wall', 'ground')))
    static = serve(node, srv.SetEntityState, entity=wall, state=entity_state(pose()))
    assert static.result.result == FAILED and 'static' in static.result.error_message


def test_every_name_get_entities_lists_is_taken(paused_sim):
    """A world's unnamed walls are listed as '<table>_<k>': a MiRo spawned as one hid it."""
    node = paused_sim
    unnamed = next(n for n in still_works(node) if n.startswith(('ring_', 'wall_', 'ground_')))
    for uri in (MIRO_URDF, BOX):
        taken = serve(node, srv.SpawnEntity, name=unnamed, uri=uri)
        assert taken.result.result == srv.SpawnEntity.Response.NAME_NOT_UNIQUE


def test_stepping_is_bounded_and_resets_take_known_scopes_only(paused_sim):
    node = paused_sim
    for steps in (0, 5001, 2 ** 64 - 1):
        refused = serve(node, srv.StepSimulation, steps=steps)
        assert refused.result.result == FAILED
        assert '1 to 5000 (10 s)' in refused.result.error_message
    assert node.sim.time == 0.0
    ok(serve(node, srv.StepSimulation, steps=3))
    for scope in range(256):
        reset = serve(node, srv.ResetSimulation, scope=scope)
        if scope <= 7 or scope == 255:
            ok(reset)
        else:  # 8 was read as 0, a whole reset
            assert reset.result.result == FAILED, scope
    still_works(node)


def test_a_reset_rewinds_the_world_unless_a_body_came_or_went(paused_sim):
    """The grader resets every episode: a whole reset rewinds the world built (the same
    bodies, far cheaper than building them again) and leaves every entity as a fresh world
    has it, and as it goes on from there; after a spawn it is built anew."""
    node = paused_sim
    world, built = node.sim, node.sim.generation

    def states():
        answer = ok(serve(node, srv.GetEntitiesStates))
        return dict(zip(answer.entities, answer.states))
    fresh = states()
    ok(serve(node, srv.StepSimulation, steps=50))
    fresh_later = states()
    robot = next(iter(node.sim.robots))
    ok(serve(node, srv.SetEntityState, entity='ball',
             state=entity_state(pose(0.3, 0.4, 0.3), linear=(1.0, 0.5, 0.0))))
    ok(serve(node, srv.SetEntityState, entity=robot, state=entity_state(pose(-0.3, 0.2))))
    ok(serve(node, srv.StepSimulation, steps=200))
    assert states() != fresh
    ok(serve(node, srv.ResetSimulation))
    assert node.sim is world and node.sim.generation == built  # rewound, not built
    assert node.sim.time == 0.0 and states() == fresh
    ok(serve(node, srv.StepSimulation, steps=50))
    assert states() == fresh_later

    ok(serve(node, srv.SpawnEntity, name='crate', uri=BOX, initial_pose=pose(0.8, 0.8)))
    ok(serve(node, srv.ResetSimulation, scope=srv.ResetSimulation.Request.SCOPE_ALL))
    assert node.sim.generation > built  # built anew: the crate is gone
    assert states() == fresh
    still_works(node)


def test_the_progress_lines_real_time_factor_counts_the_steps_taken_across_a_reset(
        paused_sim, monkeypatch):
    """It was the clock's change over the wall time: a reset between two lines made it
    negative ('real-time factor -2.64')."""
    node = paused_sim
    node._progress = (time.monotonic(), node.steps_taken)
    ok(serve(node, srv.StepSimulation, steps=500))
    ok(serve(node, srv.ResetSimulation))
    ok(serve(node, srv.StepSimulation, steps=100))
    said = []
    monkeypatch.setattr(node, 'get_logger', lambda: SimpleNamespace(info=said.append))
    node._progress = (node._progress[0] - 10.0, node._progress[1])  # the line is due
    node._report_progress()
    factor = float(said[0].split('real-time factor ')[1].split(',')[0])
    assert said[0].startswith('sim time 0.2 s,') and 0.1 <= factor <= 0.12, said


def test_a_falling_balls_acceleration_is_gravity(paused_sim):
    node = paused_sim
    ok(serve(node, srv.SetEntityState, entity='ball', state=entity_state(pose(0.5, 0.5, 1.0))))
    ok(serve(node, srv.StepSimulation, steps=2 * node.sim.ticks_per_platform_tick))
    falling = ok(serve(node, srv.GetEntityState, entity='ball')).state.acceleration.linear
    # PyBullet's damping takes 0.015 m/s² off it at the default physics step.
    assert (falling.x, falling.y, falling.z) == pytest.approx((0.0, 0.0, -GRAVITY), abs=0.05)


def test_robots_are_limited_per_request_and_per_world(paused_sim):
    node = paused_sim
    one = si.SpawnEntity(allow_renaming=True, entity_resource=si.Resource(uri=MIRO_URDF))
    many = serve(node, srv.SpawnEntities, spawn_requests=[one] * 10000)
    assert many.result.result == FAILED and 'at most 64' in many.result.error_message
    assert len(node.sim.robots) == 1
    for k in range(15):  # on the ground beyond the arena's wall, half a metre apart
        ok(serve(node, srv.SpawnEntity, allow_renaming=True, uri=MIRO_URDF,
                 initial_pose=pose(x=-3.5 + 0.5 * (k % 5), y=1.0 + 0.5 * (k // 5), z=-1.0)))
    full = serve(node, srv.SpawnEntity, allow_renaming=True, uri=MIRO_URDF,
                 initial_pose=pose(x=-3.0, y=-1.0, z=-1.0))
    assert full.result.result == FAILED and '16 robots' in full.result.error_message
    for name in list(node.sim.robots):  # every robot gone, its topics with it
        ok(serve(node, srv.DeleteEntity, entity=name))
    assert not node.robots
    still_works(node)
    ok(serve(node, srv.SpawnEntity, name='again', uri=MIRO_URDF))
    assert list(node.robots) == ['again']
    ok(serve(node, srv.DeleteEntity, entity='ball'))
    ok(serve(node, srv.ResetSimulation, scope=srv.ResetSimulation.Request.SCOPE_STATE))
    assert 'ball' not in still_works(node)  # a state reset does not undo a deletion
    ok(serve(node, srv.ResetSimulation))
    assert 'ball' in still_works(node)


def test_no_world_is_said_by_every_service_until_one_is_loaded(paused_sim):
    node = paused_sim
    ok(serve(node, srv.UnloadWorld))
    incorrect = si.Result.RESULT_INCORRECT_STATE
    for kind in (srv.GetEntities, srv.GetEntitiesStates, srv.GetEntityState,
                 srv.SetEntityState, srv.GetEntityInfo, srv.SetEntityInfo, srv.GetEntityBounds,
                 srv.SpawnEntity, srv.DeleteEntity, srv.StepSimulation, srv.ResetSimulation,
                 srv.GetNamedPoses):
        assert serve(node, kind).result.result == incorrect, kind.__name__
    no_world = srv.GetCurrentWorld.Response.NO_WORLD_LOADED
    assert serve(node, srv.GetCurrentWorld).result.result == no_world
    assert serve(node, srv.UnloadWorld).result.result == no_world
    play = si.SimulationState(state=si.SimulationState.STATE_PLAYING)
    refused = serve(node, srv.SetSimulationState, state=play)
    assert refused.result.result == srv.SetSimulationState.Response.STATE_TRANSITION_ERROR
    ok(serve(node, srv.LoadWorld, uri='package://miro_ball/worlds/football_pitch.toml'))
    assert {'miro01', 'miro02', 'miro03', 'ball'} <= set(still_works(node))


def test_files_that_would_block_or_never_end_are_refused(paused_sim, tmp_path):
    """A FIFO named .toml blocked the simulator until someone wrote to it."""
    node = paused_sim
    fifo = tmp_path / 'fifo.toml'
    os.mkfifo(fifo)
    (tmp_path / 'folder.toml').mkdir()
    text = tmp_path / 'text.toml'
    text.write_text('x')
    for uri in (str(fifo), f'file://{fifo}', str(tmp_path / 'folder.toml'), '/dev/zero',
                'file:///dev/zero', '/' + 'x' * 10000 + '.toml', 'x' * 10000,
                f'{tmp_path}/\x00.toml', str(tmp_path / 'missing.toml')):
        loaded = serve(node, srv.LoadWorld, uri=uri)
        assert loaded.result.result in (srv.LoadWorld.Response.NO_RESOURCE,
                                        srv.LoadWorld.Response.RESOURCE_PARSE_ERROR), uri
        assert len(loaded.result.error_message) < 400
        spawned = serve(node, srv.SpawnEntity, name='thing', uri=uri)
        assert spawned.result.result in (srv.SpawnEntity.Response.NO_RESOURCE,
                                         srv.SpawnEntity.Response.UNSUPPORTED_FORMAT), uri
    for folders in ([str(tmp_path)], ['/proc'], [str(text)], [str(tmp_path / 'none')],
                    ['\x00'], [''] * 16):
        listed = serve(node, srv.GetAvailableWorlds, additional_sources=folders,
                       continue_on_error=True)
        assert 'football_pitch' in {w.name for w in ok(listed).worlds}
    assert ok(serve(node, srv.GetCurrentWorld)).world.name == 'miro'
    still_works(node)


def test_spawn_resources_that_are_wrong_get_their_codes(paused_sim):
    node = paused_sim
    code = srv.SpawnEntity.Response
    box = '[[box]]\nsize = [0.1, 0.1, 0.1]\n'
    for text, expected in (('<robot', code.RESOURCE_PARSE_ERROR),
                           ('<robot name="r2"><link name="base"/></robot>',
                            code.UNSUPPORTED_ASSETS),
                           ('<html/>', code.UNSUPPORTED_FORMAT),
                           ('<' + 'x' * 2_000_000, code.RESOURCE_PARSE_ERROR),
                           ('#' * 2_000_000, code.RESOURCE_PARSE_ERROR),
                           ('[[box]\n', code.RESOURCE_PARSE_ERROR),
                           (box + box, code.RESOURCE_PARSE_ERROR),
                           ('[ball]\nradius = 0.05\n', code.NAME_NOT_UNIQUE)):
        spawned = serve(node, srv.SpawnEntity, allow_renaming=True, resource_string=text)
        assert spawned.result.result == expected, (text[:40], spawned.result.error_message)
    still_works(node)


def test_a_robot_deleted_while_its_topics_are_in_use(paused_sim, ros_context, executor):
    node = paused_sim
    probe = Probe(ros_context, executor)
    topics = RobotTopics(next(iter(node.robots)))
    odom = probe.watch(Odometry, topics.odom)
    drive = probe.publisher(TwistStamped, topics.cmd_vel)
    spin_until(executor, lambda: node.robots[topics.name].publisher('odom')
               .get_subscription_count() > 0)
    advance_ticks(node, executor, 5)
    spin_until(executor, lambda: odom)
    ok(serve(node, srv.DeleteEntity, entity=topics.name))
    for _ in range(5):  # drain() raises what a callback raised
        drive.publish(TwistStamped())
        advance_ticks(node, executor)
    assert not node.robots
    still_works(node)


def test_simulate_steps_huge_many_and_across_a_world_load(paused_sim, ros_context, executor):
    """A goal of 2**64-1 steps keeps the simulator answering and is cancelled; goals beyond
    those waiting are rejected; unload_world ends the goal in hand, a load steps on."""
    node = paused_sim
    probe = Probe(ros_context, executor)
    action = ActionClient(probe.node, SimulateSteps, '/miro_sim/simulate_steps')
    assert action.wait_for_server(timeout_sec=10)

    def send(steps):
        sent = action.send_goal_async(SimulateSteps.Goal(steps=steps))
        spin_until(executor, sent.done)
        return sent.result()

    endless = send(2 ** 64 - 1)
    assert endless.accepted
    spin_until(executor, lambda: node.sim.time > 1.0)  # a second simulated, and on
    still_works(node)
    ok(serve(node, srv.LoadWorld, uri='package://miro_ball/worlds/football_pitch.toml'))
    start = node.sim.time
    spin_until(executor, lambda: node.sim.time > start + 0.1)
    cancel = endless.cancel_goal_async()
    spin_until(executor, cancel.done)
    ended = endless.get_result_async()
    spin_until(executor, ended.done)
    assert ended.result().status == GoalStatus.STATUS_CANCELED

    queued = [send(1_000_000) for _ in range(MAX_GOALS + 3)]
    assert [g.accepted for g in queued].count(False) >= 3
    ok(serve(node, srv.UnloadWorld))
    for goal in (g for g in queued if g.accepted):
        ended = goal.get_result_async()
        spin_until(executor, ended.done)
        assert ended.result().status == GoalStatus.STATUS_ABORTED
        assert ended.result().result.result.result == FAILED
    ok(serve(node, srv.LoadWorld, uri='miro'))
    assert 'ball' in still_works(node)


class Steps:
    """A client of /miro_sim/simulate_steps whose own queues are deep: what goes unanswered
    is the simulator's doing."""

    def __init__(self, ros_context, executor):
        self.executor = executor
        deep = QoSProfile(depth=1000)
        self.action = ActionClient(Probe(ros_context, executor).node, SimulateSteps,
                                   '/miro_sim/simulate_steps', goal_service_qos_profile=deep,
                                   result_service_qos_profile=deep,
                                   cancel_service_qos_profile=deep)
        assert self.action.wait_for_server(timeout_sec=10)

    def send(self, steps):
        """The goal's handle, once answered."""
        sent = self.action.send_goal_async(SimulateSteps.Goal(steps=steps))
        spin_until(self.executor, sent.done)
        return sent.result()

    def result(self, goal):
        ended = goal.get_result_async()
        spin_until(self.executor, ended.done)
        return ended.result()


def test_every_goal_of_a_burst_is_answered(paused_sim, ros_context, executor):
    """16 goals sent at once: 10 were accepted and 6 never answered, neither accepted nor
    rejected (the action's services kept ROS's default queue of 10 requests)."""
    node = paused_sim
    steps = Steps(ros_context, executor)
    start = node.sim.time
    sent = [steps.action.send_goal_async(SimulateSteps.Goal(steps=5))
            for _ in range(MAX_GOALS + 4)]
    spin_until(executor, lambda: all(s.done() for s in sent))
    accepted = [s.result() for s in sent if s.result().accepted]
    assert len(accepted) >= MAX_GOALS  # the rest rejected: over the limit
    for goal in accepted:
        assert steps.result(goal).status == GoalStatus.STATUS_SUCCEEDED
    assert node.sim.time == pytest.approx(start + 5 * len(accepted) * node.sim.dt)
    still_works(node)


def test_a_cancelled_goal_that_waits_ends_at_once(paused_sim, ros_context, executor):
    """A goal waiting behind one of 2**64-1 steps was cancelled and never ended: only the
    goal in hand was looked at."""
    node = paused_sim
    steps = Steps(ros_context, executor)
    endless, waiting = steps.send(2 ** 64 - 1), steps.send(10)
    assert endless.accepted and waiting.accepted
    cancel = waiting.cancel_goal_async()
    spin_until(executor, cancel.done)
    assert steps.result(waiting).status == GoalStatus.STATUS_CANCELED
    assert endless.status in (GoalStatus.STATUS_ACCEPTED, GoalStatus.STATUS_EXECUTING)
    start = node.sim.time
    spin_until(executor, lambda: node.sim.time > start + 0.1)  # the endless one steps on
    cancel = endless.cancel_goal_async()
    spin_until(executor, cancel.done)
    assert steps.result(endless).status == GoalStatus.STATUS_CANCELED
    still_works(node)


def test_a_callback_that_fails_does_not_end_the_action(paused_sim, ros_context, executor,
                                                        monkeypatch, capfd):
    """rclpy raises a callback's error in the thread that spins the action's node, and it
    was caught there for good: one failed goal callback, and no goal was answered again. A
    failure in a goal's execution kept its place: 16 of them, and every goal was rejected."""
    node = paused_sim
    steps = Steps(ros_context, executor)
    accept, failed = node.step_action._accept, []

    def fails_once(request):
        if not failed:
            failed.append(request)
            raise RuntimeError('injected fault in the goal callback')
        return accept(request)
    node.step_action.server.register_goal_callback(fails_once)
    lost = steps.action.send_goal_async(SimulateSteps.Goal(steps=1))
    spin_until(executor, lambda: failed)
    for _ in range(3):
        goal = steps.send(2)
        assert steps.result(goal).status == GoalStatus.STATUS_SUCCEEDED
    assert not lost.done()  # its callback failed: no answer, and the next ones got theirs
    assert 'injected fault in the goal callback' in capfd.readouterr().err

    def broken(handle):
        raise RuntimeError('injected fault in a goal')
    monkeypatch.setattr(step_action, 'Goal', broken)
    for _ in range(MAX_GOALS):
        assert steps.result(steps.send(1)).status == GoalStatus.STATUS_ABORTED
    monkeypatch.undo()
    goal = steps.send(3)
    assert goal.accepted and steps.result(goal).status == GoalStatus.STATUS_SUCCEEDED
    still_works(node)


def test_a_goal_accepted_as_the_action_closes_ends_at_once(ros_context):
    """close() ended the goals waiting; one whose execution began just after waited for
    ever, a thread with it."""
    action = StepAction(host=None, context=ros_context)
    assert action._accept(SimulateSteps.Goal(steps=10)) == GoalResponse.ACCEPT
    action.close()
    ended = []
    handle = SimpleNamespace(request=SimulateSteps.Goal(steps=10), is_cancel_requested=False,
                             abort=lambda: ended.append('aborted'))
    late = threading.Thread(target=action._execute, args=(handle,), daemon=True)
    late.start()
    late.join(timeout=10.0)  # a guard against the hang
    assert not late.is_alive() and ended == ['aborted']
    assert action._accept(SimulateSteps.Goal(steps=10)) == GoalResponse.REJECT


def test_name_filters_that_backtrack_forever_in_re_answer_at_once(paused_sim):
    """'(a+)+$' took 2**n steps in Python's re on a name of n a's and a '_': a spawned box
    named so, then one get_entities, and the simulator hung for good."""
    node = paused_sim
    long_name = 'a' * 60 + '_1'
    ok(serve(node, srv.SpawnEntity, name=long_name, uri=BOX, initial_pose=pose(x=1.0, y=1.0)))
    for pattern, kept in (('(a+)+$', []), ('^(a|aa)*_', [long_name]),
                          ('a*' * 100 + 'Q', []), ('^(a*)*_[[:digit:]]$', [long_name]),
                          ('x{1,5000}', None), ('(.?){990}Q', None), ('[a-z]{0,120}Q', [])):
        got = serve(node, srv.GetEntities, filters=si.EntityFilters(filter=pattern))
        if kept is None:  # an automaton of more than 256 states: refused
            assert got.result.result == FAILED and 'too complex' in got.result.error_message
        else:
            assert ok(got).entities == kept, pattern


def test_deleting_statics_renames_nothing_and_the_ground_stays(paused_sim):
    """Unnamed walls were numbered as they came: deleting 'ring_3' made 'ring_4' the next
    'ring_3' (a second delete took another wall); deleting the ground broke every later
    get_entities (KeyError) for good."""
    node = paused_sim
    before = still_works(node)
    ok(serve(node, srv.DeleteEntity, entity='ring_3'))
    again = serve(node, srv.DeleteEntity, entity='ring_3')
    assert again.result.result == si.Result.RESULT_NOT_FOUND
    expected = [name for name in before if name != 'ring_3']
    assert still_works(node) == expected
    ok(serve(node, srv.ResetSimulation, scope=srv.ResetSimulation.Request.SCOPE_STATE))
    assert still_works(node) == expected  # rebuilt without it, the others keep their names
    ground = serve(node, srv.DeleteEntity, entity='ground_0')
    assert ground.result.result == FAILED and 'ground' in ground.result.error_message
    assert still_works(node) == expected


def test_a_robot_deleted_while_its_images_are_in_flight(make_sim, ros_context, executor):
    """Running free, the eyes of an instant are drawn while physics steps on; a robot deleted
    then had them published on its ended topics: InvalidHandle in the simulator's turn."""
    node = make_sim(real_time_factor=0.0)
    probe = Probe(ros_context, executor)
    topics = RobotTopics(next(iter(node.robots)))
    images = probe.watch(CompressedImage, topics.eye_compressed('caml'))
    spin_until(executor, lambda: node.robots[topics.name].wanted_eyes())
    play = si.SimulationState(state=si.SimulationState.STATE_PLAYING)
    ok(serve(node, srv.SetSimulationState, state=play))
    spin_until(executor, lambda: len(images) >= 2 and node.eyes.pending)
    ok(serve(node, srv.DeleteEntity, entity=topics.name))
    start = node.sim.time
    spin_until(executor, lambda: node.sim.time > start + 0.5)  # raises what a turn raised
    pause = si.SimulationState(state=si.SimulationState.STATE_PAUSED)
    ok(serve(node, srv.SetSimulationState, state=pause))
    still_works(node)


def test_movable_bodies_are_not_spawned_inside_each_other(paused_sim):
    """64 boxes spawned on one spot took 15 s of physics for 50 steps; 2,500 never ended."""
    node = paused_sim
    where = pose(x=1.0, y=1.0)
    one = si.SpawnEntity(allow_renaming=True, entity_resource=si.Resource(uri=BOX),
                         initial_pose=where)
    spawned = serve(node, srv.SpawnEntities, spawn_requests=[one] * 64)
    codes = [r.result.result for r in spawned.results]
    assert codes[0] == OK and set(codes[1:]) == {srv.SpawnEntity.Response.INVALID_POSE}
    assert 'inside box1' in spawned.results[1].result.error_message
    on_top = pose(x=1.0, y=1.0, z=0.3)
    ok(serve(node, srv.SpawnEntity, name='stacked', uri=BOX, initial_pose=on_top))
    ball = serve(node, srv.SpawnEntity, resource_string='[ball]\nradius = 0.05\n')
    assert ball.result.result == srv.SpawnEntity.Response.NAME_NOT_UNIQUE
    still_works(node)


def test_a_miro_is_not_spawned_inside_another_or_a_box_inside_a_miro(paused_sim):
    """A MiRo spawned on the one at the origin (no pose given) threw both across the room."""
    node = paused_sim
    robot = next(iter(node.robots))
    on_it = serve(node, srv.SpawnEntity, name='miro_b', uri=MIRO_URDF)
    assert on_it.result.result == srv.SpawnEntity.Response.INVALID_POSE
    assert f'inside {robot}' in on_it.result.error_message
    box = serve(node, srv.SpawnEntity, name='crate', uri=BOX)
    assert box.result.result == srv.SpawnEntity.Response.INVALID_POSE
    ok(serve(node, srv.SpawnEntity, name='miro_b', uri=MIRO_URDF,
                    initial_pose=pose(x=-0.6, y=0.6)))
    still_works(node)


def test_a_miro_is_never_put_inside_a_wall_or_a_table_but_may_stand_beside_or_on_one(
        paused_sim):
    """MiRo set or spawned into a wall panel was answered OK, and thrown 2.2 m up and out of
    the arena. Walls and tables are tested by their shapes: beside a turned panel (inside
    its bounding box) is clear, and so are a floor and a table top to stand on."""
    node = paused_sim
    robot = next(iter(node.robots))
    where = ok(serve(node, srv.GetEntityState, entity=robot)).state.pose
    half_turn = (0.0, 0.0, math.sin(math.pi / 12), math.cos(math.pi / 12))  # 30 deg
    into_panel = {'x': 1.15, 'y': 0.0}  # panel 0 stands at x = 1.21, MiRo's nose 0.19 ahead
    set_ = serve(node, srv.SetEntityState, entity=robot, state=entity_state(pose(**into_panel)))
    assert set_.result.result == srv.SetEntityState.Response.INVALID_POSE
    assert set_.result.error_message == (f'{robot} there would be inside ring_0: put it '
                                         'elsewhere (or on top)')
    assert ok(serve(node, srv.GetEntityState, entity=robot)).state.pose == where
    spawned = serve(node, srv.SpawnEntity, name='miro_b', uri=MIRO_URDF,
                    initial_pose=pose(**into_panel, q=half_turn))
    assert spawned.result.result == srv.SpawnEntity.Response.INVALID_POSE
    assert 'miro_b there would be inside ring_0' in spawned.result.error_message
    assert 'miro_b' not in still_works(node)
    # Nose 5 mm from panel 0; facing panel 1 (at 30 deg), 5 mm from it, well inside the
    # panel's bounding box.
    ok(serve(node, srv.SetEntityState, entity=robot, state=entity_state(pose(x=1.01))))
    beside = 1.01 * math.cos(math.pi / 6), 1.01 * math.sin(math.pi / 6)
    ok(serve(node, srv.SpawnEntity, name='miro_b', uri=MIRO_URDF,
             initial_pose=pose(*beside, q=half_turn)))
    node.advance(500)  # a second: neither is thrown
    for name, (x, y) in ((robot, (1.01, 0.0)), ('miro_b', beside)):
        at = ok(serve(node, srv.GetEntityState, entity=name)).state.pose.position
        assert (at.x, at.y, at.z) == pytest.approx((x, y, 0.0), abs=0.02), name
    ok(serve(node, srv.LoadWorld, uri='tables'))  # MiRo stands on the table at the origin
    robot = next(iter(node.robots))
    ok(serve(node, srv.SetEntityState, entity=robot, state=entity_state(pose(x=0.3, z=1.0))))
    ok(serve(node, srv.SetEntityState, entity=robot, state=entity_state(pose(x=0.3))))  # under
    into_top = serve(node, srv.SetEntityState, entity=robot,
                     state=entity_state(pose(x=0.3, z=0.9)))
    assert into_top.result.result == srv.SetEntityState.Response.INVALID_POSE
    assert 'would be inside table_' in into_top.result.error_message
    still_works(node)


def test_shapes_are_limited_per_world(paused_sim):
    """64 a request, but requests without end: as many shapes as a world file may hold."""
    node = paused_sim
    for i in range(MAX_SHAPES - len(node.sim.description.shapes) - 1):
        node.sim.spawn_shape(Shape(kind='box', position=(i % 45 * 0.3 - 6, i // 45 * 0.3 - 6,
                                                         0.05), size=(0.1,) * 3, name=f'b{i}'))
    ok(serve(node, srv.SpawnEntity, allow_renaming=True, uri=BOX, initial_pose=pose(z=3.0)))
    full = serve(node, srv.SpawnEntity, allow_renaming=True, uri=BOX, initial_pose=pose(z=4.0))
    assert full.result.result == FAILED and '2000 shapes' in full.result.error_message
