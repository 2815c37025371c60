"""The GUI in a real headless Chromium, driving the simulator in this process.

miro_gui runs as a child process (as a user starts it) on the test's ROS domain;
the simulator is in-process and paused, stepped here tick by tick, so every
"within 0.5 s" is simulated time. Where the GUI's own timing matters (a key held
or released, a page closed), the world is stepped no faster than real time, as a
simulator runs for a user. One simulator, GUI and browser serve all the tests of
this file; each test opens its own page.

The world view (three.js on WebGL, SwiftShader here) is checked as a user sees it:
screenshots of #world-view (saved under pytest's tmp dir; -s prints their paths), and
mouse gestures where the page says a thing is drawn (miroGui.world.screenOf).
"""
import http.client
import math
import os
import shutil
import sys
import time

import pytest
from rclpy.parameter import Parameter

from miro_ball.common.isolation import isolated_env
from miro_ball.gui.process import GuiProcess
from miro_ball.miro.interface import BALL_NAME, RobotTopics, SimTopics, default_robot_name
from miro_ball.miro.urdf import parse_visuals, urdf

playwright_api = pytest.importorskip('playwright.sync_api')
CHROMIUM = shutil.which('chromium') or '/usr/bin/chromium'
if not os.path.exists(CHROMIUM):
    pytest.skip("Debian's chromium is not installed (./dev.sh installs it as root)",
                allow_module_level=True)

ROBOT = default_robot_name()
T = RobotTopics(ROBOT)
BLUE_BALL_JS = """(id) => {
  const c = document.getElementById(id);
  const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
  let n = 0;
  for (let i = 0; i < d.length; i += 4) if (d[i + 2] > 120 && d[i] < 60 && d[i + 1] < 60) n++;
  return n;
}"""


class Rig:
    """Simulator, GUI process, browser; and the messages the robot got."""

    def __init__(self, context, executor, sim, url, browser, probe):
        self.context, self.executor, self.sim = context, executor, sim
        self.url, self.browser = url, browser
        from geometry_msgs.msg import PoseStamped
        from nav_msgs.msg import Odometry
        from sensor_msgs.msg import JointState
        from std_msgs.msg import Float32MultiArray, UInt16
        self.odom = probe.watch(Odometry, T.odom)
        self.ball = probe.watch(PoseStamped, SimTopics().object_pose(BALL_NAME))
        self.touch = {part: probe.watch(UInt16, T.touch(part)) for part in ('head', 'body')}
        self.joints = probe.watch(JointState, T.kinematic_joints)
        self.wheels = probe.watch(Float32MultiArray, T.wheel_speed_cmd)
        self.errors = []
        self.pages = []  # every page opened, closed after each test

    def _tick(self):
        from rostools import drain

        drain(self.executor, rounds=20)
        self.sim.advance(self.sim.sim.ticks_per_platform_tick)

    def until(self, predicate, wall_guard_s=60.0):
        """Step the world until predicate() holds (looked at every 3 ticks). The page and
        the GUI live on wall-clock time (discovery, a busy machine), so only a wall-clock
        guard against a hang limits this."""
        deadline = time.monotonic() + wall_guard_s
        while time.monotonic() < deadline:
            for _ in range(3):
                self._tick()
            if predicate():
                return True
        return False

    def paused_until(self, predicate, wall_guard_s=30.0):
        """Serve the graph without stepping the world (as a paused simulator does) until
        predicate() holds; the page lives on wall-clock time, so a guard limits this."""
        deadline = time.monotonic() + wall_guard_s
        while time.monotonic() < deadline:
            self.executor.spin_once(timeout_sec=0.05)
            if predicate():
                return True
        return False

    def run(self, sim_seconds, stop_when=None):
        """Step sim_seconds, no faster than real time, as a simulator runs for a user (the
        GUI's key and deadman handling is wall-clock time); returns the simulated seconds
        until stop_when() held, or None."""
        start_wall, start_sim = time.monotonic(), self.sim.sim.time
        while self.sim.sim.time - start_sim < sim_seconds:
            ahead = (self.sim.sim.time - start_sim) - (time.monotonic() - start_wall)
            if ahead > 0:
                time.sleep(ahead)
            self._tick()
            if stop_when is not None and stop_when():
                return self.sim.sim.time - start_sim
        return None

    def open_page(self):
        page = self.browser.new_page(viewport={'width': 1400, 'height': 900})
        self.pages.append(page)
        page.on('pageerror', lambda err: self.errors.append(str(err)))
        page.on('console', lambda msg: msg.type == 'error' and self.errors.append(msg.text))
        page.goto(self.url)
        assert self.until(lambda: frames(page, 'caml') > 0 and frames(page, 'camr') > 0), \
            'no eye images reached the page'
        return page

    def close_pages(self):
        for page in self.pages:
            if not page.is_closed():
                page.close()
        self.pages.clear()

    @property
    def wheel_cmd(self):
        return list(self.wheels[-1].data) if self.wheels else None

    def stopped(self):
        return self.wheel_cmd == [0.0, 0.0]

    def moving(self):
        return self.wheel_cmd is not None and min(self.wheel_cmd) > 0.05


