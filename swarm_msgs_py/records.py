"""Message families: protocol dataclasses <-> standard ROS messages, strictly typed.

A `MessageFamily` is what a paper's protocol looks like on the graph: which topic each message
class travels on, and how a batch of messages of one tick becomes the bytes of one message and
back. The registry names families (`swarm_sim.registry`); the nodes derive their publishers and
subscriptions from them, and nothing else lists protocol topics.

`RecordFamily` maps dataclass records to diagnostic_msgs/msg/DiagnosticArray: one array per
topic per tick, header.stamp = the tick the messages were sent in; one DiagnosticStatus per
message: level OK, name = the message's class (``DepotGrant``), hardware_id = its sender or
addressee robot, message empty, values = every field in declaration order as (name, text):
ints with ``str``, floats with ``repr`` (exact round trip), bools as ``true``/``false``, enums
as their value, ``tuple[X, ...]`` as its items separated by spaces. A class with an int class
constant ``TYPE`` (a paper's message type number) shows it first, as the value ``type``, and its
``origin`` as hardware_id when it has no ``robot`` or ``sender``. ``ros2 topic echo
/depot/grants`` therefore reads as the dataclass.

Decoding is strict: an unknown message name, an unknown or missing field, or a value that is not
of the field's declared type (int, float, bool, str, an Enum, or ``X | None``) is refused with a
ValueError naming ``Class.field`` and the text. So is a value no message of ours can hold, before
any core computes with it: a float that is not finite or beyond ``MAX_MAGNITUDE``, an int outside
int64, a tuple of more than ``MAX_ITEMS`` items (what a node refuses on physical grounds, such as
a position beyond the arena, is `swarm_sim.inbound`'s).
"""

from __future__ import annotations

import dataclasses
import enum
import types
import typing
from collections.abc import Callable, Iterable, Mapping
from typing import Any, Protocol

from swarm_msgs_py.diagnostics import OK, TYPE_NAME, decode_diagnostics, encode_diagnostics


class MessageFamily(Protocol):
    """A protocol's messages on the graph."""

    name: str
    topics: Mapping[type, str]
    """Message class -> the topic it travels on."""
    type_name: str
    """The ROS type of every topic of the family."""

    def encode(self, stamp_ns: int, messages: Iterable[Any]) -> list[bytes]:
        """Messages of one tick, all for the same topic -> the wire messages to publish."""
        ...

    def decode(self, data: bytes) -> tuple[Any, ...]:
        """One wire message -> its messages, in order; ValueError naming what is malformed."""
        ...


def topic_of(family: MessageFamily, message: Any) -> str:
    try:
        return family.topics[type(message)]
    except KeyError:
        raise TypeError(f"{family.name}: no topic for message type {type(message).__name__}") from None


MAX_MAGNITUDE = 1e9
"""The largest magnitude of a float field: positions [m], arc lengths [m], energies, all far
below; squaring it cannot overflow (a 1e308 coordinate raised OverflowError in a core)."""
MAX_ITEMS = 4096
"""The most items a ``tuple[X, ...]`` field may hold (a caging trajectory: tens of landmarks)."""
_INT64 = 2**63


def field_text(value: Any) -> str:
    """A field's value as record text (what `field_parser` reads back)."""
    if isinstance(value, tuple):
        return " ".join(field_text(v) for v in value)
    if isinstance(value, enum.Enum):
        return str(value.value)
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return repr(value)
    return str(value)


