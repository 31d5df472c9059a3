"""Deterministic delivery of messages between nodes (robot <-> robot, robot <-> nest/server).

A message sent while answering tick k is stamped k and handed to its receivers at tick k+1:
a one-tick communication latency. In the graph the world's lockstep barrier guarantees every
message stamped k has been published before tick k+1's observations go out, so a receiver
that releases only messages stamped before the current tick, sorted by content, sees exactly
what the batch runner hands it. Every message type has a ``stamp_ns`` field.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, TypeVar

from swarm_sim.protocol import channel_of

T = TypeVar("T")


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


def per_inbox(summary: Callable[[tuple[Any, ...]], T]) -> Callable[[tuple[Any, ...]], T]:
    """`summary` of a tick's messages, computed once for all the robots that got the same tuple.

    The batch runner hands every robot the very same tuple on a tick, so what a behaviour reads
    from it independently of the robot (the messages of one kind, whom they address) need not be
    worked out once per robot. The last tuple seen is kept alive with its summary, so its identity
    cannot be taken for a new tuple's; a controller node's own tuples are simply summarised anew.
    """
    memo: list[tuple[tuple[Any, ...], T]] = [((), summary(()))]

    def summarised(messages: tuple[Any, ...]) -> T:
        last, value = memo[0]
        if messages is not last:
            value = summary(messages)
            memo[0] = (messages, value)
        return value

    return summarised