def frames(page, channel):
    return page.evaluate(f'window.miroGui ? (miroGui.frames[{channel!r}] || 0) : 0')


@pytest.fixture(scope='module')
def rig():
    import rclpy
    from rclpy.context import Context
    from rclpy.executors import SingleThreadedExecutor

    from miro_sim_bullet.ros.node import SimNode
    from rostools import Probe

    domain = int(os.environ['ROS_DOMAIN_ID'])
    context = Context()
    rclpy.init(context=context, domain_id=domain)
    executor = SingleThreadedExecutor(context=context)
    sim = SimNode(context=context, parameter_overrides=[
        Parameter('paused', value=True), Parameter('renderer', value='tiny'),
        Parameter('eye_workers', value=False), Parameter('frame_width', value=320),
        Parameter('frame_height', value=240), Parameter('overhead_rate', value=5.0)])
    executor.add_node(sim)
    probe = Probe(context, executor, name='gui_probe')
    gui = GuiProcess(isolated_env(domain))
    pw = playwright_api.sync_playwright().start()
    browser = pw.chromium.launch(executable_path=CHROMIUM)
    try:
        yield Rig(context, executor, sim, gui.url, browser, probe)
    finally:
        browser.close()
        pw.stop()
        code = gui.stop()
        output = ''.join(gui.output)
        sys.stdout.write(output)
        executor.shutdown(timeout_sec=1.0)
        sim.destroy_node()
        rclpy.try_shutdown(context=context)
    # Stopped like a user's Ctrl+C: at once, cleanly.
    assert code == 0 and 'Traceback' not in output, output


@pytest.fixture(autouse=True)
def pages_closed(rig):
    """A test that failed with a key held leaves no page driving the robot in the next."""
    yield
    rig.close_pages()


def test_page_shows_both_eyes_live_the_ball_and_the_readouts(rig, tmp_path):
    page, other = rig.open_page(), rig.open_page()  # two pages at once both work
    before = {(p, eye): frames(p, eye) for p in (page, other) for eye in ('caml', 'camr')}
    assert rig.until(lambda: all(frames(p, e) >= n + 5 for (p, e), n in before.items()))
    other.close()
    assert rig.until(lambda: page.evaluate(
        "miroGui.state && miroGui.state.readouts.battery > 4 && miroGui.state.sim.present"))
    ball_pixels = max(page.evaluate(BLUE_BALL_JS, eye) for eye in ('caml', 'camr'))
    assert ball_pixels > 20, 'the blue ball is in view at the start but not on the page'
    assert page.locator('#sim').is_visible()
    shot = tmp_path / 'miro_gui.png'
    page.screenshot(path=str(shot), full_page=True)
    print(f'\nscreenshot of the GUI: {shot}')
    page.close()
    assert not rig.errors


def test_a_page_opened_while_the_simulator_is_paused_shows_the_last_instant(rig):
    rig.open_page().close()  # the world has run: the GUI has seen it
    page = rig.browser.new_page(viewport={'width': 1400, 'height': 900})
    rig.pages.append(page)
    page.goto(rig.url)  # and now nothing new comes: the simulator stays paused
    assert rig.paused_until(lambda: frames(page, 'caml') > 0 and frames(page, 'camr') > 0), \
        'the eyes stay black'
    assert rig.paused_until(lambda: page.evaluate(
        'miroGui.state && miroGui.state.readouts.battery > 4')), 'no readouts'
    assert rig.paused_until(lambda: world_ready(page)), 'no ball or robot in the world view'
    assert max(page.evaluate(BLUE_BALL_JS, eye) for eye in ('caml', 'camr')) > 20


