"""The door in front of the Foxglove SDK's WebSocket server: only the pages it should let in.

A browser lets any web page open a WebSocket to 127.0.0.1, and says which page did in the
Origin header; the SDK's server (0.30) looks at no header. So the server listens where
nobody is told (a random address of 127.0.0.0/8 and a free port: one in about 10^12 to
guess), and this door listens where the user asked. It reads each connection's HTTP
request, refuses one whose Origin is not allowed (403 and one log line), and pipes the rest
through untouched. No Origin at all is a program, not a page (a browser always sends one):
let in. Allowed by default: the Foxglove app (https://app.foxglove.dev) and pages served by
this machine (localhost, 127.0.0.1, [::1]); ``--allow-origin`` adds more (fnmatch patterns).
A client that does not offer the one WebSocket subprotocol the SDK's server speaks is told
which that is (the server answered 400 'Missing expected sec-websocket-protocol header' and
logged only 'handshake failed').
"""
import asyncio
import fnmatch
import secrets
import threading
from urllib.parse import urlsplit

FOXGLOVE_APP = 'https://app.foxglove.dev'
LOCAL_HOSTS = ('localhost', '127.0.0.1', '::1')
MAX_HEAD_BYTES = 16384  # an HTTP upgrade request is a few hundred bytes
HEAD_TIMEOUT_S = 5.0  # a connection that sends no request in this long is closed
MAX_CONNECTIONS = 64
PIPE_CHUNK = 1 << 16
FORBIDDEN = b'HTTP/1.1 403 Forbidden\r\nContent-Length: 0\r\nConnection: close\r\n\r\n'
# Not a WebSocket request (a page's <img> or no-cors fetch sends no Origin): answered here,
# never passed on (the SDK's server logged a line for each, unthrottled).
BAD_REQUEST = b'HTTP/1.1 400 Bad Request\r\nContent-Length: 0\r\nConnection: close\r\n\r\n'
SUBPROTOCOL = 'foxglove.sdk.v1'  # the only one the SDK's server (0.30) accepts


def subprotocol_refusal(offered):
    """Why a WebSocket request offering these subprotocols (the Sec-WebSocket-Protocol
    header; None: none) cannot be served, in one line; None if it can."""
    names = [name.strip() for name in (offered or '').split(',') if name.strip()]
    if SUBPROTOCOL in names:
        return None
    asked = ('asked for subprotocol ' + ', '.join(repr(n[:60]) for n in names[:4]) if names
             else 'offered no subprotocol')
    return (f'a Foxglove client {asked}; this bridge serves {SUBPROTOCOL!r} only (the Foxglove '
            'SDK\'s protocol): use a client that offers it, such as the Foxglove app')


def bad_request(text):
    """An HTTP 400 answer whose body says why."""
    body = text.encode() + b'\n'
    return (b'HTTP/1.1 400 Bad Request\r\nContent-Type: text/plain; charset=utf-8\r\n'
            b'Content-Length: %d\r\nConnection: close\r\n\r\n' % len(body)) + body


def origin_allowed(origin, patterns=()):
    """Whether a WebSocket request with this Origin header (None: none sent) may connect."""
    if origin is None:
        return True
    origin = origin.strip().lower()
    if origin == FOXGLOVE_APP or any(fnmatch.fnmatchcase(origin, p.lower()) for p in patterns):
        return True
    try:
        parts = urlsplit(origin)
        host = parts.hostname
    except ValueError:
        return False
    return parts.scheme in ('http', 'https') and host in LOCAL_HOSTS


def header(head, name):
    """The value of header ``name`` in an HTTP request's head (bytes), or None."""
    for line in head.split(b'\r\n')[1:]:
        key, sep, value = line.partition(b':')
        if sep and key.strip().lower() == name.encode():
            return value.strip().decode('latin-1')
    return None


def hidden_address():
    """A random loopback address other than 127.0.0.1, where nobody looks."""
    return f'127.{secrets.randbelow(256)}.{secrets.randbelow(256)}.{2 + secrets.randbelow(253)}'


class OriginGate:
    """Listens on (host, port) (port 0: any free one, then ``self.port``) and lets through
    to ``upstream`` (host, port) the connections origin_allowed lets in; ``warn(key,
    message)`` says a refusal (rate-limited by the caller). Its own thread; OSError when the
    port is taken."""

    def __init__(self, host, port, upstream, patterns=(), warn=print):
        self.upstream, self.patterns, self.warn = upstream, tuple(patterns), warn
        self.refused = 0
        self._open = 0
        self._loop = asyncio.new_event_loop()
        try:
            self._server = self._loop.run_until_complete(asyncio.start_server(
                self._serve, host, port, limit=MAX_HEAD_BYTES))
        except OSError:
            self._loop.close()
            raise
        self.port = self._server.sockets[0].getsockname()[1]
        self._thread = threading.Thread(target=self._loop.run_forever, name='foxglove-gate',
                                        daemon=True)
        self._thread.start()

    def close(self):
        """Stop listening and end every connection (their tasks first: a task left in a
        stopped loop printed 'Event loop is closed' tracebacks at exit)."""
        async def stop():
            self._server.close()
            tasks = [t for t in asyncio.all_tasks() if t is not asyncio.current_task()]
            for task in tasks:
                task.cancel()
            await asyncio.gather(*tasks, return_exceptions=True)
            self._loop.stop()
        if self._thread.is_alive():
            asyncio.run_coroutine_threadsafe(stop(), self._loop)
            self._thread.join(timeout=2.0)

    async def _serve(self, reader, writer):
        if self._open >= MAX_CONNECTIONS:
            self.warn('gate_full', f'a connection refused: {MAX_CONNECTIONS} are open')
            writer.close()
            return
        self._open += 1
        try:
            head = await asyncio.wait_for(reader.readuntil(b'\r\n\r\n'), HEAD_TIMEOUT_S)
            if (header(head, 'upgrade') or '').lower() != 'websocket':
                writer.write(BAD_REQUEST)
                await writer.drain()
                return
            origin = header(head, 'origin')
            if not origin_allowed(origin, self.patterns):
                self.refused += 1
                self.warn('origin', f'a WebSocket from the page {origin[:100]!r} refused: only '
                          'the Foxglove app and pages of this machine may connect '
                          '(--allow-origin adds one)')
                writer.write(FORBIDDEN)
                await writer.drain()
                return
            refusal = subprotocol_refusal(header(head, 'sec-websocket-protocol'))
            if refusal:
                self.warn('subprotocol', refusal)
                writer.write(bad_request(refusal))
                await writer.drain()
                return
            up_reader, up_writer = await asyncio.open_connection(*self.upstream)
            up_writer.write(head)
            await asyncio.gather(_pipe(reader, up_writer), _pipe(up_reader, writer))
        except (asyncio.IncompleteReadError, asyncio.LimitOverrunError, OSError):
            pass  # a client that went, or sent no request: nothing to say
        finally:
            self._open -= 1
            writer.close()


async def _pipe(reader, writer):
    try:
        while data := await reader.read(PIPE_CHUNK):
            writer.write(data)
            await writer.drain()
    except OSError:
        pass
    finally:
        writer.close()
