"""The GUI's web side (aiohttp): the page's files, and one WebSocket per page.

Each page gets the newest frame of each image channel of its robot, one at a time:
the next frame of a channel goes out only when the page says it has drawn the last
one (or after ACK_TIMEOUT_S), so a slow page gets fewer frames, never older ones,
and nothing queues up. Readouts go out at the bridge's rate; while the page shows
the world view, the scene's and the link frames' changes at most WORLD_RATE_HZ (the
whole of them when it turns the view on); the pictures' PNGs are fetched at
/texture/<key>.png. The page's commands come in on the same socket, in the other
direction, so they never wait behind images; each is checked (protocol.py) and
handed to the bridge; a drag's places at most PLACE_RATE_HZ, the newest winning.
"""
import asyncio
import collections
import ipaddress
import itertools
import json
import logging
import re
import socket
import time
import traceback
from pathlib import Path
from urllib.parse import urlsplit

from aiohttp import WSMsgType, web

from miro_ball.common.throttle import Throttled
from miro_ball.gui import protocol

STATIC = Path(__file__).parent / 'static'
ACK_TIMEOUT_S = 1.0  # a frame the page never acknowledged does not block its channel
STATE_PERIOD_S = 0.05
WORLD_RATE_HZ = 30.0  # scene and frame changes to a page
PLACE_RATE_HZ = 30.0  # a dragged object's places to the simulator, per page
OUTBOX_LENGTH = 50  # events (tones) waiting for a slow page; the oldest go first
TEXTURE_PATH = re.compile(r'([A-Za-z0-9_][A-Za-z0-9_.-]{0,99})\.png\Z')
MAX_MESSAGE_BYTES = 1 << 20  # beyond this aiohttp closes that socket; below, parse() refuses
# How long a page has to take its close as the GUI stops, and the server's requests to end:
# aiohttp waited for ever on a page that had stopped reading (a busy browser's), and the
# GUI's stop with it, deaf to SIGINT and SIGTERM. Such a page is cut off.
CLOSE_S = 0.5
LOOPBACK_NAMES = ('localhost',)
HEADERS = {
    'Cache-Control': 'no-cache',
    'X-Frame-Options': 'DENY',  # no other site can frame the controls
    'Content-Security-Policy': "default-src 'self'; img-src 'self' blob: data:; "
                               "connect-src 'self'; frame-ancestors 'none'",
}


def is_loopback(host):
    if host in LOOPBACK_NAMES:
        return True
    try:
        return ipaddress.ip_address(host.strip('[]')).is_loopback
    except ValueError:
        return False


def _hostname(netloc):
    return urlsplit('//' + netloc).hostname or ''


def origin_allowed(origin, host_header, loopback_only):
    """Whether a WebSocket from a page of ``origin`` may connect.

    Only the page this server serves may: the Origin must name the host and port the
    request was sent to. Listening on loopback, that host must be a loopback name too,
    so a foreign site that rebinds its DNS name to 127.0.0.1 is refused as well.
    Programs that are not browsers send no Origin and are let in.
    """
    if origin is None:
        return True
    parts = urlsplit(origin)
    if parts.scheme not in ('http', 'https') or parts.netloc != host_header:
        return False
    return not loopback_only or is_loopback(_hostname(host_header))


class Page:
    """One connected page: its socket and what it has been sent."""

    def __init__(self, ws, number, transport):
        self.ws = ws
        self.number = number
        self.transport = transport  # its connection, to cut it off (CLOSE_S)
        self.wake = asyncio.Event()
        self.sent = {}  # channel: seq of the last frame sent
        self.in_flight = {}  # channel: when the unacknowledged frame went out
        self.overlaid = {}  # channel: (frame seq, overlay stamp) of the last overlay sent
        self.state_sent = 0.0
        self.outbox = collections.deque(maxlen=OUTBOX_LENGTH)  # JSON texts
        self.world = False  # it shows the world view
        self.scene_seq = self.tf_seq = None  # what of the world it has (None: nothing)
        self.world_sent = 0.0
        self.place = None  # the newest place of a drag not yet forwarded
        self.place_sent = 0.0
        self.place_timer = None


class _HttpLog(logging.Handler):
    """aiohttp's word on a request it could not handle (a bad request line, a header too
    long...): one throttled line without the traceback; the client got its error answer."""

    def __init__(self, warn):
        super().__init__(logging.INFO)  # its debug lines stay out
        self.warn = warn

    def emit(self, record):
        exc = record.exc_info[1] if record.exc_info else None
        why = f': {type(exc).__name__} {str(exc).strip()[:100]!r}' if exc else ''
        self.warn('http', f'{record.getMessage()[:100]}{why}')