def test_arrow_key_drives_forward_and_release_stops_within_half_a_second(rig):
    page = rig.open_page()
    start_x = rig.odom[-1].pose.pose.position.x
    page.keyboard.down('ArrowUp')
    assert rig.until(rig.moving), 'holding ArrowUp did not drive the wheels'
    rig.run(1.0)  # longer than the GUI's deadman: the page renews the command
    # A page kept from a core for longer than the deadman is stopped by it, as it should be,
    # and drives on with its next renewal: a drive that was not renewed never would.
    assert rig.until(rig.moving, wall_guard_s=5.0), \
        'the drive did not last while the key was held'
    assert rig.odom[-1].pose.pose.position.x > start_x + 0.05
    page.keyboard.up('ArrowUp')
    stopped_after = rig.run(1.0, rig.stopped)
    # The simulator's own command timeout is 0.5 s: stopping sooner is the GUI's doing.
    assert stopped_after is not None and stopped_after < 0.4
    page.close()


def test_closing_the_page_with_a_key_held_stops_the_robot(rig):
    page = rig.open_page()
    page.keyboard.down('KeyW')
    assert rig.until(rig.moving)
    page.close()
    stopped_after = rig.run(1.0, rig.stopped)
    assert stopped_after is not None and stopped_after < 0.4


def test_the_page_losing_focus_with_a_key_held_stops_the_robot(rig):
    page = rig.open_page()
    page.keyboard.down('ArrowUp')
    assert rig.until(rig.moving)
    page.evaluate("window.dispatchEvent(new Event('blur'))")  # the key-up goes elsewhere
    stopped_after = rig.run(1.0, rig.stopped)
    assert stopped_after is not None and stopped_after < 0.4
    page.keyboard.up('ArrowUp')
    page.close()


def test_head_slider_moves_the_head(rig):
    import math
    page = rig.open_page()
    page.locator('#lift').fill('15')
    page.locator('#yaw').fill('-30')

    def head_there():
        lift, yaw = rig.joints[-1].position[1:3]
        return abs(math.degrees(lift) - 15) < 2 and abs(math.degrees(yaw) + 30) < 2
    assert rig.until(head_there)
    page.locator('#calib').click()
    assert rig.until(lambda: abs(math.degrees(rig.joints[-1].position[1]) - 34) < 2)
    page.close()


def test_every_slider_shows_its_value_as_it_moves(rig):
    page = rig.open_page()
    shown = page.evaluate("""() => [...document.querySelectorAll('input[type=range]')].map(
      (input) => [input.id, (input.parentElement.querySelector('output') || {}).textContent])""")
    assert shown and all(text for _, text in shown), f'sliders without a value: {shown}'
    page.locator('#wagperiod').fill('1.1')
    assert page.locator('#wagperiod_out').text_content() == '1.10'
    page.locator('#led_white').click()  # a preset moves the brightness slider
    assert page.locator('#led_bright_out').text_content() == '63'
    page.close()


def test_reset_puts_miro_back(rig):
    page = rig.open_page()
    page.keyboard.down('ArrowUp')
    assert rig.until(lambda: rig.odom[-1].pose.pose.position.x > 0.1)
    page.keyboard.up('ArrowUp')
    assert rig.until(rig.stopped)
    page.locator('#reset').click()
    assert rig.until(lambda: abs(rig.odom[-1].pose.pose.position.x) < 0.01)
    page.close()