def field_parser(tp: Any, key: str) -> Callable[[str], Any]:
    """The strict text -> value function for a field of type `tp` (``tuple[X, ...]``: items
    separated by single spaces, "" = empty)."""
    if typing.get_origin(tp) is tuple:
        args = typing.get_args(tp)
        if len(args) != 2 or args[1] is not Ellipsis:
            raise TypeError(f"{key}: only tuple[X, ...] tuples are supported")
        item = field_parser(args[0], key)

        def parse_tuple(text: str) -> tuple:
            if not text:
                return ()
            if text.count(" ") >= MAX_ITEMS:  # counted before any item is parsed
                raise ValueError(f"{key}: more than {MAX_ITEMS} items")
            return tuple(item(t) for t in text.split(" "))

        return parse_tuple
    if typing.get_origin(tp) in (typing.Union, types.UnionType):
        args = [a for a in typing.get_args(tp) if a is not type(None)]
        if len(args) != 1:
            raise TypeError(f"{key}: only X | None unions are supported")
        inner = field_parser(args[0], key)
        return lambda text: None if text == "None" else inner(text)
    if isinstance(tp, type) and issubclass(tp, enum.Enum):
        by_value = {str(m.value): m for m in tp}

        def parse_enum(text: str) -> Any:
            if text not in by_value:
                raise ValueError(f"{key}: {text!r} is not one of {sorted(by_value)}")
            return by_value[text]

        return parse_enum
    if tp is bool:
        def parse_bool(text: str) -> bool:
            if text not in ("true", "false"):
                raise ValueError(f"{key}: expected true/false, got {text!r}")
            return text == "true"

        return parse_bool
    if tp is int:
        def parse_int(text: str) -> int:
            if not text.lstrip("-").isdigit() or len(text) > 20 or not -_INT64 <= int(text) < _INT64:
                raise ValueError(f"{key}: expected a 64-bit integer, got {text[:40]!r}")
            return int(text)

        return parse_int
    if tp is float:
        def parse_float(text: str) -> float:
            try:
                value = float(text)
            except ValueError:
                raise ValueError(f"{key}: expected a number, got {text[:40]!r}") from None
            if not -MAX_MAGNITUDE <= value <= MAX_MAGNITUDE:  # NaN fails too
                raise ValueError(f"{key}: expected a finite number within +-{MAX_MAGNITUDE:g}, got {text[:40]!r}")
            return value

        return parse_float
    if tp is str:
        return str
    raise TypeError(f"{key}: unsupported field type {tp}")


class RecordFamily:
    """Dataclass messages as DiagnosticArray records (see the module docstring)."""

    type_name = TYPE_NAME

    def __init__(self, name: str, topics: Mapping[type, str], latched: Iterable[str] = ()) -> None:
        self.name = name
        self.topics = dict(topics)
        self.latched = frozenset(latched)
        """Topics published reliable + transient-local (a stream of states: a late joiner gets
        the latest at once); the others are volatile (`swarm_sim.nodes.qos.family_qos`)."""
        unknown = self.latched - set(self.topics.values())
        if unknown:
            raise ValueError(f"{name}: latched topics {sorted(unknown)} are not topics of the family")
        self._classes = {cls.__name__: cls for cls in self.topics}
        self._fields: dict[type, tuple[str, ...]] = {}
        self._parsers: dict[type, tuple[Callable[[str], Any], ...]] = {}
        for cls in self.topics:
            hints = typing.get_type_hints(cls)
            names = tuple(f.name for f in dataclasses.fields(cls))
            self._fields[cls] = names
            self._parsers[cls] = tuple(field_parser(hints[n], f"{cls.__name__}.{n}") for n in names)

    def encode(self, stamp_ns: int, messages: Iterable[Any]) -> list[bytes]:
        statuses = []
        for m in messages:
            cls = type(m)
            if cls not in self._fields:
                raise TypeError(f"not a {self.name} message: {cls.__name__}")
            values = tuple((name, field_text(getattr(m, name))) for name in self._fields[cls])
            if hasattr(cls, "TYPE"):
                values = (("type", str(cls.TYPE)), *values)
            addressee = getattr(m, "robot", None) or getattr(m, "sender", None) or getattr(m, "origin", "")
            statuses.append((OK, cls.__name__, "", addressee, values))
        return [encode_diagnostics(stamp_ns, statuses)]

    def decode(self, data: bytes) -> tuple[Any, ...]:
        _, statuses = decode_diagnostics(data)
        out = []
        for status in statuses:
            cls = self._classes.get(status.name)
            if cls is None:
                raise ValueError(f"unknown {self.name} message {status.name!r} (known: {', '.join(self._classes)})")
            values = dict(status.values)
            if hasattr(cls, "TYPE"):
                if values.pop("type", None) != str(cls.TYPE):
                    raise ValueError(f"{status.name}.type: expected {cls.TYPE}, got {dict(status.values).get('type')!r}")
                status = status._replace(values=tuple(kv for kv in status.values if kv[0] != "type"))
            names = self._fields[cls]
            unknown = sorted(set(values) - set(names))
            if unknown:
                raise ValueError(f"{status.name}.{unknown[0]}: unknown field")
            missing = [n for n in names if n not in values]
            if missing or len(values) != len(status.values):
                raise ValueError(f"{status.name}.{(missing or ['?'])[0]}: missing or repeated field")
            out.append(cls(*(parse(values[n]) for n, parse in zip(names, self._parsers[cls]))))
        return tuple(out)
