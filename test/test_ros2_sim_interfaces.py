"""python -m miro_ball.ros2 against simulation_interfaces servers of the test's own: the
action verbs on a simulate_steps server whose every step waits for the test to release it
(no clock at all), and service calls with nested messages and lists of them."""
import os
import queue
import signal
import subprocess
import sys
import threading

import pytest
import rclpy
from rclpy.action import ActionServer, CancelResponse
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.executors import MultiThreadedExecutor
from simulation_interfaces.action import SimulateSteps
from simulation_interfaces.msg import Result
from simulation_interfaces.srv import GetEntities, SetSimulationState, SpawnEntities

from miro_ball.common.isolation import isolated_env
from rostools import kill_if_running

NODE = 'sim_under_test'
ACTION = f'/{NODE}/simulate_steps'
TYPE = 'simulation_interfaces/action/SimulateSteps'
HANG_S = 30.0  # wall seconds that only guard against a hang
BURST = 200  # steps whose feedback is sent at once


def command(*args):
    return [sys.executable, '-m', 'miro_ball.ros2', *args]


def run_all(*commands):
    """[(exit code, stdout, stderr)] of commands run side by side (each a second of start)."""
    env = isolated_env(int(os.environ['ROS_DOMAIN_ID']))
    procs = [subprocess.Popen(c, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                              text=True) for c in commands]
    try:
        outputs = [p.communicate(timeout=HANG_S) for p in procs]
        return [(p.returncode, *output) for p, output in zip(procs, outputs)]
    finally:
        for proc in procs:
            kill_if_running(proc)


class Lines:
    """A child process's stdout read line by line as it comes (a thread), for waiting on."""

    def __init__(self, proc):
        self.proc, self.seen, self._new = proc, [], queue.Queue()
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self):
        for line in self.proc.stdout:
            self._new.put(line.rstrip('\n'))
        self._new.put(None)

    def wait_for(self, text):
        """Every line up to the one that holds text; the process ending first fails."""
        while not any(text in line for line in self.seen):
            line = self._new.get(timeout=HANG_S)
            assert line is not None, f'ended before printing {text!r}: {self.seen}'
            self.seen.append(line)
        return self.seen

    def rest(self):
        while (line := self._new.get(timeout=HANG_S)) is not None:
            self.seen.append(line)
        return self.seen


class SimUnderTest:
    """simulate_steps and three services of simulation_interfaces on a node of the test's
    domain, spun by an executor thread of its own. A step waits until release() lets it
    go, then counts and sends its feedback; the result follows the last step at once, as
    the simulator's does. A service records the request it got."""

    def __init__(self, context):
        self.node = rclpy.create_node(NODE, context=context)
        self.steps_done, self.requests = 0, []
        self._go, self._closing = threading.Semaphore(0), False
        group = ReentrantCallbackGroup()  # a step waits while a cancel request is answered
        self.server = ActionServer(self.node, SimulateSteps, '~/simulate_steps',
                                   execute_callback=self._execute, callback_group=group,
                                   cancel_callback=lambda goal: CancelResponse.ACCEPT)
        for srv, name in ((SetSimulationState, 'set_simulation_state'),
                          (GetEntities, 'get_entities'), (SpawnEntities, 'spawn_entities')):
            self.node.create_service(srv, f'~/{name}', self._record)
        self.executor = MultiThreadedExecutor(num_threads=3, context=context)
        self.executor.add_node(self.node)
        self.thread = threading.Thread(target=self.executor.spin, daemon=True)
        self.thread.start()

    def release(self, steps=1):
        for _ in range(steps):
            self._go.release()

    def _execute(self, goal):
        total = goal.request.steps
        for done in range(1, total + 1):
            self._go.acquire()
            if self._closing:
                break
            if goal.is_cancel_requested:
                goal.canceled()
                return SimulateSteps.Result(result=Result(result=Result.RESULT_OK,
                                                          error_message='canceled'))
            self.steps_done += 1
            goal.publish_feedback(SimulateSteps.Feedback(completed_steps=done,
                                                         remaining_steps=total - done))
        goal.succeed()
        return SimulateSteps.Result(result=Result(result=Result.RESULT_OK))

    def _record(self, request, response):
        self.requests.append(request)
        response.result.result = Result.RESULT_OK
        return response

    def close(self):
        self._closing = True
        self.release(1000)
        self.executor.shutdown(timeout_sec=2.0)
        self.thread.join(timeout=2.0)
        self.server.destroy()
        self.node.destroy_node()


@pytest.fixture
def sim(ros_context):
    sim = SimUnderTest(ros_context)
    yield sim
    sim.close()


