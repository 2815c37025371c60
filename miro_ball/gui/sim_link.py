"""The GUI's link to the simulator: its services (reset, step, pause, a drag's move: the
standard simulation_interfaces; its real-time factor), its inputs (the touch pads, sounds)
and its clock (the time and speed the pages show).

Only the simulator's own services and inputs are used; a simulator that is not there is
said so in the status line, never waited for: every call is answered in a callback.
"""
import time

from geometry_msgs.msg import Accel, Twist
from rcl_interfaces.msg import Parameter, ParameterType, ParameterValue
from rcl_interfaces.srv import GetParameters, SetParameters
from rosgraph_msgs.msg import Clock
from std_msgs.msg import String, UInt16

from miro_ball.common.clock_watch import clock_publishers, ClockWatch, shared_domain_line
from miro_ball.common.messages import NO_STANDARD
from miro_ball.common.qos import profile
from miro_ball.common.stamps import seconds
from miro_ball.common.throttle import Throttled
from miro_ball.miro.interface import CLOCK, CONTROL_QOS, SimTopics

try:  # built at set-up; without it the pages still see and drive, and say what is missing
    from simulation_interfaces.msg import Result, SimulationState
    from simulation_interfaces.srv import (GetEntityState, GetSimulationState, ResetSimulation,
                                           SetEntityState, SetSimulationState, StepSimulation)
    STANDARD = (GetSimulationState, SetSimulationState, StepSimulation, ResetSimulation,
                GetEntityState, SetEntityState)
except ModuleNotFoundError as missing:
    if not (missing.name or '').startswith('simulation_interfaces'):
        raise
    STANDARD = ()  # every use asks _ready() first, which says what is missing
    GetEntityState = GetSimulationState = ResetSimulation = SetEntityState = None
    SetSimulationState = StepSimulation = None

RTF_PARAMETER = 'real_time_factor'
PAUSED_PARAMETER = 'paused'
STEP_COUNT_PARAMETER = 'step_count'  # physics steps the simulator's own step button takes
GUI_SOUND_DB = -30.0  # a sound placed from the page: its RMS 1 m away, dB of full scale
RTF_WINDOW_S = 2.0  # the real-time factor shown is measured over this much wall time