def http_logger(warn):
    """The logger the web server's connections report their errors to (see _HttpLog)."""
    logger = logging.Logger('miro_gui.http')  # not in logging's tree: nothing propagates
    logger.addHandler(_HttpLog(warn))
    return logger


class GuiServer:
    """The aiohttp application around a bridge (bridge.GuiBridge or anything like it)."""

    def __init__(self, bridge, loopback_only=True, log=print, warn=print):
        self.bridge = bridge
        self.loopback_only = loopback_only
        self.log = log
        self.warn = Throttled(warn)
        self.pages = {}
        self.numbers = itertools.count(1)
        self.loop = None
        self.http_logger = http_logger(self.warn)
        self.app = web.Application(middlewares=[self._guard])
        self.app.add_routes([web.get('/', self._index), web.get('/ws', self._websocket),
                             web.get('/texture/{name}', self._texture),
                             web.static('/static', STATIC)])
        self.app.on_startup.append(self._started)
        self.app.on_shutdown.append(self._closing)

    async def _started(self, app):
        self.loop = asyncio.get_running_loop()
        self.ticker = asyncio.create_task(self._tick())

    async def _closing(self, app):
        self.ticker.cancel()
        await asyncio.gather(*(self._close(page) for page in list(self.pages.values())))

    @staticmethod
    async def _close(page):
        try:
            await asyncio.wait_for(page.ws.close(), CLOSE_S)
        except asyncio.TimeoutError:
            if page.transport is not None:  # None: the connection is gone already
                page.transport.abort()

    def frame_arrived(self, channel):
        """Called from the ROS thread for every new image."""
        if self.loop is not None:
            self.loop.call_soon_threadsafe(self._wake_all)

    def _wake_all(self):
        for page in self.pages.values():
            page.wake.set()

    def event(self, owners, text):
        """Called from the ROS thread: a JSON message for these pages (a tone)."""
        if self.loop is not None:
            self.loop.call_soon_threadsafe(self._deliver, owners, text)

    def _deliver(self, owners, text):
        for owner in owners:
            page = self.pages.get(owner)
            if page is not None:
                page.outbox.append(text)
                page.wake.set()

    async def _tick(self):
        while True:
            await asyncio.sleep(STATE_PERIOD_S)
            self._wake_all()

    @web.middleware
    async def _guard(self, request, handler):
        host = _hostname(request.host)
        if self.loopback_only and not is_loopback(host):
            self.warn('host', f'refused a request for host {request.host!r} (DNS rebinding?)')
            raise web.HTTPForbidden(text='this server answers only for localhost')
        response = await handler(request)
        response.headers.update(HEADERS)
        return response

    async def _index(self, request):
        return web.FileResponse(STATIC / 'index.html')

    async def _texture(self, request):
        match = TEXTURE_PATH.match(request.match_info['name'])
        data = self.bridge.texture(match.group(1)) if match else None
        if data is None:
            raise web.HTTPNotFound(text='no such picture in the scene')
        return web.Response(body=data, content_type='image/png')

    async def _websocket(self, request):
        origin = request.headers.get('Origin')
        if not origin_allowed(origin, request.host, self.loopback_only):
            self.warn('origin', f'refused a WebSocket from origin {origin!r:.80}')
            raise web.HTTPForbidden(text='foreign origin')
        ws = web.WebSocketResponse(max_msg_size=MAX_MESSAGE_BYTES, compress=False,
                                   heartbeat=2.0)
        await ws.prepare(request)
        page = Page(ws, next(self.numbers), request.transport)
        self.pages[page.number] = page
        self.bridge.open(page.number)
        self.log(f'page {page.number} connected from {request.remote} '
                 f'({len(self.pages)} open)')
        await ws.send_str(json.dumps(protocol.page_config()))
        sender = asyncio.create_task(self._send(page))
        try:
            await self._receive(page)
        finally:
            sender.cancel()
            if page.place_timer is not None:
                page.place_timer.cancel()
            del self.pages[page.number]
            self.bridge.release(page.number)
            self.log(f'page {page.number} closed ({len(self.pages)} open)')
        return ws

    async def _receive(self, page):
        async for msg in page.ws:
            if msg.type == WSMsgType.ERROR:  # aiohttp's word for a message past the limit too
                error = str(page.ws.exception() or 'a broken message')[:150]
                self.warn('ws_error', f'page {page.number}: its socket is closed: {error} '
                          f'(a message may be at most {MAX_MESSAGE_BYTES} bytes)')
                continue
            if msg.type != WSMsgType.TEXT:
                self.warn('binary', f'page {page.number}: a {msg.type.name.lower()} message '
                          'ignored: pages send text (JSON)')
                continue
            try:
                command, clamped = protocol.parse(msg.data)
            except protocol.Rejected as err:
                self.warn(f'bad:{page.number}', f'page {page.number}: message ignored: {err}')
                continue
            except Exception:  # noqa: BLE001 -- a gap in the checks must not end the page
                self.warn(f'bad:{page.number}', f'page {page.number}: message ignored, the '
                          f'checks of gui/protocol.py let it through and then failed on it '
                          f'(please report): {msg.data[:200]!r}\n{traceback.format_exc()}')
                continue
            if clamped:
                self.warn(f'clamp:{page.number}', f'page {page.number}: '
                          f'{", ".join(sorted(set(clamped)))} out of range: clamped')
            self._take(page, command)

    def _take(self, page, command):
        if isinstance(command, protocol.Ack):
            page.in_flight.pop(command.channel, None)
            page.wake.set()
            return
        if isinstance(command, protocol.Place):
            page.place = command
            self._forward_place(page)
            return
        if isinstance(command, protocol.View):
            if command.world and not page.world:
                page.scene_seq = page.tf_seq = None  # the whole world first
            page.world = command.world
            page.wake.set()
        self.bridge.submit(command, page.number)

    def _forward_place(self, page):
        """A drag sends places as fast as the mouse moves: forward the newest, at most
        PLACE_RATE_HZ."""
        if page.place is None or page.number not in self.pages:
            return
        wait = page.place_sent + 1.0 / PLACE_RATE_HZ - time.monotonic()
        if wait > 0:
            if page.place_timer is None:
                page.place_timer = self.loop.call_later(wait, self._place_due, page)
            return
        page.place_sent = time.monotonic()
        self.bridge.submit(page.place, page.number)
        page.place = None

    def _place_due(self, page):
        page.place_timer = None
        self._forward_place(page)

    async def _send(self, page):
        ws = page.ws
        try:
            while not ws.closed:
                await page.wake.wait()
                page.wake.clear()
                now = time.monotonic()
                state_due = now - page.state_sent >= STATE_PERIOD_S * 0.9
                for channel, frame in self.bridge.frames(page.number).items():
                    sent_at = page.in_flight.get(channel)
                    if page.sent.get(channel) == frame.seq:
                        if state_due:  # a later overlay of the frame the page has
                            await self._send_overlay(page, channel, frame)
                        continue
                    if sent_at is not None and now - sent_at < ACK_TIMEOUT_S:
                        continue
                    page.sent[channel] = frame.seq
                    page.in_flight[channel] = now
                    await self._send_overlay(page, channel, frame)
                    await ws.send_bytes(protocol.frame_message(channel, frame.stamp, frame.jpeg))
                while page.outbox:
                    await ws.send_str(page.outbox.popleft())
                if page.world and now - page.world_sent >= 0.9 / WORLD_RATE_HZ:
                    await self._send_world(page, now)
                if state_due:
                    page.state_sent = now
                    await ws.send_str(self.bridge.state(page.number))
        except (ConnectionError, RuntimeError):
            pass  # the page went away; _receive ends too

    async def _send_overlay(self, page, channel, frame):
        """Demo mode's overlay of the frame, unless the page has it already."""
        paired = self.bridge.overlay(page.number, channel, frame)
        if paired is not None and page.overlaid.get(channel) != (frame.seq, paired[0]):
            page.overlaid[channel] = (frame.seq, paired[0])
            await page.ws.send_str(protocol.overlay_message(channel, frame.stamp, paired))

    async def _send_world(self, page, now):
        """The scene's and the frames' changes since the page last heard."""
        scene, seq = self.bridge.scene_message(page.scene_seq)
        if scene is not None:
            await page.ws.send_str(scene)
        page.scene_seq = seq
        frames, seq = self.bridge.tf_message(page.tf_seq)
        if frames is not None:
            await page.ws.send_str(frames)
        page.tf_seq = seq
        page.world_sent = now


def listen(host, port):
    """The listening socket (port 0: any free port), or OSError saying why not."""
    family = socket.AF_INET6 if ':' in host else socket.AF_INET
    return socket.create_server((host, port), family=family)


def url(sock):
    host, port = sock.getsockname()[:2]
    if ipaddress.ip_address(host).is_unspecified:  # every address: name one that works
        host = socket.gethostname()
    return f'http://[{host}]:{port}/' if ':' in host else f'http://{host}:{port}/'


async def serve(server, sock, stop):
    """Serve on the socket until stop.requested."""
    runner = web.AppRunner(server.app, handle_signals=False, access_log=None,
                           logger=server.http_logger, shutdown_timeout=CLOSE_S)
    await runner.setup()
    try:
        await web.SockSite(runner, sock).start()
        while not stop.requested:
            await asyncio.sleep(0.1)
    finally:
        await runner.cleanup()
