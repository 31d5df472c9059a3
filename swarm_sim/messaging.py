"""Deterministic delivery of messages between nodes (robot <-> robot, robot <-> nest/server).

A message sent while answering tick k is stamped k and handed to its receivers at tick k+1:
a one-tick communication latency. In the graph the world's lockstep barrier guarantees every
message stamped k has been published before tick k+1's observations go out, so a receiver
that releases only messages stamped before the current tick, sorted by content, sees exactly
what the batch runner hands it. Every message type has a ``stamp_ns`` field.
"""

from __future__ import annotations

from typing import Any

from swarm_sim.protocol import channel_of


def delivery_order(message: Any) -> tuple[int, str, str]:
    """The order receivers get messages in: by stamp, then type name, then content."""
    return (message.stamp_ns, type(message).__name__, repr(message))


class Mailbox:
    """Collects incoming messages; releases those stamped before a tick in a fixed order."""

    def __init__(self) -> None:
        self._pending: list[Any] = []

    def post(self, message: Any) -> None:
        self._pending.append(message)

    def take_before(self, stamp_ns: int) -> tuple[Any, ...]:
        ready = [m for m in self._pending if m.stamp_ns < stamp_ns]
        if not ready:
            return ()
        self._pending = [m for m in self._pending if m.stamp_ns >= stamp_ns]
        return tuple(sorted(ready, key=delivery_order))


class Router:
    """One `Mailbox` per channel, made when first used: what the batch runner uses in place of
    the graph's topics."""

    def __init__(self) -> None:
        self._boxes: dict[str, Mailbox] = {}

    def post(self, message: Any) -> None:
        channel = channel_of(message)
        if channel not in self._boxes:
            self._boxes[channel] = Mailbox()
        self._boxes[channel].post(message)

    def take_before(self, channel: str, stamp_ns: int) -> tuple[Any, ...]:
        box = self._boxes.get(channel)
        return box.take_before(stamp_ns) if box is not None else ()