def test_garbage_is_ignored_out_of_range_is_clamped_and_the_server_keeps_serving(rig):
    import math
    page = rig.open_page()
    # A second socket from the page, as a buggy or hostile script would open.
    page.evaluate("""() => new Promise((resolve) => {
      const ws = window.rogue = new WebSocket(`ws://${location.host}/ws`);
      ws.onopen = () => {
        for (const m of ['not json', '[1,2]', '{"t":"nope"}',
                         '{"t":"drive","linear":"fast","angular":0}',
                         '{"t":"drive","linear":1e999,"angular":0}',
                         '{"t":"drive","linear":0.1,"angular":0,"x":1}',
                         'x'.repeat(200000)]) ws.send(m);
        ws.send(new Uint8Array([1, 2, 3]));
        resolve();
      };
    })""")
    rig.run(0.5)  # time for the GUI to act on them, were it to
    assert rig.stopped(), 'a malformed drive command reached the robot'
    assert page.evaluate('rogue.readyState') == 1, 'the server dropped the socket'
    page.evaluate("""rogue.send('{"t":"head","lift":500,"yaw":-1e6,"pitch":0}')""")
    assert rig.until(lambda: math.degrees(rig.joints[-1].position[1]) > 58
                    and math.degrees(rig.joints[-1].position[2]) < -53)
    assert math.degrees(rig.joints[-1].position[1]) < 60.5  # clamped to MiRo's 60
    page.evaluate("""rogue.send('{"t":"drive","linear":9,"angular":0}')""")
    assert rig.until(lambda: rig.wheel_cmd is not None and max(rig.wheel_cmd) > 0.3)
    assert max(rig.wheel_cmd) <= 0.4 + 1e-6
    assert rig.until(rig.stopped), 'a drive command that was not renewed went on'
    seen = frames(page, 'caml')
    assert rig.until(lambda: frames(page, 'caml') > seen + 3), 'the page stopped updating'
    page.close()
    assert not rig.errors


def handshake(url, origin=None, host=None):
    """Status of a WebSocket upgrade request to the GUI."""
    address = url.split('//')[1].strip('/')
    conn = http.client.HTTPConnection(address, timeout=5)
    headers = {'Connection': 'Upgrade', 'Upgrade': 'websocket', 'Sec-WebSocket-Version': '13',
               'Sec-WebSocket-Key': 'dGhlIHNhbXBsZSBub25jZQ=='}
    if origin:
        headers['Origin'] = origin
    if host:
        headers['Host'] = host
    conn.request('GET', '/ws', headers=headers)
    status = conn.getresponse().status
    conn.close()
    return status


def test_foreign_origins_are_refused(rig):
    own = rig.url.rstrip('/')
    port = own.rsplit(':', 1)[1]
    assert handshake(rig.url, origin=own) == 101
    assert handshake(rig.url, origin='http://evil.example') == 403
    assert handshake(rig.url, origin=f'http://evil.example:{port}',
                     host=f'evil.example:{port}') == 403  # DNS rebinding


# ---- the world view ---------------------------------------------------------------------------
def world_ready(page):
    """The page's world view has the scene and MiRo's link frames."""
    return page.evaluate(f"""() => !!miroGui.world
        && miroGui.world.positionOf({BALL_NAME!r}) !== null
        && miroGui.world.positionOf({ROBOT!r}) !== null""")


def world_page(rig):
    page = rig.open_page()
    assert rig.until(lambda: world_ready(page)), 'the scene never reached the world view'
    page.evaluate('miroGui.world.home()')
    return page


def redrawn(rig, page):
    """Wait until the world view has drawn what it has now."""
    drawn = page.evaluate('miroGui.world.dirty = true; miroGui.world.drawn')
    assert rig.until(lambda: page.evaluate('miroGui.world.drawn') > drawn)


def world_shot(page, tmp_path, name):
    path = tmp_path / f'{name}.png'
    png = page.locator('#world-view').screenshot(path=str(path))
    print(f'\nscreenshot of the world view: {path}')
    import cv2
    import numpy as np
    return cv2.imdecode(np.frombuffer(png, np.uint8), cv2.IMREAD_COLOR)


def blue_pixels(bgr):
    b, g, r = (bgr[..., i].astype(int) for i in range(3))
    return int(((b > 120) & (g < 60) & (r < 60)).sum())


def screen(page, point):
    at = page.evaluate('(p) => miroGui.world.screenOf(p)', list(point))
    return at['x'], at['y']


def position(page, name):
    return page.evaluate('(n) => miroGui.world.positionOf(n)', name)