def started(*args):
    proc = subprocess.Popen(command(*args), env=isolated_env(int(os.environ['ROS_DOMAIN_ID'])),
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    return proc, Lines(proc)


def test_send_goal_prints_every_feedback_the_result_and_succeeded(sim):
    """Every feedback, though they come in a burst (the simulator sends hundreds at once)
    and the result overtakes some (rclpy's client drops those: 784 of 1000 were printed)."""
    proc, lines = started('action', 'send_goal', ACTION, TYPE, f'{{steps: {BURST}}}', '-f')
    try:
        lines.wait_for('Goal accepted with ID: ')
        sim.release(BURST)  # the result comes right after the last feedback, or before it
        out = lines.rest()
        assert proc.wait(timeout=HANG_S) == 0 and proc.stderr.read() == ''
    finally:
        kill_if_running(proc)
    assert out[:5] == ['Waiting for an action server to become available...', 'Sending goal:',
                       f'     steps: {BURST}', '', out[4]]
    assert len(out[4].split('Goal accepted with ID: ')[1]) == 32  # the goal's UUID in hex
    # ros2's own layout: a message's first line under its title, indented, the rest not
    assert out[6:] == [*[line for k in range(1, BURST + 1) for line in (
        'Feedback:', f'    completed_steps: {k}', f'remaining_steps: {BURST - k}', '')],
        'Result:', '    result:', '  result: 1', "  error_message: ''", '',
        'Goal finished with status: SUCCEEDED']
    assert sim.steps_done == BURST


def test_ctrl_c_cancels_the_running_goal_and_exits_quietly(sim):
    proc, lines = started('action', 'send_goal', ACTION, TYPE, '{steps: 100}', '--feedback')
    try:
        lines.wait_for('Goal accepted with ID: ')
        sim.release(2)
        lines.wait_for('remaining_steps: 98')
        proc.send_signal(signal.SIGINT)
        assert lines.wait_for('Goal canceled.')[-2] == 'Canceling goal...'
        sim.release()  # the server sees the cancel at its next step
        out = lines.rest()
        code, err = proc.wait(timeout=HANG_S), proc.stderr.read()
    finally:
        kill_if_running(proc)
    assert code == 0 and err == '', (out, err)
    assert out[-1] == 'Goal finished with status: CANCELED'
    assert '  error_message: canceled' in out
    assert sim.steps_done == 2


def test_the_action_is_listed_with_its_server_and_its_topics_are_hidden(sim):
    (code, listed, _), (_, info, _), (_, node, _), (_, topics, _) = run_all(
        command('action', 'list', '-t'), command('action', 'info', ACTION, '-t'),
        command('node', 'info', f'/{NODE}'), command('topic', 'list'))
    assert code == 0 and f'{ACTION} [{TYPE}]' in listed.splitlines()
    assert info.splitlines() == [f'Action: {ACTION}', 'Action clients: 0', 'Action servers: 1',
                                 f'    /{NODE} [{TYPE}]']
    assert f'  Action Servers:\n    {ACTION}: {TYPE}\n' in node and '_action' not in node
    assert '_action' not in topics


def test_interface_list_and_show_cover_actions():
    (code, listed, _), (_, shown, _) = run_all(command('interface', 'list', '-a'),
                                               command('interface', 'show', TYPE))
    assert code == 0 and listed.splitlines()[0] == 'Actions:'
    assert f'    {TYPE}' in listed.splitlines()
    assert shown.split('\n---\n')[0] == 'uint64 steps' and '\tstring error_message' in shown
    assert shown.rstrip().endswith('uint64 completed_steps\nuint64 remaining_steps')


def test_service_calls_fill_nested_messages_and_lists_of_them(sim):
    answers = run_all(
        command('service', 'call', f'/{NODE}/set_simulation_state',
                'simulation_interfaces/srv/SetSimulationState', '{state: {state: 2}}'),
        command('service', 'call', f'/{NODE}/get_entities',
                'simulation_interfaces/srv/GetEntities',
                '{filters: {filter: "miro.*", categories: [{category: 1}, {category: 4}]}}'),
        command('service', 'call', f'/{NODE}/spawn_entities',
                'simulation_interfaces/srv/SpawnEntities', '{spawn_requests: [{name: box2, '
                'initial_pose: {pose: {position: {x: 1.0}}}}, {name: miro2}]}'))
    assert all(code == 0 and 'response:' in out for code, out, _ in answers)
    got = {type(r).__name__: r for r in sim.requests}
    assert got['SetSimulationState_Request'].state.state == 2
    filters = got['GetEntities_Request'].filters
    assert filters.filter == 'miro.*' and [c.category for c in filters.categories] == [1, 4]
    spawned = got['SpawnEntities_Request'].spawn_requests
    assert [s.name for s in spawned] == ['box2', 'miro2']
    assert spawned[0].initial_pose.pose.position.x == 1.0


def test_bad_input_is_one_line_and_exit_1_a_bad_option_exit_2():
    cases = [
        (('action', 'send_goal', ACTION, 'simulation_interfaces/action/Nope', '{}'),
         'no interface simulation_interfaces/action/Nope'),
        (('action', 'send_goal', ACTION, 'std_srvs/srv/Trigger', '{}'), 'is not an action type'),
        (('action', 'send_goal', ACTION, TYPE, '{steps: ['), 'not valid YAML'),
        (('action', 'send_goal', ACTION, TYPE, '{stepz: 3}'), "no field 'stepz'"),
        (('action', 'send_goal', ACTION, TYPE, '{steps: -1}'), 'give an integer from 0'),
        (('action', 'send_goal', '/no/such/action', TYPE, '{steps: 1}'),
         'no action server /no/such/action'),
        (('service', 'call', '/x', 'simulation_interfaces/srv/SpawnEntities',
          '{spawn_requests: [3]}'), 'spawn_requests[0] is a SpawnEntity: give a mapping'),
    ]
    answers = run_all(*[command(*args) for args, _ in cases],
                      command('action', 'send_goal', ACTION))
    for (args, says), (code, _, err) in zip(cases, answers):
        assert code == 1 and says in err and len(err.strip().splitlines()) == 1, (args, err)
    assert answers[-1][0] == 2 and 'Traceback' not in answers[-1][2]
