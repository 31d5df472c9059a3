"""The inter-node protocol (`swarm_sim.protocol`) <-> diagnostic_msgs/msg/DiagnosticArray.

Mapping: one DiagnosticArray per topic per tick, header.stamp = the tick the messages were sent
in; one DiagnosticStatus per message: level OK, name = the message's class (``DepotGrant``),
hardware_id = its sender or addressee robot, message empty, values = every field in
declaration order as (name, text): ints with ``str``, floats with ``repr`` (exact round trip),
bools as ``true``/``false``. `ros2 topic echo /depot/grants` therefore reads as the dataclass.

Topics (all reliable, deep, volatile: every message counts):

| message | topic | from -> to |
|---|---|---|
| ProgressReport | /center/reports | robot -> center |
| RegionAssignment | /center/assignments | center -> robots |
| DepotReport | /depot/reports | robot -> depot manager |
| DepotGrant | /depot/grants | depot manager -> robots |
| RadioQuery, RadioReply | /radio | robot -> robots (receivers keep what is in range) |
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Iterable
from typing import Any

from swarm_msgs_py.cdr import codec
from swarm_msgs_py.diagnostics import OK, TYPE_NAME, decode_diagnostics, encode_diagnostics
from swarm_sim.protocol import (
    DepotGrant,
    DepotReport,
    ProgressReport,
    RadioQuery,
    RadioReply,
    RegionAssignment,
)

MESSAGE_TOPICS: dict[type, str] = {
    ProgressReport: "/center/reports",
    RegionAssignment: "/center/assignments",
    DepotReport: "/depot/reports",
    DepotGrant: "/depot/grants",
    RadioQuery: "/radio",
    RadioReply: "/radio",
}
_CLASSES = {cls.__name__: cls for cls in MESSAGE_TOPICS}
_FIELDS = {cls: tuple(f.name for f in dataclasses.fields(cls)) for cls in MESSAGE_TOPICS}
_TYPES = {cls: tuple(f.type for f in dataclasses.fields(cls)) for cls in MESSAGE_TOPICS}


def topic_of(message: Any) -> str:
    try:
        return MESSAGE_TOPICS[type(message)]
    except KeyError:
        raise TypeError(f"no topic for message type {type(message).__name__}") from None


def _text(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return repr(value)
    return str(value)


def _value(text: str, type_name: str, key: str) -> Any:
    if type_name == "bool":
        if text not in ("true", "false"):
            raise ValueError(f"{key}: expected true/false, got {text!r}")
        return text == "true"
    if type_name == "int":
        return int(text)
    if type_name == "float":
        return float(text)
    return text


def _addressee(message: Any) -> str:
    return getattr(message, "robot", None) or getattr(message, "sender", "")


@codec(f"{TYPE_NAME} (protocol)")
def encode_messages(stamp_ns: int, messages: Iterable[Any]) -> bytes:
    statuses = []
    for m in messages:
        cls = type(m)
        if cls not in _FIELDS:
            raise TypeError(f"not a protocol message: {cls.__name__}")
        values = tuple((name, _text(getattr(m, name))) for name in _FIELDS[cls])
        statuses.append((OK, cls.__name__, "", _addressee(m), values))
    return encode_diagnostics(stamp_ns, statuses)


@codec(f"{TYPE_NAME} (protocol)")
def decode_messages(data: bytes) -> tuple[Any, ...]:
    """-> the messages in order; ValueError naming the first unknown or malformed one."""
    _, statuses = decode_diagnostics(data)
    out = []
    for status in statuses:
        cls = _CLASSES.get(status.name)
        if cls is None:
            raise ValueError(f"unknown protocol message {status.name!r}")
        values = dict(status.values)
        names = _FIELDS[cls]
        if sorted(values) != sorted(names):
            raise ValueError(f"{status.name}: fields {sorted(values)}, expected {sorted(names)}")
        out.append(cls(*(_value(values[n], t, f"{status.name}.{n}") for n, t in zip(names, _TYPES[cls]))))
    return tuple(out)


def post_all(data: bytes, post: Callable[[Any], None], warn: Callable[[str], None]) -> None:
    """A node's raw subscription callback body: decode `data` and `post` every message; a
    malformed array is dropped with a warning naming the problem (nothing else is lost)."""
    try:
        messages = decode_messages(data)
    except ValueError as exc:
        warn(f"dropping a malformed protocol message: {exc}")
        return
    for m in messages:
        post(m)
