"""A WebSocket subprotocol-rewriting proxy in front of the live view's Foxglove server.

foxglove-sdk (0.30) accepts only the subprotocol ``foxglove.sdk.v1`` (its handshake answers HTTP
400 to anything else; the name is a constant of its Rust server, with no option to add one).
Foxglove's own app offers that name, but clients of the classic name ``foxglove.websocket.v1``
(Foxglove Studio up to 1.87, Lichtblick before its December 2025 release, the
``@foxglove/ws-protocol`` client library) cannot connect. The two names are one protocol (the
SDK's maintainers say so, and Lichtblick's and Flora's support for the new name is just the name
added), so this proxy listens where the user asked, and for a client that offers the classic
name only it rewrites the offer to the SDK's name on the way in and the server's choice back to
the classic name on the way out; everything after the handshake passes through as bytes. A
client that offers the SDK's name is passed through untouched. The SDK listens on an ephemeral
port of 127.0.0.1 only, whatever address the proxy binds.

Threads, not asyncio: one accepting thread and one thread per client, each moving bytes between
its two sockets; `close` shuts every socket down. ROS-free.
"""

from __future__ import annotations

import selectors
import socket
import threading

CLASSIC = "foxglove.websocket.v1"
"""The subprotocol name of the Foxglove WebSocket protocol up to foxglove-sdk (ws-protocol)."""
SDK = "foxglove.sdk.v1"
"""The name foxglove-sdk accepts (the same protocol)."""
MAX_HEAD = 16 * 1024
"""Bytes an HTTP upgrade request or response head may take."""
HEAD_TIMEOUT = 10.0
"""Wall seconds a client has to send its upgrade request."""
_PROTOCOL = b"sec-websocket-protocol"


def _read_head(sock: socket.socket) -> tuple[bytes, bytes]:
    """(head up to and including the blank line, bytes read past it); ValueError if it does not end."""
    data = b""
    while b"\r\n\r\n" not in data:
        chunk = sock.recv(4096)
        if not chunk or len(data) + len(chunk) > MAX_HEAD:
            raise ValueError("no complete HTTP head")
        data += chunk
    end = data.index(b"\r\n\r\n") + 4
    return data[:end], data[end:]


def _offered(head: bytes) -> list[str]:
    """The subprotocols a head names (every Sec-WebSocket-Protocol line, comma-separated)."""
    out = []
    for line in head.split(b"\r\n")[1:]:
        name, _, value = line.partition(b":")
        if name.strip().lower() == _PROTOCOL:
            out += [v.strip() for v in value.decode("latin-1").split(",") if v.strip()]
    return out


def _with_protocol(head: bytes, protocol: str) -> bytes:
    """`head` with its Sec-WebSocket-Protocol lines replaced by one naming `protocol`."""
    lines = head[:-4].split(b"\r\n")
    kept = [line for line in lines if line.partition(b":")[0].strip().lower() != _PROTOCOL]
    return b"\r\n".join([*kept, b"Sec-WebSocket-Protocol: " + protocol.encode()]) + b"\r\n\r\n"


def rewrite_request(head: bytes) -> tuple[bytes, bool]:
    """(the head to send the SDK, whether its answer must name the classic subprotocol): a head
    offering the classic name but not the SDK's is rewritten to offer the SDK's."""
    offered = _offered(head)
    if CLASSIC in offered and SDK not in offered:
        return _with_protocol(head, SDK), True
    return head, False


def rewrite_response(head: bytes) -> bytes:
    """The SDK's answer to a rewritten offer, naming the classic subprotocol the client offered."""
    return _with_protocol(head, CLASSIC) if SDK in _offered(head) else head


class SubprotocolProxy:
    """Listens on (`host`, `port`) (0: any free port) at once, so a busy port is known before
    anything else starts; serves once `start(upstream_port)` is called."""

    def __init__(self, host: str, port: int) -> None:
        family = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM)[0][0]
        self._listener = socket.create_server((host, port), family=family, backlog=16)
        self.host = host
        self.port: int = self._listener.getsockname()[1]
        self._upstream = 0
        self._open: set[socket.socket] = set()
        self._lock = threading.Lock()
        self._closed = False

    def start(self, upstream_port: int) -> None:
        """Proxy every client to the server on 127.0.0.1:`upstream_port`."""
        self._upstream = upstream_port
        threading.Thread(target=self._accept, name="live-view-proxy", daemon=True).start()

    def _accept(self) -> None:
        while not self._closed:
            try:
                client, _ = self._listener.accept()
            except OSError:
                return  # closed
            threading.Thread(target=self._serve, args=(client,), name="live-view-client", daemon=True).start()

    def _track(self, *socks: socket.socket) -> bool:
        with self._lock:
            if self._closed:
                return False
            self._open.update(socks)
            return True

    def _serve(self, client: socket.socket) -> None:
        upstream = None
        try:
            client.settimeout(HEAD_TIMEOUT)
            head, rest = _read_head(client)
            head, classic = rewrite_request(head)
            upstream = socket.create_connection(("127.0.0.1", self._upstream), timeout=HEAD_TIMEOUT)
            if not self._track(client, upstream):
                return
            upstream.sendall(head + rest)
            answer, rest = _read_head(upstream)
            client.sendall((rewrite_response(answer) if classic else answer) + rest)
            client.settimeout(None)
            upstream.settimeout(None)
            self._pump(client, upstream)
        except (OSError, ValueError):
            pass  # a client that went away or spoke no HTTP: nothing to keep
        finally:
            for s in (client, upstream):
                if s is not None:
                    with self._lock:
                        self._open.discard(s)
                    s.close()

    @staticmethod
    def _pump(a: socket.socket, b: socket.socket) -> None:
        """Bytes both ways until either side closes."""
        other = {a: b, b: a}
        with selectors.DefaultSelector() as sel:
            sel.register(a, selectors.EVENT_READ)
            sel.register(b, selectors.EVENT_READ)
            while True:
                for key, _ in sel.select():
                    data = key.fileobj.recv(65536)
                    if not data:
                        return
                    other[key.fileobj].sendall(data)

    def close(self) -> None:
        """Stop listening and end every connection (idempotent)."""
        with self._lock:
            self._closed = True
            socks, self._open = list(self._open), set()
        self._listener.close()
        for s in socks:
            try:
                s.shutdown(socket.SHUT_RDWR)
            except OSError:
                pass


def check_port(host: str, port: int) -> str | None:
    """Why a live view could not listen on (`host`, `port`), or None if it can (now)."""
    try:
        family = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM)[0][0]
        socket.create_server((host, port), family=family).close()
    except OSError as exc:
        return exc.strerror or str(exc)
    return None
