"""The GUI's ROS side: the bridge between the web pages and the ROS graph.

The bridge (``/miro_gui``) keeps the pages and runs their commands, finds the robots that
run, follows the scene, and keeps a robot part (robot_part.py: ``/<robot>/miro_gui``, in
the robot's namespace, with MiRo's relative names) for each robot that some page watches.
Each page chooses its own robot. The simulator's services, inputs and clock are
sim_link.py's; the images the pages show are frames.py's.

Nothing is subscribed that no page shows: a robot's sensors only while a page watches
it, each eye only while such a page shows it (so with no page open the simulator
renders nothing for the GUI), the overhead view likewise, and the scene, the robots'
robot_description and /tf only while a page shows the world view.

It runs in the ROS thread (its own executor); the web server calls the thread-safe
methods marked so. Commands from the pages go into a queue that a guard condition drains
in the ROS thread at once, so they never wait behind images.

It publishes only MiRo's control topics (from the robot parts) and the simulator's
touch and sound inputs, and calls only the simulator's services (the standard
simulation_interfaces', and its parameters).
"""
import collections
import json
import threading
import time
from dataclasses import dataclass

from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from std_msgs.msg import String
from visualization_msgs.msg import MarkerArray

from miro_ball.common.messages import message_class
from miro_ball.common.qos import profile
from miro_ball.common.robots import robots_running
from miro_ball.common.throttle import Throttled
from miro_ball.gui import protocol as p
from miro_ball.gui.demo_mode_panel import DemoModeRunner
from miro_ball.gui import readouts as r
from miro_ball.gui.frames import FrameStore
from miro_ball.gui.robot_part import NODE_NAME, PUBLISHED, RobotPart
from miro_ball.gui.scene import SceneState
from miro_ball.gui.sim_link import SimLink
from miro_ball.miro.constants import PLATFORM_TICK_S
from miro_ball.miro.interface import (DEFAULT_ROBOT_NAME, EYES, RobotTopics, TF, TF_STATIC,
                                      TF_STATIC_QOS, TF_TYPE, TOPIC)
from miro_ball.miro.touch import pads_at

DISCOVERY_PERIOD_S = 1.0
READOUT_PERIOD_S = 0.05  # readouts to the pages at 20 Hz
# What a page shows before it says (a page of an older version never says).
DEFAULT_VIEW = (frozenset(EYES), False)
# The scene is sent once and kept (transient local), as RViz expects.
# The simulator keeps two messages on the scene for a late subscriber (the layout and the
# movers, from a publisher each): a depth of 1 would keep only the one that came last.
SCENE_QOS = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE,
                       durability=DurabilityPolicy.TRANSIENT_LOCAL)
# The page draws the newest frames: /tf's depth need not be tf2's 100.
TF_PAGE_QOS = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE)


@dataclass
class _Page:
    robot: str
    channels: frozenset = DEFAULT_VIEW[0]
    world: bool = DEFAULT_VIEW[1]
    hearing: bool = False  # its Hearing panel is open
    demo: bool = False  # its demo-mode panel is open


@dataclass(frozen=True)
class _Open:
    """A page has connected (queued like its commands, so it comes before them)."""


@dataclass(frozen=True)
class _Close:
    """A page has gone."""


