"""The GUI's link to the simulator: its services (reset, step, pause, its real-time factor),
its inputs (set_pose, the touch pads) and its clock (the time and speed the pages show).

Only the simulator's own services and inputs are used; a simulator that is not there is
said so in the status line, never waited for.
"""
import math
import time

from geometry_msgs.msg import PoseStamped
from rcl_interfaces.msg import Parameter, ParameterType, ParameterValue
from rcl_interfaces.srv import GetParameters, SetParameters
from rosgraph_msgs.msg import Clock
from std_msgs.msg import String, UInt16
from std_srvs.srv import SetBool, Trigger

from miro_ball.common.clock_watch import clock_publishers, ClockWatch, shared_domain_line
from miro_ball.common.qos import profile
from miro_ball.common.stamps import seconds
from miro_ball.common.throttle import Throttled
from miro_ball.miro.interface import CLOCK, CONTROL_QOS, SimTopics

RTF_PARAMETER = 'real_time_factor'
PAUSED_PARAMETER = 'paused'
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
        self._rtf_asked = False
        self._clock_samples = []  # (wall, sim) of the last RTF_WINDOW_S of /clock
        self._clock_watch = ClockWatch(node)
        self._pubs = {}
        self._sounds = 0  # placed from the pages so far (their names' numbers)
        node.create_subscription(Clock, CLOCK, self._on_clock, 10)
        self.clients = {'reset': node.create_client(Trigger, self.topics.reset),
                        'step': node.create_client(Trigger, self.topics.step),
                        'pause': node.create_client(SetBool, self.topics.pause),
                        'set_parameters': node.create_client(
                            SetParameters, self.topics.topic('set_parameters')),
                        'get_parameters': node.create_client(
                            GetParameters, self.topics.topic('get_parameters'))}

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
        sim = {'present': self.clients['reset'].service_is_ready(), 'time': self.time,
               'rtf': rtf, 'paused': paused}
        status = (shared_domain_line(clock_publishers(self.node),
                                     self.node.context.get_domain_id())
                  if contested else None)
        return sim, status

    # -- inputs ---------------------------------------------------------------------------------
    def place(self, name, x, y):
        """Move an object (or a robot) to x, y; its height and orientation stay its own
        (height NaN, orientation all zeros say so to the simulator)."""
        msg = PoseStamped()
        msg.header.stamp = self.node.get_clock().now().to_msg()
        msg.header.frame_id = name
        msg.pose.position.x, msg.pose.position.y = x, y
        msg.pose.position.z = math.nan
        o = msg.pose.orientation
        o.x = o.y = o.z = o.w = 0.0
        self._publisher(PoseStamped, self.topics.set_pose).publish(msg)

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
        name = 'pause' if action in ('pause', 'resume') else action
        client = self.clients[name]
        if not client.service_is_ready():
            self.report(f'{action}: no simulator')
            return
        request = client.srv_type.Request()
        if name == 'pause':
            request.data = action == 'pause'

        def done(future):
            result = future.result()
            if result is None:
                self.report(f'{action}: no answer')
                return
            if name == 'pause' and result.success:
                self.paused = request.data
            self.report(f'{action}: {result.message}')
            self.said(action, f'simulator {action}: {result.message}')
        client.call_async(request).add_done_callback(done)

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
        """Ask for the simulator's real_time_factor (and whether it is paused) unless known
        or being asked."""
        client = self.clients['get_parameters']
        if self.rtf_set is not None or self._rtf_asked or not client.service_is_ready():
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
        client.call_async(GetParameters.Request(names=[RTF_PARAMETER, PAUSED_PARAMETER])) \
            .add_done_callback(done)

    # -- the clock ------------------------------------------------------------------------------
    def _on_clock(self, msg):
        now = time.monotonic()
        sim = seconds(msg.clock)
        if self.time is not None and sim < self.time:
            self._clock_watch.went_back()
            self._clock_samples.clear()  # a reset, or a new simulator
            self.paused = None
            self.rtf_set = None  # a new simulator may run at another speed: read it again
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
