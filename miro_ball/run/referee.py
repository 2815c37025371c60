"""The referee of a run: a node on the run's ROS domain that watches it (Monitor) and
starts the simulator's clock (the standard simulation_interfaces' set_simulation_state)
only once everyone who must see the run from its first instant is there.

The simulator of a run starts paused. Free-running, it was seconds into the run
before a slow controller or the observer had matched its topics: the observer
reported 0.0 s simulated while the robots were already at the ball.
"""
import time
from contextlib import contextmanager

from miro_ball.common.messages import has_standard
from miro_ball.controller.names import NODE_NAME as CONTROLLER
from miro_ball.miro.interface import EYES, RobotTopics, SimTopics
from miro_ball.run.monitor import Monitor, unmatched

SERVICE_TIMEOUT_S = 10.0


class RunError(RuntimeError):
    """A run that can not go on (the simulator did not answer or took no placement, a node
    exited before the start); the message says why, in one line."""


@contextmanager
def ros_domain(domain):
    """An initialised rclpy Context on ROS domain ``domain``, shut down at the end."""
    import rclpy
    from rclpy.context import Context

    context = Context()
    rclpy.init(context=context, domain_id=domain)
    try:
        yield context
    finally:
        rclpy.try_shutdown(context=context)


class Referee:
    """A node ``name`` on ``context`` (its own executor unless one is given) watching the
    robots named. video: a Video to write (overhead view and the controllers' eyes);
    video_note: what its caption says until the ball is kicked."""

    def __init__(self, context, robots, name, executor=None, video=None, video_note='',
                 debug_frames=False):
        import rclpy
        from rclpy.executors import SingleThreadedExecutor
        from rclpy.parameter import Parameter

        self.node = rclpy.create_node(name, context=context, parameter_overrides=[
            Parameter('use_sim_time', value=True)])
        self.own_executor = executor is None
        self.executor = executor or SingleThreadedExecutor(context=context)
        self.executor.add_node(self.node)
        self.video, self.video_note = video, video_note
        self.monitor = Monitor(self.node, robots, on_eye=video.eye if video else None,
                               on_overhead=self._on_overhead if video else None,
                               debug_frames=debug_frames or video is not None)
        self._set_state = None  # made when first asked for (an in-process rig needs none)
        self.start_time = None  # simulated s when the clock was started

    @property
    def judge(self):
        """The run's judge (run/judge.py), judging from the clock's start."""
        return self.monitor.judge

    @property
    def elapsed(self):
        """Simulated seconds since the clock was started."""
        return self.judge.elapsed

    def _on_overhead(self, bgr, stamp):
        note = 'KICKED' if self.judge.kicked else self.video_note
        self.video.overhead(bgr, stamp - (self.start_time or 0.0), note)

    def spin_once(self, timeout_s):
        self.executor.spin_once(timeout_sec=timeout_s)

    def spin_until(self, predicate, timeout_s):
        """Spin until predicate() holds (True) or timeout_s of wall time pass (False)."""
        deadline = time.monotonic() + timeout_s
        while not predicate():
            if time.monotonic() > deadline:
                return False
            self.executor.spin_once(timeout_sec=0.02)
        return True

    def _state_client(self):
        """The simulator's set_simulation_state; in an install built without
        simulation_interfaces (no compiler), its older ~/pause alias, which std_srvs has."""
        if self._set_state is None:
            if has_standard():
                from simulation_interfaces.srv import SetSimulationState
                self._set_state = self.node.create_client(
                    SetSimulationState, SimTopics().standard(SetSimulationState))
            else:
                from std_srvs.srv import SetBool
                self._set_state = self.node.create_client(SetBool, SimTopics().pause)
        return self._set_state

    def play(self):
        """The simulator playing (or so already), or RunError saying why not."""
        client = self._state_client()
        if client.srv_type.__name__ == 'SetBool':
            request = client.srv_type.Request(data=False)
        else:
            from simulation_interfaces.msg import SimulationState
            request = client.srv_type.Request(
                state=SimulationState(state=SimulationState.STATE_PLAYING))
        future = client.call_async(request)
        if not self.spin_until(future.done, SERVICE_TIMEOUT_S):
            raise RunError(f'the simulator did not answer {client.srv_name}')
        answer = future.result()
        if hasattr(answer, 'success'):
            refused = None if answer.success else answer.message
        else:
            from simulation_interfaces.msg import Result
            from simulation_interfaces.srv import SetSimulationState
            played = (Result.RESULT_OK, SetSimulationState.Response.ALREADY_IN_TARGET_STATE)
            refused = None if answer.result.result in played else answer.result.error_message
        if refused is not None:
            raise RunError(f'the simulator refused {client.srv_name}: {refused}')

    # -- before the run --------------------------------------------------------------------------
    def simulator_ready(self):
        """Its state service answers and its ground truth reaches us."""
        return self._state_client().service_is_ready() and not unmatched(self.monitor.truth)

    def waiting_for(self, controllers=(), recorder=None):
        """What the run still waits for before its clock may start, in words ([]: nothing):
        the simulator; this node's own subscriptions (the controllers' annotated frames and
        the overhead view among them); each robot's controller, /<robot>/kick_blue_ball,
        commanding and watching its eyes; the node ``recorder`` subscribed to the robots'
        commands."""
        missing = [] if self.simulator_ready() else ['the simulator']
        missing += unmatched(self.monitor.debug + [s for s in [self.monitor.overhead] if s])
        for robot in controllers:
            topics = RobotTopics(robot)
            for topic, publishes in [(topics.cmd_vel, True)] + [
                    (topics.eye_compressed(eye), False) for eye in EYES]:
                if not self._serves(CONTROLLER, f'/{robot}', topic, publishes):
                    missing.append(f'/{robot}/{CONTROLLER} on {topic}')
            if recorder and not self._serves(recorder, '/', topics.cmd_vel, False):
                missing.append(f'/{recorder} on {topics.cmd_vel}')
        return missing

    def _serves(self, name, namespace, topic, publishes):
        """Whether node namespace/name publishes (or subscribes to) topic, in our graph."""
        ends = (self.node.get_publishers_info_by_topic(topic) if publishes
                else self.node.get_subscriptions_info_by_topic(topic))
        return any(end.node_name == name and end.node_namespace == namespace for end in ends)

    def start_clock(self):
        """The run starts now: judged from here (Monitor.restart), the simulator resumed."""
        self.monitor.restart()
        self.start_time = self.monitor.sim_time
        self.play()

    def close(self):
        if self.own_executor:
            self.executor.shutdown(timeout_sec=1.0)
        else:
            self.executor.remove_node(self.node)
        self.node.destroy_node()
