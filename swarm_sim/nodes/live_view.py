"""The live view: the run's topics served over the Foxglove WebSocket protocol (``swarm-run --foxglove``).

The official `foxglove-sdk` server runs inside the world node, beside the recorder, and is fed
exactly what the recorder writes: the CDR bytes already on the wire (schema encoding ``ros2msg``
with the same message definitions as the bag, message encoding ``cdr``), stamped with sim time.
Nothing is serialised twice, and what Foxglove shows live is what the bag will hold: markers,
odometry, scans, depot and center state, events, statuses. The server advertises the Time
capability and broadcasts the sim clock, so Foxglove's timeline follows sim time. A client that
subscribes to a latched topic (state, markers) is sent its last message at once, as a
transient-local DDS subscriber would be. No rclpy here: the recorder calls `add` and `write`.

Clients connect to a `swarm_sim.nodes.ws_proxy.SubprotocolProxy`, which listens where the user
asked (127.0.0.1 unless told otherwise) and lets a client offering either subprotocol name in
(``foxglove.sdk.v1``, which the SDK accepts, or the classic ``foxglove.websocket.v1``); the SDK
itself listens on an ephemeral port of 127.0.0.1. The proxy binds its port when the view is made,
so a busy port fails at once (`ws_proxy.check_port` lets the launcher ask before anything runs).
The SDK's global context is not used, so nothing else in the process can log to it. The server
starts (`start`) once the run's topics exist: foxglove-sdk 0.30 advertises a channel created while
a client is connected before it can take that client's subscription ("Unknown channel ID"), so a
client that subscribes at once (as Foxglove does) would miss it; channels that exist when a
client connects are advertised safely.
"""

from __future__ import annotations

import threading

from foxglove.websocket import ServerListener

from swarm_sim.nodes.ws_proxy import SubprotocolProxy
from swarm_sim.recording.metadata import _msgdef, _normalize_type

DEFAULT_PORT = 8765
"""Foxglove's default WebSocket port."""
LOOPBACK = "127.0.0.1"
CLOCK_TOPIC = "/clock"


class LiveView(ServerListener):
    """A Foxglove WebSocket server publishing recorded topics as they are written. As a
    `ServerListener` it has every callback the SDK may call (a client's unsubscribing and
    disconnecting need nothing from us)."""

    def __init__(self, port: int = DEFAULT_PORT, host: str = LOOPBACK, name: str = "swarmforage") -> None:
        """`port` 0 lets the OS choose (see `port`); OSError if it cannot listen there."""
        import foxglove

        self.proxy = SubprotocolProxy(host, port)
        self._foxglove = foxglove
        self.context = foxglove.Context()
        self._channels: dict[str, object] = {}
        self._latched: set[str] = set()
        self._last: dict[str, tuple[bytes, int]] = {}
        self._lock = threading.Lock()
        self.server = None
        self.host, self._name = host, name
        self.closed = False

    def start(self) -> None:
        """Start serving (idempotent); messages written before are not sent (latched ones are, on
        subscription)."""
        from foxglove.websocket import Capability

        if self.server is None and not self.closed:
            self.server = self._foxglove.start_server(
                name=self._name, host=LOOPBACK, port=0, capabilities=[Capability.Time],
                server_listener=self, context=self.context,
            )
            self.proxy.start(self.server.port)

    @property
    def port(self) -> int:
        """Where clients connect (the proxy's port)."""
        return self.proxy.port

    @property
    def url(self) -> str:
        host = f"[{self.host}]" if ":" in self.host else self.host
        return f"ws://{host}:{self.port}"

    def add(self, topic: str, type_name: str, latched: bool = False) -> None:
        """Advertise `topic` (idempotent)."""
        with self._lock:
            if topic in self._channels:
                return
            type_name = _normalize_type(type_name)
            schema = self._foxglove.Schema(name=type_name, encoding="ros2msg", data=_msgdef(type_name).encode())
            self._channels[topic] = self._foxglove.Channel(topic, schema=schema, message_encoding="cdr",
                                                           context=self.context)
            if latched:
                self._latched.add(topic)

    def write(self, topic: str, stamp_ns: int, data: bytes) -> None:
        """Send one message (CDR bytes) to the clients subscribed to `topic`."""
        channel = self._channels.get(topic)
        if channel is None:
            return
        if topic in self._latched:
            self._last[topic] = (data, stamp_ns)
        channel.log(data, log_time=stamp_ns)
        if topic == CLOCK_TOPIC and self.server is not None:
            self.server.broadcast_time(stamp_ns)

    # foxglove.websocket.ServerListener (called on the SDK's threads)

    def on_subscribe(self, client: object, channel: object) -> None:
        """A latched topic's last message goes out at once (to every subscriber of the channel:
        the SDK logs per channel, and a repeated state message is harmless)."""
        last = self._last.get(channel.topic)
        ours = self._channels.get(channel.topic)
        if last is not None and ours is not None:
            ours.log(last[0], log_time=last[1])

    def close(self) -> None:
        """Stop the server (idempotent)."""
        self.closed = True
        self.proxy.close()
        if self.server is not None:
            self.server.stop()
            self.server = None
