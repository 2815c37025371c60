"""A client written only against the standard simulation_interfaces drives the simulator.

Nothing of miro_ball is imported here: what a tool built for Gazebo, Isaac Sim or O3DE
does, this client does, against `python -m miro_sim_bullet` as a process (started paused,
stepped by the client: simulated time only). The tests share the process, and each finds
it as it started (`sim`): any one runs alone, or in any order.
"""
import signal
import time

import pytest
import rclpy
from geometry_msgs.msg import PoseStamped, TwistStamped
from nav_msgs.msg import Odometry
from rclpy.action import ActionClient
from rclpy.executors import SingleThreadedExecutor
from rclpy.qos import QoSProfile
from simulation_interfaces import msg as si
from simulation_interfaces import srv
from simulation_interfaces.action import SimulateSteps

from program import Program

SIM = '/miro_sim'
DT = 0.002  # the simulator's physics step (s)
F = si.SimulatorFeatures
OK = si.Result.RESULT_OK


class Client:
    """An rclpy node that calls the standard services by name."""

    def __init__(self):
        self.context = rclpy.Context()
        rclpy.init(context=self.context)
        self.node = rclpy.create_node('standard_client', context=self.context)
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)
        self.clients = {}

    def call(self, kind, timeout_s=60.0, **fields):
        name = ''.join('_' + c.lower() if c.isupper() else c for c in kind.__name__)
        client = self.clients.get(kind)
        if client is None:
            client = self.clients[kind] = self.node.create_client(kind, f'{SIM}/{name[1:]}')
        assert client.wait_for_service(timeout_sec=timeout_s), f'no {name[1:]} service'
        future = client.call_async(kind.Request(**fields))
        self.executor.spin_until_future_complete(future, timeout_sec=timeout_s)
        assert future.done(), f'{name[1:]} did not answer'
        return future.result()

    def now(self):
        """Simulated time, as the ball's entity state is stamped."""
        stamp = self.call(srv.GetEntityState, entity='ball').state.header.stamp
        return stamp.sec + stamp.nanosec * 1e-9

    def close(self):
        self.node.destroy_node()
        rclpy.shutdown(context=self.context)


class Simulator:
    """The simulator as a process (its output read as it comes), started again when a test
    has ended it; one client for whichever is running."""

    def __init__(self):
        self.client, self.program = Client(), None

    def running(self):
        if self.program is None or self.program.proc.poll() is not None:
            # Named on the command line, as a launch file names it.
            self.program = Program('miro_sim_bullet', '--robot', 'miro', '--ros-args',
                                   '-r', '__node:=miro_sim', '-p', 'paused:=true', guard_s=60)
        return self.program

    def close(self):
        self.client.close()
        if self.program is not None and self.program.proc.poll() is None:
            self.program.proc.send_signal(signal.SIGINT)
            self.program.finish()


@pytest.fixture(scope='module')
def simulator():
    simulator = Simulator()
    try:
        yield simulator
    finally:
        simulator.close()


@pytest.fixture
def sim(simulator):
    """(the simulator's Program, the client), the world as it started whatever the test
    before did: paused, at time zero, nothing spawned, every entity where it began."""
    program, client = simulator.running(), simulator.client
    state = si.SimulationState  # already paused is fine
    client.call(srv.SetSimulationState, state=state(state=state.STATE_PAUSED))
    ok(client.call(srv.ResetSimulation, scope=srv.ResetSimulation.Request.SCOPE_ALL))
    return program, client


def ok(response):
    assert response.result.result == OK, response.result.error_message
    return response


def names(client, **filters):
    return list(ok(client.call(srv.GetEntities, filters=si.EntityFilters(**filters))).entities)


def test_features_name_everything_the_client_uses(sim):
    _, client = sim
    features = set(client.call(srv.GetSimulatorFeatures).features.features)
    for needed in (F.SPAWNING, F.DELETING, F.ENTITY_STATE_GETTING, F.ENTITY_STATE_SETTING,
                   F.SIMULATION_RESET_TIME, F.SIMULATION_RESET_STATE,
                   F.SIMULATION_RESET_SPAWNED, F.SIMULATION_STATE_PAUSE,
                   F.STEP_SIMULATION_MULTIPLE, F.STEP_SIMULATION_ACTION, F.WORLD_LOADING,
                   F.AVAILABLE_WORLDS, F.ENTITY_CATEGORIES, F.SPAWNING_ENTITIES):
        assert needed in features
    assert 'urdf' in client.call(srv.GetSimulatorFeatures).features.spawn_formats