def test_the_world_view_shows_the_ball_and_miro_driving(rig, tmp_path):
    page = world_page(rig)
    assert page.locator('#world-view').is_visible(), 'the world view is not shown by default'
    redrawn(rig, page)
    before = world_shot(page, tmp_path, 'world_view')
    assert blue_pixels(before) > 30, 'the blue ball is not in the world view'
    start = position(page, ROBOT)
    page.keyboard.down('ArrowUp')
    rig.run(1.0)
    page.keyboard.up('ArrowUp')
    assert rig.until(rig.stopped)
    assert rig.until(lambda: math.dist(position(page, ROBOT)[:2], start[:2]) > 0.1), \
        'MiRo drove but did not move in the world view'
    redrawn(rig, page)
    after = world_shot(page, tmp_path, 'world_view_after_driving')
    changed = (abs(after.astype(int) - before.astype(int)).sum(axis=2) > 40).mean()
    assert changed > 0.002, f'driving MiRo changed {changed:.2%} of the world view'
    page.close()
    assert not rig.errors


def test_the_first_view_of_the_den_shows_miro_and_the_ball_not_only_the_boards(rig):
    """framing.js on the den world's boxes (its boards are named objects, MiRo and the ball
    are far from them), checked with three.js's own camera: every box is in the picture, and
    the picture is not mostly empty."""
    from miro_sim_bullet.scene.world_file import load_world
    den = load_world('den')
    boxes = [[[x - sx / 2, y - sy / 2, z - sz / 2], [x + sx / 2, y + sy / 2, z + sz / 2]]
             for (x, y, z), (sx, sy, sz) in ((s.position, s.size) for s in den.shapes)]
    (bx, by), r = den.ball.position, den.ball.radius
    boxes.append([[bx - r, by - r, 0.0], [bx + r, by + r, 2 * r]])
    mx, my, _ = den.robots[0].pose
    boxes.append([[mx - 0.2, my - 0.1, 0.0], [mx + 0.1, my + 0.1, 0.35]])  # MiRo's size
    page = rig.browser.new_page(viewport={'width': 1400, 'height': 900})
    rig.pages.append(page)
    page.goto(rig.url)
    reach = page.evaluate("""async (boxes) => {
      const THREE = await import('/static/vendor/three/three.module.js');
      const { homeView } = await import('/static/framing.js');
      const view = homeView(boxes, 45, 16 / 9);
      const camera = new THREE.PerspectiveCamera(45, 16 / 9, 0.02, 200);
      camera.up.set(0, 0, 1);
      camera.position.fromArray(view.position);
      camera.lookAt(new THREE.Vector3().fromArray(view.target));
      camera.updateMatrixWorld();
      return boxes.map(([lo, hi]) => {
        const xs = [], ys = [];
        for (const x of [lo[0], hi[0]]) for (const y of [lo[1], hi[1]]) for (const z of [lo[2], hi[2]]) {
          const v = new THREE.Vector3(x, y, z).project(camera);
          xs.push(v.x); ys.push(v.y);
        }
        return Math.max(...xs.map(Math.abs), ...ys.map(Math.abs));
      });
    }""", boxes)
    assert all(r < 1.0 for r in reach), f'a box out of the picture: {reach}'
    assert max(reach) > 0.5, f'everything small in the middle of the picture: {reach}'


def test_the_world_view_builds_miro_from_its_robot_description(rig, tmp_path):
    """Every primitive <visual> of the URDF is a mesh of the page, hung on the frame of its
    link ('<robot>/<link>', placed by /tf), and the head sits above the wheels."""
    page = world_page(rig)
    built = page.evaluate(f"""() => [...miroGui.world.markers.values()]
        .filter(({{ data }}) => data.id.startsWith({ROBOT + '/urdf-'!r}))
        .map(({{ data, obj }}) => [data.link, data.kind,
             obj.parent === miroGui.world.frames.get({ROBOT!r} + '/' + data.link)])""")
    visuals = parse_visuals(urdf())
    assert sorted(link for link, _, _ in built) == sorted(link for link, _, _ in visuals)
    assert sorted(kind for _, kind, _ in built) == sorted(shape.kind for _, shape, _ in visuals)
    assert all(on_its_frame for _, _, on_its_frame in built)
    head = page.evaluate(f'miroGui.world.worldOf({ROBOT!r} + "/head").toArray()')
    wheel = page.evaluate(f'miroGui.world.worldOf({ROBOT!r} + "/wheel_l").toArray()')
    assert head[2] - wheel[2] > 0.1
    redrawn(rig, page)
    world_shot(page, tmp_path, 'world_view_miro')
    page.close()
    assert not rig.errors


