"""The GUI in a real headless Chromium, driving the simulator in this process.

miro_gui runs as a child process (as a user starts it) on the test's ROS domain;
the simulator is in-process and paused, stepped here tick by tick, so every
"within 0.5 s" is simulated time. Where the GUI's own timing matters (a key held
or released, a page closed), the world is stepped no faster than real time, as a
simulator runs for a user. One simulator, GUI and browser serve all the tests of
this file; each test opens its own page.
"""
import http.client
import os
import shutil
import sys
import time

import pytest
from rclpy.parameter import Parameter

from miro_ball.common.isolation import isolated_env
from miro_ball.gui.process import GuiProcess
from miro_ball.miro.interface import RobotTopics, default_robot_name

playwright_api = pytest.importorskip('playwright.sync_api')
CHROMIUM = shutil.which('chromium') or '/usr/bin/chromium'
if not os.path.exists(CHROMIUM):
    pytest.skip("Debian's chromium is not installed (./dev.sh installs it as root)",
                allow_module_level=True)

T = RobotTopics(default_robot_name())
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
        from nav_msgs.msg import Odometry
        from sensor_msgs.msg import JointState
        from std_msgs.msg import Float32MultiArray
        self.odom = probe.watch(Odometry, T.odom)
        self.joints = probe.watch(JointState, T.kinematic_joints)
        self.wheels = probe.watch(Float32MultiArray, T.wheel_speed_cmd)
        self.errors = []

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
        page.on('pageerror', lambda err: self.errors.append(str(err)))
        page.on('console', lambda msg: msg.type == 'error' and self.errors.append(msg.text))
        page.goto(self.url)
        assert self.until(lambda: frames(page, 'caml') > 0 and frames(page, 'camr') > 0), \
            'no eye images reached the page'
        return page

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


def test_arrow_key_drives_forward_and_release_stops_within_half_a_second(rig):
    page = rig.open_page()
    start_x = rig.odom[-1].pose.pose.position.x
    page.keyboard.down('ArrowUp')
    assert rig.until(rig.moving), 'holding ArrowUp did not drive the wheels'
    rig.run(1.0)  # longer than the GUI's deadman: the page renews the command
    assert rig.moving(), 'the drive did not last while the key was held'
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