def test_the_simulators_two_nodes_have_names_of_their_own(sim):
    _, client = sim  # the action's node kept its name under `-r __node:=miro_sim`
    deadline = time.monotonic() + 30
    while time.monotonic() < deadline:
        names = [f'{ns.rstrip("/")}/{name}'
                 for name, ns in client.node.get_node_names_and_namespaces()]
        if '/miro_sim_steps' in names:
            break
        client.executor.spin_once(timeout_sec=0.1)
    assert names.count('/miro_sim') == 1 and names.count('/miro_sim_steps') == 1, names


def test_pause_step_by_service_and_by_action(sim):
    _, client = sim
    state = si.SimulationState
    assert client.call(srv.GetSimulationState).state.state == state.STATE_PAUSED
    ok(client.call(srv.SetSimulationState, state=state(state=state.STATE_PLAYING)))
    refused = client.call(srv.StepSimulation, steps=5)
    assert refused.result.result == si.Result.RESULT_OPERATION_FAILED
    assert 'paused' in refused.result.error_message
    ok(client.call(srv.SetSimulationState, state=state(state=state.STATE_PAUSED)))
    again = client.call(srv.SetSimulationState, state=state(state=state.STATE_PAUSED))
    assert again.result.result == srv.SetSimulationState.Response.ALREADY_IN_TARGET_STATE
    before = client.now()
    ok(client.call(srv.StepSimulation, steps=50))
    assert client.now() - before == pytest.approx(50 * DT)

    # Feedback comes after every step, faster than a default queue of 10 keeps it.
    action = ActionClient(client.node, SimulateSteps, f'{SIM}/simulate_steps',
                          feedback_sub_qos_profile=QoSProfile(depth=1000))
    assert action.wait_for_server(timeout_sec=30)
    feedback = []
    before = client.now()
    sent = action.send_goal_async(SimulateSteps.Goal(steps=100),
                                  feedback_callback=lambda m: feedback.append(m.feedback))
    client.executor.spin_until_future_complete(sent, timeout_sec=30)
    # The result is asked for once every feedback is in: rclpy drops the feedback it takes
    # after the result (on a loaded machine that was all but the first few).
    deadline = time.monotonic() + 60  # a hang guard only
    while len(feedback) < 100 and time.monotonic() < deadline:
        client.executor.spin_once(timeout_sec=0.1)
    done = sent.result().get_result_async()
    client.executor.spin_until_future_complete(done, timeout_sec=60)
    assert done.result().result.result.result == OK
    # One after every step, in order, consistent.
    assert [f.completed_steps for f in feedback] == list(range(1, 101))
    assert all(f.completed_steps + f.remaining_steps == 100 for f in feedback)
    assert client.now() - before == pytest.approx(100 * DT)


def test_every_entity_has_a_state_and_a_category(sim):
    _, client = sim
    got = ok(client.call(srv.GetEntitiesStates, filters=si.EntityFilters()))
    assert {'miro', 'ball'} <= set(got.entities)
    assert len(got.states) == len(got.entities)
    ball = got.states[list(got.entities).index('ball')]
    assert ball.header.frame_id == 'world' and ball.pose.position.z > 0.05
    robots = names(client, categories=[si.EntityCategory(
        category=si.EntityCategory.CATEGORY_ROBOT)])
    assert robots == ['miro']
    statics = names(client, categories=[si.EntityCategory(
        category=si.EntityCategory.CATEGORY_STATIC_OBJECT)])
    assert statics and 'ball' not in statics
    assert names(client, filter='^bal') == ['ball']


def test_a_spawned_miro_drives_on_its_own_topics(sim):
    _, client = sim
    where = PoseStamped()  # header.frame_id '': the world frame; heading along x
    where.pose.position.x, where.pose.position.y = -0.6, 0.6
    request = {'name': 'miro_b', 'uri': 'package://miro_ball/robots/miro.urdf'}
    spawned = ok(client.call(srv.SpawnEntity, **request, initial_pose=where))
    assert spawned.entity_name == 'miro_b'
    twice = client.call(srv.SpawnEntity, **request)
    assert twice.result.result == srv.SpawnEntity.Response.NAME_NOT_UNIQUE
    odom = []
    heard = client.node.create_subscription(Odometry, '/miro_b/sensors/odom', odom.append, 10)
    drive = client.node.create_publisher(TwistStamped, '/miro_b/control/cmd_vel', 10)
    command = TwistStamped()
    command.twist.linear.x = 0.2
    try:
        for _ in range(100):  # 10 s of simulated time at most, 0.1 s at a time
            drive.publish(command)
            ok(client.call(srv.StepSimulation, steps=50))
            client.executor.spin_once(timeout_sec=0.01)
            if odom and odom[-1].pose.pose.position.x > -0.5:
                break
    finally:
        client.node.destroy_subscription(heard)
        client.node.destroy_publisher(drive)
    assert odom and odom[-1].pose.pose.position.x > -0.5  # moved 10 cm forwards


