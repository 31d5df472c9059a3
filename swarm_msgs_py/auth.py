"""The run's credential: our own messages carry a tag only the run's processes can make.

Fast DDS as shipped (2.14.5, the PyPI wheels) has no DDS Security plug-ins, so anyone who joins
the run's domain can publish on its topics. The launcher (`launch_py.run`) therefore draws a
random 32-byte key per run and hands it to each child process through a pipe it inherits
(``SWARMFORAGE_KEY_FD`` names the descriptor; never argv, never the bus, never the bag); a node
process reads it once at start (`load_from_environment`) and the controllers' forked processes
inherit it in memory.

What carries the tag: every message of ours that begins with a std_msgs/msg/Header and that a
node or the analysis acts on: the message families' DiagnosticArrays (acks, server and peer
messages, the nest state), the servers' state, the behaviours' status, ``/diagnostics``, the
world's events and stats, ``/lockstep/ack``. The tag is ``#`` and 31 hex digits of
HMAC-SHA256(key, the message without its tag), appended to header.frame_id: 32 characters, a
multiple of 8, so every byte after the frame id keeps its place and alignment; decoders ignore
frame ids, except the ack's, which is verified (and so stripped) first. Observations, commands
and ``/clock`` are standard types whose frame ids mean something: they carry no tag, and a
foreign publisher on them is detected instead (`swarm_sim.nodes.taint`).

Without a key (a node started by hand, the batch runner, tests) nothing is tagged and nothing
is checked. ROS-free: bytes in, bytes out.
"""

from __future__ import annotations

import hashlib
import hmac
import os
import struct

ENV = "SWARMFORAGE_KEY_FD"
"""The environment variable naming the inherited descriptor the key is read from."""
KEY_BYTES = 32
TAG_CHARS = 32
"""``#`` plus 31 hex digits (124 bits of the HMAC)."""
_FRAME_AT = 12
"""Data offset of header.frame_id's length: encapsulation (4), stamp (8)."""
_U32 = struct.Struct("<I")

_key: bytes | None = None


def key() -> bytes | None:
    """This process's run key (None: nothing is signed or checked)."""
    return _key


def set_key(value: bytes | None) -> None:
    global _key
    if value is not None and len(value) != KEY_BYTES:
        raise ValueError(f"a run key is {KEY_BYTES} bytes, got {len(value)}")
    _key = value


def load_from_environment() -> bool:
    """Read the key from the descriptor ``SWARMFORAGE_KEY_FD`` names, then close it and forget the
    variable (a child of ours must not find it). True if a key was loaded."""
    text = os.environ.pop(ENV, "")
    if not text:
        return False
    fd = int(text)
    try:
        data = b""
        while len(data) < KEY_BYTES:
            chunk = os.read(fd, KEY_BYTES - len(data))
            if not chunk:
                break
            data += chunk
    finally:
        os.close(fd)
    set_key(data)
    return True


def _tag(data: bytes) -> bytes:
    """Over the message without its trailing zero bytes: DDS pads a payload to a multiple of 4
    bytes on the way (measured between processes), and our decoders ignore trailing bytes."""
    return b"#" + hmac.digest(_key, data.rstrip(b"\x00"), hashlib.sha256).hex()[: TAG_CHARS - 1].encode()


def _frame(data: bytes) -> tuple[int, int]:
    """(frame_id's length with its NUL, data offset just past it); ValueError if it overruns."""
    if len(data) < _FRAME_AT + 4:
        raise ValueError("too short for a std_msgs/Header")
    (n,) = _U32.unpack_from(data, _FRAME_AT)
    end = _FRAME_AT + 4 + n
    if n == 0 or end > len(data):
        raise ValueError("header.frame_id overruns the message")
    return n, end


def sign(data: bytes) -> bytes:
    """`data` (a message beginning with a std_msgs/Header) with the run's tag appended to its
    frame id; unchanged without a key."""
    if _key is None:
        return data
    n, end = _frame(data)
    return b"".join((data[:_FRAME_AT], _U32.pack(n + TAG_CHARS), data[_FRAME_AT + 4:end - 1], _tag(data),
                     data[end - 1:]))


SIGNED_TYPES = frozenset({"diagnostic_msgs/msg/DiagnosticArray", "std_msgs/msg/Header"})
"""The types our own messages use (records, states, statuses, acks): they carry the tag."""


def sign_if(type_name: str, data: bytes) -> bytes:
    """`sign` for a message of `type_name` if it is one of `SIGNED_TYPES`, else `data`."""
    return sign(data) if type_name in SIGNED_TYPES else data


def strip(data: bytes) -> bytes | None:
    """`data` without its tag (unchecked), None if it has none."""
    try:
        n, end = _frame(data)
    except ValueError:
        return None
    if n <= TAG_CHARS or data[end - 1 - TAG_CHARS] != ord("#"):
        return None
    return b"".join((data[:_FRAME_AT], _U32.pack(n - TAG_CHARS), data[_FRAME_AT + 4:end - 1 - TAG_CHARS],
                     data[end - 1:]))


def verify(data: bytes) -> bytes | None:
    """The message without its tag if the tag is the run's, else None (untagged or forged);
    `data` unchanged without a key."""
    if _key is None:
        return data
    unsigned = strip(data)
    if unsigned is None:
        return None
    _, end = _frame(data)
    return unsigned if hmac.compare_digest(data[end - 1 - TAG_CHARS:end - 1], _tag(unsigned)) else None


def verified(decode):
    """`decode` (bytes -> value) applied to the verified message: raises Unauthenticated for one
    without the run's tag, so a node's guard counts it (`swarm_sim.inbound.Inbound.decode`)."""

    def decode_verified(data: bytes):
        unsigned = verify(data)
        if unsigned is None:
            raise Unauthenticated("no valid tag of this run (sent by a process outside the run?)")
        return decode(unsigned)

    return decode_verified


class Unauthenticated(ValueError):
    """A message without the run's tag where one is required."""

    reason = "unauthenticated"
    """What a node's guard counts it as (`swarm_sim.inbound.Reason.UNAUTHENTICATED`)."""


def inheritable_key_pipe(value: bytes) -> int:
    """A pipe holding `value` for one child process: returns its read end, inheritable (pass it
    with ``pass_fds`` and name it in ``SWARMFORAGE_KEY_FD``); close it in the parent once the
    child is started."""
    read, write = os.pipe()
    try:
        os.write(write, value)  # 32 bytes: far below the pipe's buffer
    finally:
        os.close(write)
    os.set_inheritable(read, True)
    return read
