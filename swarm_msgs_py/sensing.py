"""How a world task's data travels: its sense, one message per robot and tick, and its world-level state.

Every tick the world node publishes three observations to each robot (`topics.OBSERVATIONS`):
odometry, the scan and the task's sense on ``/<robot>/sense``; a controller steps once it holds
all three stamped with the same tick. A task's `StateTopic` values are world-level topics the world
node publishes every tick (recorded; analysis reads them back as time series). The records are
data, so adding a task adds no code to the nodes: only its types, its field codecs and these values.

The sense message (`Sensing.encode`): diagnostic_msgs/msg/DiagnosticArray, header.stamp = the
tick, frame_id empty; one status per field of the sense, in the order the task declares them:
level OK, name = the field, message and hardware_id empty, values = the field's (key, text) pairs
(`SenseField`). Why this type: a sense mixes strings (the ids of what a sensor sees) with floats
and flags, and the controller needs the tick's stamp; a labelled Float64MultiArray carries neither
strings nor a header, and one message type per sense field meant one message per field (two or
three a robot and tick, issue 40). Floats travel as ``repr`` text, which gives every float back
bit for bit, so a controller's sense equals the world's (graph == batch); `ros2 topic echo` shows
each field by its name.

`Sensing` writes and reads these bytes itself rather than through `swarm_msgs_py.diagnostics`'
generic DiagnosticArray codec: one sense a robot and tick is the hot path, and with each field's
fixed status bytes built once it takes 3.9 against 9.9 us to encode and 5.8 against 12.2 us to
decode a foraging sense (the same bytes; test_sensing decodes them with the generic codec and back).
"""

from __future__ import annotations

import struct
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from typing import Any, NamedTuple

from swarm_msgs_py.cdr import (
    CATCH,
    ENCAPSULATION,
    Writer,
    align,
    failure,
    frames_fragment,
    read_string,
    skip_header,
    skip_string,
    split_stamp,
)

TYPE_NAME = "diagnostic_msgs/msg/DiagnosticArray"

Pairs = tuple[tuple[str, str], ...]
"""A status's values: (key, text) pairs."""


@dataclass(frozen=True)
class SenseField:
    """One field of a sense: one status of the sense message, the field's value as text pairs."""

    field: str
    """The sense's field (also the status's name)."""
    encode: Callable[[Any], Pairs]
    """value -> (key, text) pairs."""
    decode: Callable[[Pairs], Any]
    """(key, text) pairs -> the value encoded, exactly; ValueError naming the problem otherwise."""


def numbers_text(values: Iterable[float]) -> str:
    """Floats as ``repr`` text, space-separated: ``float()`` gives each back bit for bit."""
    return " ".join([repr(float(v)) for v in values])


def parse_numbers(text: str, size: int, key: str) -> tuple[float, ...]:
    """`numbers_text`'s text of `size` floats -> the floats; ValueError naming `key`. Not-finite
    numbers pass: the controller's guard refuses them (`swarm_sim.inbound`), counted."""
    parts = text.split(" ")
    if len(parts) != size:
        raise ValueError(f"{key}: expected {size} numbers, got {text[:40]!r}")
    try:
        return tuple([float(p) for p in parts])
    except ValueError:
        raise ValueError(f"{key}: expected {size} numbers, got {text[:40]!r}") from None


def _one(pairs: Pairs, key: str) -> str:
    if len(pairs) != 1 or pairs[0][0] != key:
        raise ValueError(f"expected one value {key!r}, got keys {[k[:40] for k, _ in pairs[:4]]}")
    return pairs[0][1]


def flag(name: str) -> SenseField:
    """A bool: one pair (`name`, ``true`` | ``false``)."""
    texts = {True: ((name, "true"),), False: ((name, "false"),)}
    values = {"true": True, "false": False}

    def decode(pairs: Pairs) -> bool:
        text = _one(pairs, name)
        if text not in values:
            raise ValueError(f"{name}: expected 'true' or 'false', got {text[:40]!r}")
        return values[text]

    return SenseField(name, lambda value: texts[bool(value)], decode)


def vector(name: str, size: int) -> SenseField:
    """A tuple of `size` floats: one pair (`name`, ``"x y ..."``)."""
    return SenseField(name, lambda value: ((name, numbers_text(value)),),
                      lambda pairs: parse_numbers(_one(pairs, name), size, name))


def vectors(name: str, size: int) -> SenseField:
    """A tuple of any number of `size`-float tuples, in order: pair i is (``"i"``, ``"x y ..."``)."""
    def decode(pairs: Pairs) -> tuple[tuple[float, ...], ...]:
        out = []
        for i, (key, text) in enumerate(pairs):
            if key != str(i):
                raise ValueError(f"{name}: key {key[:40]!r} where {str(i)!r} was expected")
            out.append(parse_numbers(text, size, f"{name}[{i}]"))
        return tuple(out)

    return SenseField(name, lambda value: tuple([(str(i), numbers_text(v)) for i, v in enumerate(value)]), decode)


class SenseData(NamedTuple):
    stamp_ns: int
    sense: Any