def test_dragging_the_ball_moves_it_in_the_simulator_by_the_dragged_amount(rig, tmp_path):
    page = world_page(rig)
    assert rig.until(lambda: rig.ball), 'no ground truth of the ball'
    truth = rig.ball[-1].pose.position
    start = position(page, BALL_NAME)
    assert math.dist(start[:2], (truth.x, truth.y)) < 0.01
    # Towards the arena's edge and away from MiRo, wherever an earlier test left them.
    away = -0.4 if start[1] > -0.5 else 0.4
    shift = (-0.1, away)
    target = (start[0] + shift[0], start[1] + shift[1], start[2])
    (x0, y0), (x1, y1) = screen(page, start), screen(page, target)
    page.mouse.move(x0, y0)
    page.mouse.down()
    for k in range(1, 11):
        page.mouse.move(x0 + (x1 - x0) * k / 10, y0 + (y1 - y0) * k / 10)
        rig.run(0.05)
    rig.run(0.3)  # held still: it stays under the pointer
    world_shot(page, tmp_path, 'world_view_dragging_the_ball')
    page.mouse.up()
    rig.run(0.3)
    end = rig.ball[-1].pose.position
    miss = math.dist((end.x, end.y), (truth.x + shift[0], truth.y + shift[1]))
    assert miss < 0.05, f'the ball ended {miss:.3f} m from where it was dragged'
    assert rig.until(lambda: math.dist(position(page, BALL_NAME)[:2], (end.x, end.y)) < 0.01)
    page.close()
    assert not rig.errors


def stroke(rig, page, points, sensor, sim_seconds=5.0):
    """Press at the first point and stroke back and forth through the others, as a hand
    does, until the sensor reads a touch (the GUI's first touch of a part also waits for
    ROS to find the simulator's topic); the simulated seconds that took, or None."""
    import itertools
    heard = len(sensor)
    path = itertools.cycle(points + points[-2:0:-1])
    ticks = itertools.count()
    page.mouse.move(*next(path))
    page.mouse.down()

    def touched():
        if next(ticks) % 3 == 0:  # a move every 60 ms
            page.mouse.move(*next(path))
        return any(m.data for m in sensor[heard:])
    took = rig.run(sim_seconds, touched)
    page.mouse.up()
    return took


def test_stroking_miros_head_in_the_view_and_its_back_on_the_body_map_touches_it(rig, tmp_path):
    page = world_page(rig)
    page.select_option('#world_mode', 'stroke')

    def head(fractions):  # a point of the head's shapes, as fractions of their box
        return page.evaluate('(f) => miroGui.world.linkPoint(%r, "head", f)' % ROBOT, fractions)
    # Seen from in front of the head and above it, as a hand would come.
    page.evaluate('([eye, at]) => miroGui.world.setView(eye, at)',
                  [head([3, 0.5, 5]), head([0.5, 0.5, 0.5])])
    redrawn(rig, page)
    world_shot(page, tmp_path, 'world_view_head')
    points = [screen(page, head([f, 0.5, 1.0])) for f in (0.8, 0.7, 0.6, 0.5, 0.4, 0.3)]
    under = [page.evaluate('([x, y]) => miroGui.world.hitAt(x, y)', list(p)) for p in points]
    assert stroke(rig, page, points, rig.touch['head']) is not None, \
        f"stroking MiRo's head in the world view did not touch its head sensor ({under})"
    # The body map beside the readouts: a stroke down MiRo's back.
    box = page.locator('#bodymap').bounding_box()
    w, h = page.evaluate("[document.getElementById('bodymap').width, "
                         "document.getElementById('bodymap').height]")

    def on_map(x, y):
        return box['x'] + x * box['width'] / w, box['y'] + y * box['height'] / h
    points = [on_map(75, y) for y in (110, 130, 150, 170, 190, 210)]
    assert stroke(rig, page, points, rig.touch['body']) is not None, \
        'stroking the body map did not touch the body sensor'
    assert rig.until(lambda: page.evaluate('miroGui.state.readouts.touch_body') == 0), \
        'the touch went on after the stroke'
    page.close()
    assert not rig.errors


