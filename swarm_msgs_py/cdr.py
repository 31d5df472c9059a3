"""Pure-Python CDR primitives: enough of XCDR1 little-endian to write and read ROS 2 messages.

ROS-free on purpose, so that the world can publish `bytes` without building rclpy message
objects and bag analysis can decode without a ROS install.

Wire format (what rmw_fastrtps and rosbags use for ROS 2 messages):

- a 4-byte encapsulation header ``00 01 00 00`` (CDR, little-endian), then the body;
- every primitive is aligned to its own size, counted from the start of the body (so a
  float64 sits at a body offset that is a multiple of 8, i.e. data offset 4 + 8k);
- a string is a uint32 length that counts the terminating NUL, the UTF-8 bytes, then NUL;
- a sequence is a uint32 count, then the items, the first one aligned to its item size.

We write zero padding. Fast-CDR leaves padding bytes uninitialised, and
`rclpy.serialization.serialize_message` may append a few bytes past the end when its
size estimate exceeds the real size (it does for empty float64 sequences), so readers ignore
padding contents and trailing bytes, as Fast-CDR itself does.
"""

from __future__ import annotations

import functools
import struct
from collections.abc import Callable, Iterable, Sequence
from typing import Any, TypeVar

import numpy as np

ENCAPSULATION = b"\x00\x01\x00\x00"
"""CDR_LE representation identifier plus zero options."""
HEADER_SIZE = len(ENCAPSULATION)
NS_PER_S = 1_000_000_000

TIME = struct.Struct("<iI")
"""builtin_interfaces/msg/Time: int32 sec, uint32 nanosec."""
_U32 = struct.Struct("<I")
_HEADER_START = struct.Struct("<iII")
"""Header stamp plus the frame_id's length: always at body offset 0."""

_STRUCTS: dict[tuple[str, int], struct.Struct] = {}


class CodecError(ValueError):
    """Bytes that are not a valid serialized message, or values a message cannot hold.

    The message starts with the ROS type name (``nav_msgs/msg/Odometry: ...``).
    """


def _struct(code: str, count: int) -> struct.Struct:
    key = (code, count)
    s = _STRUCTS.get(key)
    if s is None:
        s = _STRUCTS[key] = struct.Struct(f"<{count}{code}")
    return s


CATCH = (struct.error, ValueError, IndexError, OverflowError)
"""What malformed bytes or unencodable values raise inside a codec (CodecError included)."""


def failure(type_name: str, exc: BaseException) -> CodecError:
    """The CodecError to raise for `exc` caught while coding `type_name`.

    Hot codecs use ``try: ... except CATCH as exc: raise failure(TYPE_NAME, exc) from exc``
    inline: a decorator costs a third of a twist decode.
    """
    if isinstance(exc, CodecError):
        return exc
    return CodecError(f"{type_name}: {exc}")


F = TypeVar("F", bound=Callable[..., Any])


def codec(type_name: str) -> Callable[[F], F]:
    """Turn any failure inside an encoder/decoder into a `CodecError` naming `type_name`."""

    def wrap(fn: F) -> F:
        @functools.wraps(fn)
        def inner(*args: Any, **kwargs: Any) -> Any:
            try:
                return fn(*args, **kwargs)
            except CodecError:
                raise
            except CATCH as exc:
                raise failure(type_name, exc) from exc

        return inner  # type: ignore[return-value]

    return wrap


def split_stamp(stamp_ns: int) -> tuple[int, int]:
    """Integer nanoseconds -> (sec, nanosec) as builtin_interfaces/Time holds them."""
    sec, nanosec = divmod(stamp_ns, NS_PER_S)
    if not -(2**31) <= sec < 2**31:
        raise ValueError(f"stamp {stamp_ns} ns does not fit builtin_interfaces/Time")
    return sec, nanosec


# --------------------------------------------------------------------------- writing