class SimLink:
    """See the module docstring. node: the bridge's node; report(text): the status line;
    warn(key, text): a rate-limited warning."""

    def __init__(self, node, report, warn):
        self.node = node
        self.report = report
        # What pages ask of the simulator, for the log: 200 pages' resets are a few lines.
        self.said = Throttled(node.get_logger().info)
        self.warn = warn
        self.topics = SimTopics()
        self.time = None
        self.paused = None  # known only when paused or resumed from here
        self.started_paused = None  # the paused parameter, read with the real-time factor
        self.rtf_set = None  # the simulator's real_time_factor as last set or read
        self.step_count = None  # the simulator's step_count, read with the real-time factor
        self._rtf_asked = False
        self._after_read = []  # what waits for the parameters being read
        self._clock_samples = []  # (wall, sim) of the last RTF_WINDOW_S of /clock
        self._clock_watch = ClockWatch(node)
        self._pubs = {}
        self._sounds = 0  # placed from the pages so far (their names' numbers)
        node.create_subscription(Clock, CLOCK, self._on_clock, 10)
        self.clients = {kind: node.create_client(kind, self.topics.standard(kind))
                        for kind in STANDARD}
        self.clients.update({
            'set_parameters': node.create_client(SetParameters,
                                                 self.topics.topic('set_parameters')),
            'get_parameters': node.create_client(GetParameters,
                                                 self.topics.topic('get_parameters'))})

    def state(self):
        """What the pages show of the simulator; and the status line if two simulators'
        clocks are seen (else None)."""
        # Two simulators' clocks side by side make a speed of nonsense: none is shown.
        contested = self._clock_watch.contested
        rtf = None if contested else self._rtf()
        # Known when paused from here; else guessed from time standing still, or read from
        # the simulator's parameter while its clock has not yet run.
        if self.paused is not None:
            paused = self.paused
        elif self.time is not None:
            paused = rtf == 0.0
        else:
            paused = bool(self.started_paused)
        present = self.clients[STANDARD[0] if STANDARD else 'get_parameters']
        sim = {'present': present.service_is_ready(), 'time': self.time, 'rtf': rtf,
               'paused': paused}
        status = (shared_domain_line(clock_publishers(self.node),
                                     self.node.context.get_domain_id())
                  if contested else None)
        return sim, status

    # -- inputs ---------------------------------------------------------------------------------
    def place(self, name, x, y):
        """Move an object (or a robot) to x, y, at rest: its state is asked for first, so
        that its height (a robot's floor) and orientation stay its own."""
        if not self._ready('place', GetEntityState, SetEntityState):
            return

        def got(response):
            state = response.state
            state.pose.position.x, state.pose.position.y = x, y
            state.twist, state.acceleration = Twist(), Accel()  # dropped where it is put
            self._call('place', SetEntityState,
                       SetEntityState.Request(entity=name, state=state), lambda _: None)
        self._call('place', GetEntityState, GetEntityState.Request(entity=name), got)

    def play_sound(self, kind, x, y):
        """A sound of ``kind`` (protocol.SOUND_KINDS) on the floor at x, y, named by the
        GUI ('gui_sound<N>'), as a world file's [[sound]] says it."""
        self._sounds += 1
        what = 'tone = 440' if kind == 'tone' else 'noise = true'
        text = (f'[[sound]]\nname = "gui_sound{self._sounds}"\n'
                f'position = [{x:.3f}, {y:.3f}, 0.1]\n{what}\nlevel = {GUI_SOUND_DB}\n')
        self._publisher(String, self.topics.sound).publish(String(data=text))

    def stop_sound(self, name):
        self._publisher(String, self.topics.sound_off).publish(String(data=name))

    def touch(self, robot, part, pads):
        self._publisher(UInt16, self.topics.touch(robot, part)).publish(UInt16(data=pads))

    def _publisher(self, msg_type, topic):
        if topic not in self._pubs:
            self._pubs[topic] = self.node.create_publisher(msg_type, topic,
                                                           profile(CONTROL_QOS))
        return self._pubs[topic]

    # -- services -------------------------------------------------------------------------------
    def call(self, action):
        """pause, resume, step or reset; the answer goes to the status line."""
        if not self._ready(action):  # this install has the standard
            return
        if action == 'step' and self.step_count is None:
            # How far the simulator's step goes is its own parameter: asked for first.
            if self._ready(action, StepSimulation, 'get_parameters'):
                self._read_parameters(lambda: self.call(action) if self.step_count is not None
                                      else self.report('step: the simulator did not say its '
                                                       'step_count'))
            return
        if action == 'reset':
            kind, fields = ResetSimulation, {'scope': ResetSimulation.Request.SCOPE_DEFAULT}
        elif action == 'step':
            kind, fields = StepSimulation, {'steps': self.step_count}
        else:
            kind, fields = SetSimulationState, {'state': SimulationState(
                state=SimulationState.STATE_PAUSED if action == 'pause'
                else SimulationState.STATE_PLAYING)}
        if not self._ready(action, kind):
            return

        def done(response):
            if kind is SetSimulationState:
                self.paused = action == 'pause'
            said = f'{fields["steps"]} physics steps' if action == 'step' else 'done'
            self.report(f'{action}: {said}')
            self.said(action, f'simulator {action}: {said}')
        self._call(action, kind, kind.Request(**fields), done)

    def _ready(self, what, *kinds):
        """Whether this install has the standard and the simulator serves each of ``kinds``;
        if not, the status line says why."""
        if not STANDARD:
            self.report(f'{what}: {NO_STANDARD}')
            return False
        if all(self.clients[kind].service_is_ready() for kind in kinds):
            return True
        self.report(f'{what}: no simulator')
        return False

    def _call(self, what, kind, request, then):
        """Call the standard's service ``kind``; then(response) once it succeeded (or was
        already so); the status line says why not."""
        def done(future):
            response = future.result()
            if response is None:
                self.report(f'{what}: no answer')
                return
            result = response.result
            if result.result in (Result.RESULT_OK,
                                 SetSimulationState.Response.ALREADY_IN_TARGET_STATE):
                then(response)
                return
            self.report(f'{what} refused: {result.error_message}')
            self.warn(f'refused:{what}', f'the simulator refused {what}: '
                                         f'{result.error_message}')
        self.clients[kind].call_async(request).add_done_callback(done)

    def set_rtf(self, value):
        client = self.clients['set_parameters']
        if not client.service_is_ready():
            self.report('real-time factor: no simulator')
            return
        request = SetParameters.Request(parameters=[Parameter(
            name=RTF_PARAMETER, value=ParameterValue(type=ParameterType.PARAMETER_DOUBLE,
                                                     double_value=float(value)))])

        def done(future):
            response = future.result()
            results = response.results if response is not None else []
            if results and results[0].successful:
                self.rtf_set = float(value)
                self.report(f'real-time factor set to {value:g}')
                self.said('rtf', f'real-time factor set to {value:g}')
            else:
                reason = results[0].reason if results else 'no answer'
                self.report(f'real-time factor {value:g} refused: {reason}')
                self.warn('rtf', f'real-time factor {value:g} refused: {reason}')
        client.call_async(request).add_done_callback(done)

    def read_rtf(self):
        """Ask for the simulator's real_time_factor (and whether it is paused, and its
        step_count) unless known or being asked."""
        if self.rtf_set is None and self.clients['get_parameters'].service_is_ready():
            self._read_parameters()

    def _read_parameters(self, then=None):
        """One request at a time for the parameters read_rtf says; then() after its answer."""
        if then is not None:
            self._after_read.append(then)
        if self._rtf_asked:
            return
        self._rtf_asked = True

        def done(future):
            self._rtf_asked = False
            response = future.result()
            values = response.values if response is not None else []
            if values and values[0].type == ParameterType.PARAMETER_DOUBLE:
                self.rtf_set = values[0].double_value
            if len(values) > 1 and values[1].type == ParameterType.PARAMETER_BOOL:
                self.started_paused = values[1].bool_value
            if len(values) > 2 and values[2].type == ParameterType.PARAMETER_INTEGER:
                self.step_count = values[2].integer_value
            waiting, self._after_read = self._after_read, []
            for then in waiting:
                then()
        self.clients['get_parameters'].call_async(GetParameters.Request(
            names=[RTF_PARAMETER, PAUSED_PARAMETER, STEP_COUNT_PARAMETER])) \
            .add_done_callback(done)

    # -- the clock ------------------------------------------------------------------------------
    def _on_clock(self, msg):
        now = time.monotonic()
        sim = seconds(msg.clock)
        if self.time is not None and sim < self.time:
            self._clock_watch.went_back()
            self._clock_samples.clear()  # a reset, or a new simulator
            self.paused = None
            # A new simulator may run at another speed, or step farther: read them again.
            self.rtf_set = self.step_count = None
        self.time = sim
        self._clock_samples.append((now, sim))
        while self._clock_samples and now - self._clock_samples[0][0] > RTF_WINDOW_S:
            self._clock_samples.pop(0)

    def _rtf(self):
        """Simulated seconds per wall second over the window; 0 when time stands still."""
        if len(self._clock_samples) < 2 or time.monotonic() - self._clock_samples[-1][0] > 0.5:
            return 0.0 if self.time is not None else None
        (w0, s0), (w1, s1) = self._clock_samples[0], self._clock_samples[-1]
        return (s1 - s0) / (w1 - w0) if w1 > w0 else None