_U32 = struct.Struct("<I")
_EMPTY_FRAME = frames_fragment("", then_align=4)
_OPEN = struct.Struct(f"<4siI{len(_EMPTY_FRAME)}sI")
"""Encapsulation, header (stamp, frame_id empty), status count."""
_PADS = (b"", b"\0", b"\0\0", b"\0\0\0")
_MIN_PAIR = 2 * 5
"""Two empty strings: bounds a value count by the bytes left."""


def _put(buf: bytearray, text: str) -> None:
    """A CDR string at the end of `buf` (an encapsulated message: body alignment = len mod 4)."""
    if "\0" in text:
        raise ValueError(f"{text[:40]!r} contains NUL, which a CDR string cannot carry")
    raw = text.encode("utf-8")
    buf += _PADS[-len(buf) & 3]
    buf += _U32.pack(len(raw) + 1)
    buf += raw
    buf.append(0)


def _status_heads(name: str) -> tuple[bytes, ...]:
    """Per start offset mod 4, the bytes of a status up to its values count: level OK, the name,
    empty message and hardware_id, padding."""
    heads = []
    for offset in range(4):
        w = Writer(offset=offset)
        w.u8(0)
        w.string(name)
        w.string("")
        w.string("")
        w.align(4)
        heads.append(w.body())
    return tuple(heads)


@dataclass(frozen=True)
class Sensing:
    """A task's sense type and its fields' codecs (every field exactly once): the sense message."""

    sense: type
    """The sense type (a NamedTuple or frozen dataclass), built as ``sense(**fields)``."""
    fields: tuple[SenseField, ...]
    """In message order."""
    _heads: tuple[tuple[bytes, ...], ...] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        names = getattr(self.sense, "_fields", None) or tuple(self.sense.__dataclass_fields__)
        if sorted(f.field for f in self.fields) != sorted(names):
            raise ValueError(f"{self.sense.__name__}: fields {[f.field for f in self.fields]}, "
                             f"expected each of {list(names)} once")
        object.__setattr__(self, "_heads", tuple(_status_heads(f.field) for f in self.fields))

    @property
    def what(self) -> str:
        """The name its codec errors start with."""
        return f"{TYPE_NAME} ({self.sense.__name__})"

    def encode(self, stamp_ns: int, sense: Any) -> bytes:
        """`sense` stamped `stamp_ns` -> CDR bytes; CodecError if a value cannot travel."""
        try:
            sec, nanosec = split_stamp(stamp_ns)
            buf = bytearray(_OPEN.pack(ENCAPSULATION, sec, nanosec, _EMPTY_FRAME, len(self.fields)))
            for f, heads in zip(self.fields, self._heads):
                pairs = f.encode(getattr(sense, f.field))
                buf += heads[len(buf) & 3]
                buf += _U32.pack(len(pairs))
                for key, text in pairs:
                    _put(buf, key)
                    _put(buf, text)
            return bytes(buf)
        except CATCH as exc:
            raise failure(self.what, exc) from exc

    def decode(self, data: bytes) -> SenseData:
        """CDR bytes -> (stamp_ns, sense); CodecError naming the problem if they are not this
        task's sense (another field, a value that does not parse, truncated or malformed)."""
        try:
            stamp_ns, pos = skip_header(data)
            pos = align(pos, 4)
            (count,) = _U32.unpack_from(data, pos)
            if count != len(self.fields):
                raise ValueError(f"{count} statuses, expected {len(self.fields)} "
                                 f"({', '.join(f.field for f in self.fields)})")
            pos += 4
            values = {}
            for f, heads in zip(self.fields, self._heads):
                head = heads[pos & 3]
                if data[pos:pos + len(head)] == head:  # what `encode` writes: no string to read
                    pos += len(head)
                else:
                    name, pos = read_string(data, align(pos + 1, 4))  # after the level (any)
                    if name != f.field:
                        raise ValueError(f"status {name[:40]!r} where {f.field!r} was expected")
                    pos = skip_string(data, align(pos, 4))  # message
                    pos = align(skip_string(data, align(pos, 4)), 4)  # hardware_id
                (n,) = _U32.unpack_from(data, pos)
                pos += 4
                if n * _MIN_PAIR > len(data) - pos:
                    raise ValueError(f"{f.field}: {n} values overrun the {len(data) - pos} bytes left")
                pairs = []
                for _ in range(n):
                    key, pos = read_string(data, pos + (-pos & 3))
                    text, pos = read_string(data, pos + (-pos & 3))
                    pairs.append((key, text))
                values[f.field] = f.decode(tuple(pairs))
        except CATCH as exc:
            raise failure(self.what, exc) from exc
        return SenseData(stamp_ns, self.sense(**values))


@dataclass(frozen=True)
class StateTopic:
    """One value of a task's ``state()`` on a world-level topic, published every tick."""

    topic: str
    """Absolute topic name (``/caging/object``)."""
    type_name: str
    """ROS type string: standard types only."""
    field: str
    """The key of the value in the task's ``state()``; also its series name in the run trace."""
    encode: Callable[[int, Any], bytes]
    """(stamp_ns, value) -> CDR bytes."""
    decode: Callable[[bytes], tuple[int, Any]]
    """CDR bytes -> (stamp_ns, value) with ``value == state()[field]`` exactly (the task applies
    the wire's rounding, e.g. yaw through a quaternion), so the batch runner's series equal a
    bag's; raises CodecError (a ValueError) on malformed bytes."""
