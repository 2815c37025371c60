"""The standard's simulate_steps action (/miro_sim/simulate_steps), served beside the node.

rclpy's EventsExecutor, which the simulator spins on, takes no action server in Jazzy (a
goal sent to one is never answered: tried). So the action lives on a small node of its own,
/miro_sim_steps, spun by an executor of its own in a thread; it only hands goals over.
The simulator's own thread does the stepping, as it does for every other request: each
turn of its timer takes the goal in hand, steps it (up to MAX_STEPS_A_TURN), sends
feedback after every step, and ends it when done (a turn later), cancelled, or the
simulator is no longer paused. A goal cancelled while it waits behind others ends at the
next turn, not when those ahead of it have ended.
"""
import collections
import threading

from rclpy.action import ActionServer, CancelResponse, GoalResponse
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.executors import ExternalShutdownException, MultiThreadedExecutor, ShutdownException
from rclpy.node import Node
from rclpy.qos import QoSProfile
from simulation_interfaces.action import SimulateSteps

from miro_ball.common.throttle import Throttled
from miro_ball.miro.interface import SIM_ACTION_NODE_NAME, SimTopics
from miro_sim_bullet.control.codes import Result
from miro_sim_bullet.ros.sim_interface import SERVICE_QOS

MAX_STEPS_A_TURN = 500  # steps of a goal per turn of the simulator's timer: it stays lively
CLOSE_WAIT_S = 5.0  # wall seconds close() waits for the action's thread (a guard)
MAX_GOALS = 16  # goals accepted and not ended; more are rejected
# Each goal accepted holds a thread until it ends: with 2 threads, two goals left none to
# answer a third, or a cancel (a goal of 2**64-1 steps could then never be stopped).
THREADS = MAX_GOALS + 2


class Goal:
    """One goal in the simulator's hands: steps left, and the event its server waits on."""

    def __init__(self, handle):
        self.handle = handle
        self.left = handle.request.steps
        self.result = SimulateSteps.Result()
        self.done = threading.Event()

    def end(self, code=Result.OK, message=''):
        self.result.result.result, self.result.result.error_message = code, message
        self.done.set()


class StepAction:
    """The action server for the simulator ``host``: host.step(n) -> (done, message) steps
    n physics steps while paused. Call serve() from the simulator's thread, often."""

    def __init__(self, host, context):
        self.host = host
        # Not the command line's remaps: `-r __node:=miro_sim` (what a launch file's node
        # name becomes) would name this node miro_sim too.
        self.node = Node(SIM_ACTION_NODE_NAME, context=context, use_global_arguments=False,
                         start_parameter_services=False)
        self.waiting = collections.deque()
        self.held = 0  # goals accepted and not ended, each on a thread of the executor
        self.closed = False  # close() has begun: no goal is taken any more
        self.lock = threading.Lock()
        self.fault = Throttled(self.node.get_logger().error)
        self.server = ActionServer(
            self.node, SimulateSteps, SimTopics().topic('simulate_steps'),
            execute_callback=self._execute, goal_callback=self._accept,
            cancel_callback=lambda goal: CancelResponse.ACCEPT,
            callback_group=ReentrantCallbackGroup(),
            # ROS's default queue of 10 requests lost the goals of a burst beyond ten,
            # neither accepted nor rejected: the depth of the simulator's other services.
            goal_service_qos_profile=SERVICE_QOS, result_service_qos_profile=SERVICE_QOS,
            cancel_service_qos_profile=SERVICE_QOS,
            # Feedback after every step comes in bursts: a deep queue keeps each one for
            # a client whose queue is deep too.
            feedback_pub_qos_profile=QoSProfile(depth=MAX_STEPS_A_TURN))
        self.executor = MultiThreadedExecutor(num_threads=THREADS, context=context)
        self.executor.add_node(self.node)
        self.thread = threading.Thread(target=self._spin, name=SIM_ACTION_NODE_NAME,
                                       daemon=True)
        self.thread.start()

    def _spin(self):
        # The executor raises a callback's error here, in its spinning thread: caught for
        # good, one bug would end the action while the simulator runs on without it.
        while True:
            try:
                self.executor.spin()  # returns when the executor or its context shuts down
                return
            except (ExternalShutdownException, ShutdownException):
                return
            except Exception as err:
                if self.closed or not self.executor.context.ok():
                    return  # the simulator is ending: what failed was its shutdown
                self.fault('callback', f'simulate_steps: a callback failed, serving on: '
                                       f'{type(err).__name__}: {err}')

    def _accept(self, request):
        with self.lock:
            if self.closed or self.held >= MAX_GOALS:
                return GoalResponse.REJECT
            self.held += 1
            return GoalResponse.ACCEPT

    def _execute(self, handle):
        try:
            goal = Goal(handle)
            with self.lock:
                if self.closed:  # accepted as close() ended the others: nobody steps it
                    goal.end(Result.OPERATION_FAILED, 'the simulator stopped')
                else:
                    self.waiting.append(goal)
            goal.done.wait()
        finally:  # its place is free again, whatever went wrong
            with self.lock:
                self.held -= 1
        if handle.is_cancel_requested:
            handle.canceled()
        elif goal.result.result.result == Result.OK:
            handle.succeed()
        else:
            handle.abort()
        return goal.result

    def serve(self):
        """In the simulator's thread: step the goal in hand (some of it), feedback after
        each step; True while a goal is in hand. Goals cancelled while they wait end now."""
        with self.lock:
            cancelled = [g for g in self.waiting if g.handle.is_cancel_requested]
            for goal in cancelled:
                self.waiting.remove(goal)
            goal = self.waiting[0] if self.waiting else None
        for ended in cancelled:
            ended.end(Result.OK, f'cancelled with {ended.left} steps left')
        if goal is None:
            return bool(cancelled)
        handle = goal.handle
        if goal.left == 0:  # stepped last turn: the feedback has had its head start
            self._finish(goal, Result.OK)
            return True
        for _ in range(min(goal.left, MAX_STEPS_A_TURN)):
            if handle.is_cancel_requested:
                break
            done, message = self.host.step(1)
            if not done:
                self._finish(goal, Result.OPERATION_FAILED, message)
                return True
            goal.left -= 1
            handle.publish_feedback(SimulateSteps.Feedback(
                completed_steps=handle.request.steps - goal.left, remaining_steps=goal.left))
        if handle.is_cancel_requested:
            self._finish(goal, Result.OK, f'cancelled with {goal.left} steps left')
        # Done, the goal ends at the next turn, not now: a client drops the feedback that
        # comes after the result, and the result would overtake the last feedback.
        return True

    def _finish(self, goal, code, message=''):
        with self.lock:
            self.waiting.popleft()
        goal.end(code, message)

    def close(self):
        with self.lock:
            self.closed = True
            while self.waiting:
                self.waiting.popleft().end(Result.OPERATION_FAILED, 'the simulator stopped')
        # The goals' callbacks return at once now; on a busy machine that took over a
        # second, and a server left behind stayed on the graph.
        self.executor.shutdown(timeout_sec=CLOSE_WAIT_S)
        self.thread.join(timeout=CLOSE_WAIT_S)
        # The server holds its node: destroyed first, or the node stays on the graph.
        self.server.destroy()
        self.node.destroy_node()