class GuiBridge(Node):
    """See the module docstring. robot: the MiRo every page watches, or None to let each
    page pick one. on_frame(channel): a new image or scene change arrived (to wake the
    pages); on_event(owners, text): a JSON message for these pages (a tone)."""

    def __init__(self, robot=None, *, context=None, on_frame=None, on_event=None,
                 default_robot=DEFAULT_ROBOT_NAME):
        super().__init__(NODE_NAME, context=context)
        self.warn = Throttled(self.get_logger().warning)
        self.fixed_robot = robot
        self.default_robot = robot or default_robot
        self.on_frame = on_frame if on_frame is not None else (lambda channel: None)
        self.on_event = on_event if on_event is not None else (lambda owners, text: None)
        self.images = FrameStore(self.warn, self.on_frame)
        self.demo = DemoModeRunner()  # demo mode processes the pages started
        self.sim = SimLink(self, self._report, self.warn)
        self._lock = threading.Lock()
        # Pages coming and going apart from their commands, so a flood of commands (whose
        # oldest the bounded queue drops) never loses one.
        self._comings_goings = collections.deque()
        self._commands = collections.deque(maxlen=10000)
        self.pages = {}  # owner: _Page (ROS thread)
        self._page_robot = {}  # owner: robot, for the web server's thread
        self._page_demo = set()  # owners showing demo mode, for the web server's thread
        self.watches = {}  # robot: RobotPart
        self.status = ''
        self.robots = []
        self.scene = SceneState()  # under self._lock
        self._scene_subs = {}  # 'scene', TF, TF_STATIC or a robot's name: subscription
        try:
            self._tf_type = message_class(TF_TYPE)
        except ValueError as err:  # tf2_msgs not built: the world view shows no robot
            self._tf_type = None
            self.get_logger().warning(f'the world view draws no robot: {err}')
        self._overhead_sub = None
        self._wake = self.create_guard_condition(self._run_commands)
        self._states = {}
        self._make_state()
        self.create_timer(PLATFORM_TICK_S, self._on_tick)
        self.create_timer(READOUT_PERIOD_S, self._make_state)
        self.create_timer(DISCOVERY_PERIOD_S, self._discover)

    def destroy_node(self):
        self.demo.stop_all()
        for name in list(self.watches):
            self._drop_watch(name)
        super().destroy_node()

    # -- thread-safe, for the web server ------------------------------------------------------
    def open(self, owner):
        """Page ``owner`` has connected: it watches the default robot until it picks one."""
        self._comings_goings.append((_Open(), owner))
        self._wake.trigger()

    def submit(self, command, owner):
        """Queue a checked command (protocol.py) from page ``owner``; run at once."""
        self._commands.append((command, owner))
        self._wake.trigger()

    def release(self, owner):
        """Page ``owner`` has gone: if it was driving, stop; drop what only it showed (its
        commands still queued are dropped too)."""
        self._comings_goings.append((_Close(), owner))
        self._wake.trigger()

    def frames(self, owner):
        """{channel: Frame}, the newest of each that page ``owner`` may show."""
        with self._lock:
            robot = self._page_robot.get(owner)
        return self.images.shown_with(robot)

    def overlay(self, owner, channel, frame):
        """(stamp, overlay) of demo mode to draw on ``frame`` of ``channel`` for page
        ``owner`` (while it shows demo mode), or None."""
        with self._lock:
            robot = self._page_robot.get(owner) if owner in self._page_demo else None
        return None if robot is None else self.images.overlay_on(robot, channel, frame)

    def state(self, owner):
        """JSON text of everything page ``owner`` shows besides images and the scene (made
        in the ROS thread)."""
        states = self._states
        return states.get(self._page_robot.get(owner)) or states[None]

    def scene_message(self, since):
        """(JSON text of the scene's changes after seq ``since`` or None, seq now)."""
        with self._lock:
            return self.scene.scene_message(since), self.scene.seq

    def tf_message(self, since):
        """(JSON text of the link frames changed after seq ``since`` or None, seq now)."""
        with self._lock:
            return self.scene.tf_message(since), self.scene.seq

    def texture(self, key):
        """The PNG bytes of a picture of the scene, or None."""
        with self._lock:
            return self.scene.textures.get(key)

    def stop_driving(self, why):
        """Stop every robot a page is driving; only once the ROS thread has ended."""
        for watch in self.watches.values():
            if watch.out.drive is not None:
                watch.stop(why)

    # -- readouts (ROS thread) -------------------------------------------------------------------
    def _report(self, text):
        self.status = text

    def _make_state(self):
        sim, contested = self.sim.state()
        common = {
            'robots': self.robots,
            'fixed': self.fixed_robot is not None,
            'sim': sim,
            'rtf_set': self.sim.rtf_set,
            'status': contested or self.status,
            'demo_running': self.demo.running(),
        }
        now = time.monotonic()
        states = {None: json.dumps(r.jsonable({
            't': 'state', 'robot': None, 'readouts': {}, 'age': None, 'eye_fov_deg': None,
            **common}))}
        for name, watch in self.watches.items():
            heard = watch.last_heard
            states[name] = json.dumps(r.jsonable({
                't': 'state', 'robot': name, 'readouts': watch.values,
                'age': now - heard if heard else None, 'eye_fov_deg': watch.fov, **common}))
        self._states = states

    def _tell_pages(self, robot, text):
        """Send a JSON message to every page watching ``robot`` (ROS thread)."""
        owners = [owner for owner, page in self.pages.items() if page.robot == robot]
        if owners:
            self.on_event(owners, text)

    # -- what the pages show: the subscriptions ----------------------------------------------------
    def _update_subscriptions(self):
        """Subscribe to what some page shows, and to nothing else."""
        shown = collections.defaultdict(set)  # robot: channel numbers
        for page in self.pages.values():
            shown[page.robot].update(p.CHANNELS.index(c) for c in page.channels)
        for name in shown:
            if name not in self.watches:
                self._add_watch(name)
        for name, watch in list(self.watches.items()):
            watching = name in shown
            if not watching and watch.out.drive is not None:
                watch.stop('no page watches it')
            watch.watch_sensors(watching)
            watch.watch_mics(any(page.hearing for page in self.pages.values()
                                 if page.robot == name))
            watch.watch_demo(any(page.demo for page in self.pages.values()
                                 if page.robot == name))
            watch.show({ch for ch in shown.get(name, ()) if p.CHANNELS[ch] != 'overhead'})
            if not watching and name not in self.robots:
                self._drop_watch(name)  # not running, not watched: nothing left to do
        overhead = p.CHANNELS.index('overhead')
        wanted = any(overhead in channels for channels in shown.values())
        if wanted and self._overhead_sub is None:
            self._overhead_sub = self.images.subscribe(self, self.sim.topics.overhead,
                                                       overhead)
        elif not wanted and self._overhead_sub is not None:
            self.destroy_subscription(self._overhead_sub)
            self._overhead_sub = None
        self._update_scene_subscriptions()
        with self._lock:
            self._page_robot = {owner: page.robot for owner, page in self.pages.items()}
            self._page_demo = {owner for owner, page in self.pages.items() if page.demo}

    def _update_scene_subscriptions(self):
        world = any(page.world for page in self.pages.values())
        wanted = set()
        if world:
            wanted = {'scene'} | set(self.robots)
            if self._tf_type is not None:
                wanted |= {TF, TF_STATIC}
        for key in set(self._scene_subs) - wanted:
            self.destroy_subscription(self._scene_subs.pop(key))
        for key in wanted - set(self._scene_subs):
            if key == 'scene':
                sub = self.create_subscription(MarkerArray, self.sim.topics.scene,
                                               self._on_scene, SCENE_QOS)
            elif key in (TF, TF_STATIC):
                sub = self.create_subscription(
                    self._tf_type, key, self._on_tf,
                    profile(TF_STATIC_QOS) if key == TF_STATIC else TF_PAGE_QOS)
            else:
                sub = self.create_subscription(
                    String, RobotTopics(key).topic(TOPIC['robot_description'].name),
                    lambda msg, robot=key: self._on_description(robot, msg),
                    profile(TOPIC['robot_description'].qos))
            self._scene_subs[key] = sub

    def _on_scene(self, msg):
        with self._lock:
            changed = self.scene.apply_markers(msg.markers, self.warn)
        if changed:
            self.on_frame(None)

    def _on_description(self, robot, msg):
        with self._lock:
            changed = self.scene.apply_description(robot, msg.data, self.warn)
        if changed:
            self.on_frame(None)

    def _on_tf(self, msg):
        with self._lock:
            changed = self.scene.apply_tf(msg.transforms, self.warn)
        if changed:
            self.on_frame(None)

    # -- commands (ROS thread) -------------------------------------------------------------------
    def _run_commands(self):
        changed = False
        for queue in (self._comings_goings, self._commands):
            while queue:
                command, owner = queue.popleft()
                changed |= bool(self._run(command, owner))
        if changed:
            self._update_subscriptions()
            self._make_state()

    def _run(self, command, owner):
        """Carry out one command; True if what the pages show has changed."""
        if isinstance(command, _Open):
            self.pages[owner] = _Page(self._robot_for_new_page())
            return True
        page = self.pages.get(owner)
        if page is None:
            return False  # from a page that has gone
        kind = type(command)
        if kind in _PAGE_COMMANDS:
            return _PAGE_COMMANDS[kind](self, page, command, owner)
        watch = self.watches.get(page.robot)
        if watch is None:
            return False  # its robot is not there (yet): nothing to drive
        if kind in PUBLISHED:
            watch.publish(command)
        else:
            _ROBOT_COMMANDS[kind](watch, command, owner)
        return False

    # Each handler: (bridge, page, command, owner) -> True if what the pages show changed.
    def _close(self, page, command, owner):
        watch = self.watches.get(page.robot)
        if watch is not None:
            watch.let_go(owner, 'its page closed')
        del self.pages[owner]
        return True

    def _view(self, page, command, owner):
        page.channels, page.world = command.channels, command.world
        return True

    def _choose(self, page, command, owner):
        """Page ``owner`` watches the robot named from now on; True if that changed."""
        name = command.name
        if self.fixed_robot is not None:
            self.status = f'fixed to {self.fixed_robot} by --robot'
            return False
        if name not in self.robots:
            self.warn('robot', f'no robot {name!r} running; there are {self.robots}')
            return False
        if name == page.robot:
            return False
        watch = self.watches.get(page.robot)
        if watch is not None:
            watch.let_go(owner, 'its page chose another robot')
        page.robot = name
        self.get_logger().info(f'page {owner} watches {name}')
        return True

    def _sim_action(self, page, command, owner):
        self.sim.call(command.action)
        return False

    def _set_rtf(self, page, command, owner):
        self.sim.set_rtf(command.value)
        return False

    def _place(self, page, command, owner):
        self.sim.place(command.name, command.x, command.y)
        return False

    def _hear(self, page, command, owner):
        page.hearing = command.shown
        watch = self.watches.get(page.robot)
        if watch is not None:
            watch.hear(command.mic, command.listen)
        return True

    def _demo(self, page, command, owner):
        page.demo = command.shown
        return True

    def _demo_run(self, page, command, owner):
        if not command.run:
            self.demo.stop(page.robot)
            self.status = f'demo mode stopped for {page.robot}'
            return False
        failed = self.demo.start(page.robot)
        self.status = failed or f'demo mode started for {page.robot}'
        return False

    def _play_sound(self, page, command, owner):
        self.sim.play_sound(command.kind, command.x, command.y)
        return False

    def _stop_sound(self, page, command, owner):
        self.sim.stop_sound(command.name)
        return False

    def _on_tick(self):
        """Once per platform tick: each robot part's drive, stop and touches go out."""
        now = time.monotonic()
        for watch in list(self.watches.values()):
            for part, pads in watch.tick(now).items():
                self.sim.touch(watch.robot, part, pads)

    # -- which robot -----------------------------------------------------------------------------
    def _robot_for_new_page(self):
        if self.fixed_robot is not None:
            return self.fixed_robot
        if self.default_robot in self.robots or not self.robots:
            return self.default_robot
        return self.robots[0]

    # The robot parts spin on the bridge's executor: they are made and dropped only in its
    # callbacks, when Node.executor (public, set by Executor.add_node) is the one spinning.
    def _add_watch(self, name):
        watch = self.watches[name] = RobotPart(name, context=self.context, frames=self.images,
                                               warn=self.warn, tell_pages=self._tell_pages)
        if self.executor is not None:
            self.executor.add_node(watch)

    def _drop_watch(self, name):
        watch = self.watches.pop(name)
        self.images.forget(name)
        if watch.executor is not None:
            watch.executor.remove_node(watch)
        watch.destroy_node()

    def _discover(self):
        robots = robots_running(self)
        changed = robots != self.robots
        self.robots = robots
        if self.fixed_robot is None and robots:
            for page in self.pages.values():
                if page.robot not in robots:  # it has gone: show one that runs
                    page.robot = self._robot_for_new_page()
                    changed = True
        if changed:
            self._update_subscriptions()
        self.sim.read_rtf()
        for robot, said in self.demo.reap():
            self.status = f'demo mode for {robot} ended: {said}'


# The page's own commands, whatever robot it watches.
_PAGE_COMMANDS = {
    _Close: GuiBridge._close,
    p.View: GuiBridge._view,
    p.SelectRobot: GuiBridge._choose,
    p.SimAction: GuiBridge._sim_action,
    p.SetRtf: GuiBridge._set_rtf,
    p.Place: GuiBridge._place,
    p.Hear: GuiBridge._hear,
    p.PlaceSound: GuiBridge._play_sound,
    p.Demo: GuiBridge._demo,
    p.DemoRun: GuiBridge._demo_run,
    p.StopSound: GuiBridge._stop_sound,
}

# Commands for the robot the page watches (besides PUBLISHED, one message each):
# (robot part, command, owner).
_ROBOT_COMMANDS = {
    p.Drive: lambda watch, c, owner: watch.drive(c.linear, c.angular, owner),
    p.Stop: lambda watch, c, owner: watch.let_go(owner, 'stopped by the page'),
    p.Touch: lambda watch, c, owner: watch.touch(c.part, pads_at(c.u, c.v)),
}


def handled_commands():
    """Every command type a page can send that the bridge carries out."""
    return set(_PAGE_COMMANDS) | set(_ROBOT_COMMANDS) | set(PUBLISHED)