def test_a_box_is_spawned_and_deleted_and_the_ball_moved(sim):
    _, client = sim
    beside = PoseStamped()  # not where MiRo stands: a body is not spawned inside another
    beside.pose.position.x = beside.pose.position.y = 0.5
    ok(client.call(srv.SpawnEntity, name='crate', initial_pose=beside,
                   uri='package://miro_ball/worlds/models/box.toml'))
    assert 'crate' in names(client)
    ok(client.call(srv.DeleteEntity, entity='crate'))
    assert 'crate' not in names(client)
    missing = client.call(srv.DeleteEntity, entity='crate')
    assert missing.result.result == si.Result.RESULT_NOT_FOUND
    state = si.EntityState()
    state.pose.position.x, state.pose.position.y, state.pose.position.z = 0.9, -0.4, 0.1
    ok(client.call(srv.SetEntityState, entity='ball', state=state))
    at = client.call(srv.GetEntityState, entity='ball').state.pose.position
    assert (at.x, at.y) == pytest.approx((0.9, -0.4), abs=1e-6)


def test_each_reset_scope(sim):
    """It spawns and moves what it resets (it once relied on an earlier test's miro_b)."""
    _, client = sim
    reset = srv.ResetSimulation.Request
    home = client.call(srv.GetEntityState, entity='ball').state.pose.position
    beside = PoseStamped()
    beside.pose.position.x = beside.pose.position.y = 0.5
    ok(client.call(srv.SpawnEntity, name='crate', initial_pose=beside,
                   uri='package://miro_ball/worlds/models/box.toml'))
    moved = si.EntityState()
    moved.pose.position.x, moved.pose.position.y, moved.pose.position.z = 0.9, -0.4, 0.1
    ok(client.call(srv.SetEntityState, entity='ball', state=moved))
    ok(client.call(srv.StepSimulation, steps=10))
    ok(client.call(srv.ResetSimulation, scope=reset.SCOPE_TIME))
    assert client.now() == 0.0
    still = client.call(srv.GetEntityState, entity='ball').state.pose.position
    assert (still.x, still.y) == pytest.approx((0.9, -0.4), abs=1e-3)  # nothing moved back

    ok(client.call(srv.StepSimulation, steps=10))
    ok(client.call(srv.ResetSimulation, scope=reset.SCOPE_STATE))
    assert client.now() == pytest.approx(10 * DT)  # time goes on
    start = client.call(srv.GetEntityState, entity='ball').state.pose.position
    assert (start.x, start.y) == pytest.approx((home.x, home.y), abs=1e-3)  # back home
    assert 'crate' in names(client)  # spawned entities stay

    ok(client.call(srv.ResetSimulation, scope=reset.SCOPE_SPAWNED))
    assert 'crate' not in names(client) and 'miro' in names(client)

    ok(client.call(srv.ResetSimulation, scope=reset.SCOPE_ALL))
    assert client.now() == 0.0


def test_worlds_are_listed_and_loaded_and_quitting_ends_the_simulator(sim):
    program, client = sim  # the next test that needs it starts another
    worlds = ok(client.call(srv.GetAvailableWorlds)).worlds
    assert {'miro', 'football_pitch', 'den'} <= {w.name for w in worlds}
    pitch = next(w for w in worlds if w.name == 'football_pitch')
    loaded = ok(client.call(srv.LoadWorld, uri=pitch.world_resource.uri))
    assert loaded.world.name == 'football_pitch'
    assert ok(client.call(srv.GetCurrentWorld)).world.name == 'football_pitch'
    assert {'miro01', 'miro02', 'miro03', 'ball'} <= set(names(client))
    bad = client.call(srv.LoadWorld, resource_string='[robot]\npose = "here"\n')
    assert bad.result.result == srv.LoadWorld.Response.RESOURCE_PARSE_ERROR
    assert ok(client.call(srv.GetCurrentWorld)).world.name == 'football_pitch'
    state = si.SimulationState
    ok(client.call(srv.SetSimulationState, state=state(state=state.STATE_QUITTING)))
    code, log = program.finish()
    assert code == 0, log
    assert 'Traceback' not in log and 'FATAL' not in log and 'quitting, as asked' in log