class Writer:
    """Append-only CDR body builder.

    `offset` is the body offset the first byte will land at; a non-zero offset builds a
    constant fragment (frame ids, fixed fields) once, to splice into a `struct` template.
    """

    __slots__ = ("_buf", "_base")

    def __init__(self, offset: int = 0) -> None:
        self._buf = bytearray()
        self._base = offset

    @property
    def offset(self) -> int:
        """Current body offset (alignment is counted from here)."""
        return self._base + len(self._buf)

    def align(self, size: int) -> None:
        pad = -(self._base + len(self._buf)) % size
        if pad:
            self._buf += bytes(pad)

    def pack(self, code: str, *values: Any) -> None:
        """Primitives of one struct `code` (``"d"``, ``"f"``, ``"I"``, ``"B"``, ...), aligned."""
        s = _struct(code, len(values))
        self.align(s.size // len(values) if values else 1)
        self._buf += s.pack(*values)

    def u8(self, value: int) -> None:
        self._buf.append(value)

    def u32(self, value: int) -> None:
        self.align(4)
        self._buf += _U32.pack(value)

    def f64(self, *values: float) -> None:
        self.pack("d", *values)

    def f32(self, *values: float) -> None:
        self.pack("f", *values)

    def string(self, text: str) -> None:
        raw = text.encode("utf-8")
        if b"\x00" in raw:
            raise ValueError(f"string {text!r} contains NUL, which CDR strings cannot carry")
        buf = self._buf
        pad = -(self._base + len(buf)) % 4
        if pad:
            buf += bytes(pad)
        buf += _U32.pack(len(raw) + 1)
        buf += raw
        buf.append(0)

    def time(self, stamp_ns: int) -> None:
        self.align(4)
        self._buf += TIME.pack(*split_stamp(stamp_ns))

    def header(self, stamp_ns: int, frame_id: str) -> None:
        """std_msgs/msg/Header."""
        self.time(stamp_ns)
        self.string(frame_id)

    def sequence_length(self, count: int) -> None:
        self.u32(count)

    def strings(self, texts: Sequence[str]) -> None:
        self.u32(len(texts))
        for text in texts:
            self.string(text)

    def f64_array(self, values: Iterable[float] | np.ndarray) -> None:
        """float64[] sequence."""
        arr = np.ascontiguousarray(values, dtype="<f8")
        self.u32(arr.size)
        if arr.size:
            self.align(8)
            self._buf += arr.tobytes()

    def f32_array(self, values: Iterable[float] | np.ndarray) -> None:
        """float32[] sequence (values rounded to nearest float32)."""
        arr = np.ascontiguousarray(values, dtype="<f4")
        self.u32(arr.size)
        self._buf += arr.tobytes()

    def body(self) -> bytes:
        return bytes(self._buf)

    def message(self) -> bytes:
        """Encapsulation header plus body: what a raw publisher sends."""
        if self._base:
            raise ValueError("a Writer with a non-zero start offset builds fragments only")
        return ENCAPSULATION + self._buf


# --------------------------------------------------------------------------- reading


def check_encapsulation(data: bytes) -> None:
    if len(data) < HEADER_SIZE:
        raise ValueError(f"{len(data)} bytes is shorter than the CDR encapsulation header")
    if data[0] != 0 or data[1] != 1:
        raise ValueError(
            f"encapsulation {bytes(data[:2]).hex()} is not CDR little-endian (0001)"
        )


def read_string(data: bytes, pos: int) -> tuple[str, int]:
    """Read a CDR string at data offset `pos` (already 4-aligned); return (text, next pos)."""
    (n,) = _U32.unpack_from(data, pos)
    pos += 4
    end = pos + n
    if n == 0 or end > len(data):
        raise ValueError(f"string length {n} at offset {pos - 4} overruns {len(data)} bytes")
    if data[end - 1] != 0:
        raise ValueError(f"string at offset {pos - 4} is not NUL-terminated")
    return bytes(data[pos : end - 1]).decode("utf-8"), end


def skip_string(data: bytes, pos: int) -> int:
    """Like `read_string` without decoding the text (hot decoders skip frame ids)."""
    (n,) = _U32.unpack_from(data, pos)
    end = pos + 4 + n
    if n == 0 or end > len(data):
        raise ValueError(f"string length {n} at offset {pos} overruns {len(data)} bytes")
    if data[end - 1] != 0:
        raise ValueError(f"string at offset {pos} is not NUL-terminated")
    return end


def align(pos: int, size: int) -> int:
    """Data offset `pos` rounded up to a body offset that is a multiple of `size`."""
    return pos + (-(pos - HEADER_SIZE) % size)


class Reader:
    """Sequential CDR reader over a whole message (encapsulation header included)."""

    __slots__ = ("data", "pos")

    def __init__(self, data: bytes) -> None:
        check_encapsulation(data)
        self.data = data
        self.pos = HEADER_SIZE

    def align(self, size: int) -> None:
        self.pos = align(self.pos, size)

    def unpack(self, code: str, count: int = 1) -> tuple[Any, ...]:
        s = _struct(code, count)
        self.align(s.size // count if count else 1)
        values = s.unpack_from(self.data, self.pos)
        self.pos += s.size
        return values

    def u8(self) -> int:
        if self.pos >= len(self.data):
            raise ValueError(f"message ends at {len(self.data)} bytes, wanted one more")
        value = self.data[self.pos]
        self.pos += 1
        return value

    def u32(self) -> int:
        self.align(4)
        (value,) = _U32.unpack_from(self.data, self.pos)
        self.pos += 4
        return value

    def f64(self) -> float:
        return self.unpack("d")[0]

    def string(self) -> str:
        self.align(4)
        text, self.pos = read_string(self.data, self.pos)
        return text

    def time(self) -> int:
        self.align(4)
        stamp_ns = read_stamp(self.data, self.pos)
        self.pos += TIME.size
        return stamp_ns

    def header(self) -> tuple[int, str]:
        """std_msgs/msg/Header -> (stamp_ns, frame_id)."""
        return self.time(), self.string()

    def sequence_length(self, min_item_size: int) -> int:
        """A sequence count, refused when its items could not fit in what is left."""
        count = self.u32()
        left = len(self.data) - self.pos
        if count * min_item_size > left:
            raise ValueError(f"sequence of {count} items overruns the {left} bytes left")
        return count

    def strings(self) -> list[str]:
        return [self.string() for _ in range(self.sequence_length(5))]

    def f64_array(self) -> np.ndarray:
        """float64[] sequence as a fresh, writable native float64 array."""
        count = self.sequence_length(8)
        if count:
            self.align(8)
        return self._array("<f8", np.float64, count)

    def f32_array(self) -> np.ndarray:
        """float32[] sequence as a fresh, writable native float32 array."""
        return self._array("<f4", np.float32, self.sequence_length(4))

    def _array(self, wire: str, native: type, count: int) -> np.ndarray:
        size = np.dtype(wire).itemsize
        if self.pos + count * size > len(self.data):
            raise ValueError(f"array of {count} items overruns {len(self.data)} bytes")
        arr = np.frombuffer(self.data, wire, count, self.pos).astype(native)
        self.pos += count * size
        return arr


# --------------------------------------------------------------------------- headers


def read_stamp(data: bytes, pos: int = HEADER_SIZE) -> int:
    """builtin_interfaces/msg/Time at data offset `pos` -> integer nanoseconds."""
    sec, nanosec = TIME.unpack_from(data, pos)
    if nanosec >= NS_PER_S:
        raise ValueError(f"nanosec {nanosec} is not below one second")
    return sec * NS_PER_S + nanosec


def skip_header(data: bytes) -> tuple[int, int]:
    """A message that starts with a std_msgs/msg/Header -> (stamp_ns, data offset after it).

    The frame id is checked but not decoded: the hot decoders know their frames.
    """
    if len(data) < HEADER_SIZE or data[0] != 0 or data[1] != 1:
        check_encapsulation(data)  # raises, naming the problem
    sec, nanosec, n = _HEADER_START.unpack_from(data, HEADER_SIZE)
    if nanosec >= NS_PER_S:
        raise ValueError(f"nanosec {nanosec} is not below one second")
    end = HEADER_SIZE + _HEADER_START.size + n
    if n == 0 or end > len(data):
        raise ValueError(f"frame_id length {n} overruns {len(data)} bytes")
    if data[end - 1] != 0:
        raise ValueError("frame_id is not NUL-terminated")
    return sec * NS_PER_S + nanosec, end


def frames_fragment(*frame_ids: str, then_align: int = 1) -> bytes:
    """The constant bytes of consecutive strings that follow a header stamp (body offset 8),
    padded so the next field lands aligned to `then_align`."""
    w = Writer(offset=TIME.size)
    for frame_id in frame_ids:
        w.string(frame_id)
    w.align(then_align)
    return w.body()