def test_speed_menu_sets_the_simulators_real_time_factor_and_tones_are_heard(rig):
    page = rig.open_page()
    assert page.locator('#readtable .mark').count() == 2, 'the battery marks at 4.6 and 4.8 V'
    page.select_option('#rtf_set', '2')
    assert rig.until(lambda: rig.sim.get_parameter('real_time_factor').value == 2.0)
    rig.sim.set_parameters([Parameter('real_time_factor', value=1.0)])
    page.locator('#sound').click()  # a click: browsers let a page make sound after one
    page.locator('#hearing summary').click()
    page.locator('#listen').check()
    page.locator('#tone_play').click()
    assert rig.until(lambda: page.evaluate(
        'miroGui.tones.some((t) => t.played && t.hz === 440 && t.ticks === 50)')), \
        'the tone MiRo was asked to play was not played in the page'
    # Played through the simulation: MiRo's own microphones hear it, the page shows their
    # levels and the tone's band in the spectrum, and plays what the left ear hears.
    assert rig.until(lambda: min(page.evaluate('miroGui.mics ? miroGui.mics.levels : [-100]'))
                     > -40), 'the tone was not heard by the microphones shown in the page'
    spectrum = page.evaluate('miroGui.mics.spectrum')
    top = page.evaluate('miroGui.mics.top_hz')
    assert abs((spectrum.index(max(spectrum)) + 0.5) * top / len(spectrum) - 440) < top / 64
    assert rig.until(lambda: page.evaluate(
        "miroGui.audio.some((a) => a.played && a.source === 'mic' && a.rate === 20000)"))
    page.close()
    assert not rig.errors


def test_a_click_in_the_world_view_places_a_sound_and_a_click_on_it_stops_it(rig):
    page = world_page(rig)
    page.select_option('#world_mode', 'sound')
    acoustics = rig.sim.sim.acoustics
    x, y = screen(page, (0.5, 0.5, 0.0))
    page.mouse.click(x, y)
    assert rig.until(lambda: acoustics.sounds), 'no sound placed in the simulator'
    (name, (_, source)), = acoustics.sounds.items()
    assert math.dist(source.position[:2], (0.5, 0.5)) < 0.05
    assert rig.until(lambda: page.evaluate(
        "[...miroGui.world.markers.values()].some(({ data }) => data.ns === 'sound')"))
    redrawn(rig, page)
    x, y = screen(page, tuple(source.position))
    page.mouse.click(x, y)
    assert rig.until(lambda: not acoustics.sounds), f'{name} still plays'
    page.close()
    assert not rig.errors


def test_demo_mode_is_started_watched_and_stopped_from_the_page(rig, tmp_path):
    """The demo mode panel: its button runs miro_animal for the page's robot; the page shows the
    selected action, every action's priority, the affect and sleep, and the attention map
    over the eyes; the other button stops it."""
    page = rig.open_page()
    page.locator('#demo summary').click()
    page.locator('#demo_start').click()
    actions = page.evaluate('miroGui.config.actions')
    assert 'approach' in actions and 'mull' in actions

    def shown():
        # Demo mode stamps an overlay with the frame it was made of once it has seen a
        # frame; before that (a loaded machine: the first few), with its own tick's time.
        return page.evaluate("""() => {
          const d = miroGui.demo, o = miroGui.overlaid || [];
          return !!(d && d.state && Array.isArray(d.priorities) && d.action
                    && (miroGui.demoOverlays || 0) > 2 && o.length
                    && Math.abs(o[o.length - 1].stamp - o[o.length - 1].frame) < 1e-6);
        }""")
    assert rig.until(shown, wall_guard_s=90.0), (page.evaluate('miroGui.state.status'),
                                                 page.evaluate('miroGui.overlaid'))
    # Each overlay on its frame or a later one: none from before the picture, none from later
    # than its next frame (three frame periods at most, if the GUI skipped some).
    overlaid = page.evaluate('miroGui.overlaid')
    assert overlaid and all(0 <= o['stamp'] - o['frame'] < 3 / 15 for o in overlaid), overlaid
    assert page.locator('#demo_action').inner_text() in actions
    assert ROBOT in page.evaluate('miroGui.state.demo_running')
    assert 0.0 <= float(page.locator('#demo_wake').inner_text()) <= 1.0
    page.screenshot(path=str(tmp_path / 'demo_panel.png'), full_page=True)
    page.locator('#demo_stop').click()
    assert rig.until(lambda: not page.evaluate('miroGui.state.demo_running'))
    page.close()
    assert not rig.errors
