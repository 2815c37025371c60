"""The GUI's web side (aiohttp): the page's files, and one WebSocket per page.

Each page gets the newest frame of each image channel, one at a time: the next
frame of a channel goes out only when the page says it has drawn the last one
(or after ACK_TIMEOUT_S), so a slow page gets fewer frames, never older ones,
and nothing queues up. Readouts go out at the bridge's rate. The page's commands
come in on the same socket, in the other direction, so they never wait behind
images; each is checked (protocol.py) and handed to the bridge.
"""
import asyncio
import ipaddress
import itertools
import json
import socket
import time
from pathlib import Path
from urllib.parse import urlsplit

from aiohttp import WSMsgType, web

from miro_ball.common.throttle import Throttled
from miro_ball.gui import protocol

STATIC = Path(__file__).parent / 'static'
ACK_TIMEOUT_S = 1.0  # a frame the page never acknowledged does not block its channel
STATE_PERIOD_S = 0.05
MAX_MESSAGE_BYTES = 1 << 20  # beyond this aiohttp closes that socket; below, parse() refuses
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

    def __init__(self, ws, number):
        self.ws = ws
        self.number = number
        self.wake = asyncio.Event()
        self.sent = {}  # channel: seq of the last frame sent
        self.in_flight = {}  # channel: when the unacknowledged frame went out
        self.state_sent = 0.0


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
        self.app = web.Application(middlewares=[self._guard])
        self.app.add_routes([web.get('/', self._index), web.get('/ws', self._websocket),
                             web.static('/static', STATIC)])
        self.app.on_startup.append(self._started)
        self.app.on_shutdown.append(self._closing)

    async def _started(self, app):
        self.loop = asyncio.get_running_loop()
        self.ticker = asyncio.create_task(self._tick())

    async def _closing(self, app):
        self.ticker.cancel()
        for page in list(self.pages.values()):
            await page.ws.close()

    def frame_arrived(self, channel):
        """Called from the ROS thread for every new image."""
        if self.loop is not None:
            self.loop.call_soon_threadsafe(self._wake_all)

    def _wake_all(self):
        for page in self.pages.values():
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

    async def _websocket(self, request):
        origin = request.headers.get('Origin')
        if not origin_allowed(origin, request.host, self.loopback_only):
            self.warn('origin', f'refused a WebSocket from origin {origin!r:.80}')
            raise web.HTTPForbidden(text='foreign origin')
        ws = web.WebSocketResponse(max_msg_size=MAX_MESSAGE_BYTES, compress=False,
                                   heartbeat=2.0)
        await ws.prepare(request)
        page = Page(ws, next(self.numbers))
        self.pages[page.number] = page
        self.log(f'page {page.number} connected from {request.remote} '
                 f'({len(self.pages)} open)')
        await ws.send_str(json.dumps(protocol.page_config()))
        sender = asyncio.create_task(self._send(page))
        try:
            await self._receive(page)
        finally:
            sender.cancel()
            del self.pages[page.number]
            self.bridge.release(page.number)
            self.log(f'page {page.number} closed ({len(self.pages)} open)')
        return ws

    async def _receive(self, page):
        async for msg in page.ws:
            if msg.type != WSMsgType.TEXT:
                self.warn('binary', f'page {page.number}: a non-text message ignored')
                continue
            try:
                command, clamped = protocol.parse(msg.data)
            except protocol.Rejected as err:
                self.warn(f'bad:{page.number}', f'page {page.number}: message ignored: {err}')
                continue
            if clamped:
                self.warn(f'clamp:{page.number}', f'page {page.number}: '
                          f'{", ".join(sorted(set(clamped)))} out of range: clamped')
            if isinstance(command, protocol.Ack):
                page.in_flight.pop(command.channel, None)
                page.wake.set()
            else:
                self.bridge.submit(command, page.number)

    async def _send(self, page):
        ws = page.ws
        try:
            while not ws.closed:
                await page.wake.wait()
                page.wake.clear()
                now = time.monotonic()
                for channel, frame in self.bridge.frames().items():
                    sent_at = page.in_flight.get(channel)
                    if page.sent.get(channel) == frame.seq or (
                            sent_at is not None and now - sent_at < ACK_TIMEOUT_S):
                        continue
                    page.sent[channel] = frame.seq
                    page.in_flight[channel] = now
                    await ws.send_bytes(protocol.frame_message(channel, frame.stamp, frame.jpeg))
                if now - page.state_sent >= STATE_PERIOD_S * 0.9:
                    page.state_sent = now
                    await ws.send_str(self.bridge.state())
        except (ConnectionError, RuntimeError):
            pass  # the page went away; _receive ends too


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
    runner = web.AppRunner(server.app, handle_signals=False, access_log=None)
    await runner.setup()
    try:
        await web.SockSite(runner, sock).start()
        while not stop.requested:
            await asyncio.sleep(0.1)
    finally:
        await runner.cleanup()
