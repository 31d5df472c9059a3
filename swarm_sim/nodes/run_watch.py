"""A run ends everywhere: the world says so (`RunBeacon`), every other process listens (`RunWatch`).

The world publishes its run's state on ``/world/run`` (`swarm_msgs_py.run_state`; reliable and
transient-local, tagged with the run's key): ``running`` every `BEAT_PERIOD` wall seconds, then
once the run's end. At its end the world waits (at most `END_ACK_WAIT` s) until every reader has
acknowledged the end, so the word reaches the other hosts across lossy links.

Every controller and server process (on this host or another, a robot's own computer too)
watches it and leaves by itself, with one line saying why and an exit code (`EXIT_CODES`, the
codes swarm-run gives the same ends):

- the world said the run ended: complete (0), a server died (3), interrupted (130);
- the world vanished (5): nothing heard of it for ``--world-timeout`` wall seconds (killed,
  its host down, or unreachable longer than that; before it is first heard, `FIRST_HEARD_WAIT`).

The timeout is a liveness guard in wall time, not simulation logic: it never changes what a
run computes, only when a process orphaned by its world gives up. It must exceed the outages a
run should ride out (a 3 s partition, a world busy for a second between spins).

A process answers ticks only while its own world is the last it heard on ``/world/run``
(`RunWatch.current`): the first ``running`` it hears names its run (the run id; with a key,
only tagged messages count at all). A state of another run (another world on the domain, or a
message without the run's tag: counted) holds its answers until its own world speaks again, so
a process left over from an ended run never answers the next run's ticks; it leaves at its
timeout. A forger can thus delay a robot's answers by one beat at most per message.
"""

from __future__ import annotations

import secrets
import time

from rclpy.duration import Duration
from rclpy.node import Node

from swarm_msgs_py import auth, run_state, topics
from swarm_sim.inbound import Inbound
from swarm_sim.nodes.qos import STATE_LATCHED

WORLD_RUN = "/world/run"
BEAT_PERIOD = 1.0
"""Wall seconds between the world's ``running`` messages."""
WORLD_TIMEOUT = 20.0
"""Default ``--world-timeout``: wall seconds without a word from the world after which a process
of its run leaves (world vanished)."""
FIRST_HEARD_WAIT = 300.0
"""Wall seconds a process waits to hear its world a first time (the world starts, builds its
scene, or is started after the controllers) before it leaves (world vanished)."""
END_ACK_WAIT = 5.0
"""Wall seconds the world waits for every reader to acknowledge the run's end (across hosts)."""
END_ACK_WAIT_HERE = 1.0
"""The same on one host (loopback: acknowledged within milliseconds; a reader whose process was
killed holds it until then)."""
RUN_STATE_BYTES = 256
"""Cap on a ``/world/run`` message [bytes]."""
VANISHED = 5
EXIT_CODES = {
    0: "the run completed",
    3: "the run ended early: a server died",
    VANISHED: "the world vanished (killed, or unreachable longer than --world-timeout)",
    130: "the run was interrupted",
}
"""A controller or server process's exit codes when its run ends."""


def end_code(state: str) -> int:
    """The exit code of a process whose world ended its run in `state`."""
    if state in ("complete", "finished"):
        return 0
    if state == "interrupted":
        return 130
    return 3


class RunBeacon:
    """The world's side (see the module docstring)."""

    def __init__(self, node: Node, now_ns) -> None:
        """`now_ns()`: the world's sim time, stamped on each message."""
        self.run = secrets.token_hex(8)
        """This world's run id."""
        self._now_ns = now_ns
        self._pub = node.create_publisher(topics.import_type(run_state.TYPE_NAME), WORLD_RUN, STATE_LATCHED)
        self._timer = node.create_timer(BEAT_PERIOD, self.beat)
        self.beat()

    def beat(self) -> None:
        self._publish(run_state.RUNNING)

    def end(self, state: str) -> None:
        """Say the run ended in `state` (no more beats)."""
        self._timer.cancel()
        self._publish(state)

    def wait_acknowledged(self, seconds: float = END_ACK_WAIT) -> bool:
        """Until every reader acknowledged the end (`seconds` at most): True if all did."""
        return self._pub.wait_for_all_acked(Duration(nanoseconds=int(seconds * 1e9)))

    def _publish(self, state: str) -> None:
        self._pub.publish(auth.sign(run_state.encode_run_state(self.run, state, self._now_ns())))


_DECODE = auth.verified(run_state.decode_run_state)


class RunWatch:
    """A controller or server process's side (see the module docstring): `current` gates its
    answers, `verdict` says when and why to leave."""

    def __init__(self, node: Node, inbound: Inbound, world_timeout: float = WORLD_TIMEOUT,
                 clock=time.monotonic) -> None:
        if not 0.0 < world_timeout < float("inf"):
            raise ValueError(f"world_timeout: expected a positive number of seconds, got {world_timeout!r}")
        self.world_timeout = world_timeout
        self._clock = clock
        self._inbound = inbound
        self.run: str | None = None
        """The run id of this process's world (None until first heard)."""
        self.heard_at: float | None = None
        self.started = clock()
        self.held = False
        """Another run's state (or an untagged one) came after our world's last word."""
        self.ended: str | None = None
        self._sub = node.create_subscription(topics.import_type(run_state.TYPE_NAME), WORLD_RUN, self.on_message,
                                             STATE_LATCHED, raw=True)

    def on_message(self, data: bytes) -> None:
        decoded = self._inbound.decode(WORLD_RUN, _DECODE, data, RUN_STATE_BYTES)
        if decoded is None:  # untagged or forged: counted; our world must speak again
            self.held = True
            return
        run, state = decoded
        if self.run is None:
            if state != run_state.RUNNING:
                return  # the last word of a run that ended before we came: not ours
            self.run = run
        if run != self.run:
            self.held = True  # another world on our domain: ours has gone
            return
        self.heard_at = self._clock()
        self.held = False
        if state != run_state.RUNNING:
            self.ended = state

    def current(self) -> bool:
        """Whether this process may answer ticks: its world is heard, the last to speak, running."""
        return self.run is not None and not self.held and self.ended is None

    def verdict(self) -> tuple[int, str] | None:
        """(exit code, why) once this process should leave, else None."""
        if self.ended is not None:
            return end_code(self.ended), f"the world ended the run ({self.ended})"
        last, limit = (self.heard_at, self.world_timeout) if self.heard_at is not None else (
            self.started, max(FIRST_HEARD_WAIT, self.world_timeout))
        silent = self._clock() - last
        if silent > limit:
            what = "not heard for" if self.heard_at is not None else "never heard in"
            return VANISHED, f"the world vanished: {what} {silent:.1f} s (--world-timeout {self.world_timeout:g} s)"
        return None
