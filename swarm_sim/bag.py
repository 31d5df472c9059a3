"""ROS-free rosbag2 recorder and reader with MCAP storage.

Runs are recorded inside the simulation loop and analysed without a running ROS, so neither side
may need rclpy or rosbag2_py. `mcap` (foxglove) writes and reads the files, `rosbags` supplies the
message definitions; the result is a rosbag2 directory (``metadata.yaml`` version 9, as Jazzy's
``ros2 bag record`` writes it) that ``ros2 bag``, rosbags and Foxglove open.

A run that is killed must keep almost all of its data, so the writer

* splits the bag into ``<dirname>_<i>.mcap`` every ``split_seconds`` of wall time; every file but
  the one in progress is finalised (summary, footer, the ``rosbag2`` metadata record). The next
  file is opened before the previous one is finalised, so at every instant some file is
  unfinished and any kill shows up as a truncated bag;
* closes the chunk in progress and flushes it to the OS every ``flush_seconds`` of wall time, so
  SIGKILL loses at most the last ``flush_seconds`` of writes (``fsync=True`` also survives a power
  cut);
* rewrites ``metadata.yaml`` atomically when the bag opens, at every split and at close, listing
  the finished files and the file in progress.

The reader recovers every complete record of a file that was cut off mid-write and reports it
(`BagInfo.truncated`, a `BagTruncatedWarning` naming the file); a bag without ``metadata.yaml`` is
read from its ``*.mcap`` files alone. rosbags and ``ros2 bag`` need every file finalised, so they
read a cleanly closed bag only.
"""

from __future__ import annotations

import bisect
import functools
import io
import json
import os
import re
import struct
import threading
import time
import warnings
import zlib
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass
from operator import attrgetter
from pathlib import Path, PurePath
from types import TracebackType
from typing import Any, BinaryIO

import yaml
import zstandard
from mcap.data_stream import ReadDataStream
from mcap.opcode import Opcode
from mcap.reader import SeekingReader
from mcap.records import Channel, Chunk, Header, Message, Metadata, Schema
from mcap.writer import LIBRARY_IDENTIFIER, CompressionType, Writer

try:
    import lz4.frame as lz4_frame
except ImportError:  # pragma: no cover - lz4 is optional, as in mcap
    lz4_frame = None

__all__ = [
    "QOS_NAMES",
    "BagError",
    "BagFileInfo",
    "BagInfo",
    "BagMessage",
    "BagTruncatedWarning",
    "BagWriter",
    "TopicInfo",
    "bag_info",
    "read_bag",
]

MCAP_MAGIC = b"\x89MCAP0\r\n"
METADATA_FILE = "metadata.yaml"
METADATA_VERSION = 9
ROS_DISTRO = "jazzy"
LIBRARY = f"swarm_sim.bag; {LIBRARY_IDENTIFIER}"
CUSTOM_RECORD = "custom_data"
"""Name of the MCAP metadata record, at the start of every file, that carries the custom metadata
known when the file was opened (so a lone .mcap file, or a bag killed before its first
metadata.yaml, keeps it)."""

QOS_NAMES = ("reliable", "best_effort", "latched")
_FOOTER_LENGTH = 20  # footer record body [bytes]: summary_start, summary_offset_start, crc
_U64 = 1 << 64
_NO_START = _U64  # sentinel: no message yet
_COMPRESSION = {
    "zstd": CompressionType.ZSTD,
    "lz4": CompressionType.LZ4,
    "none": CompressionType.NONE,
    "": CompressionType.NONE,
    None: CompressionType.NONE,
}


class BagError(ValueError):
    """A path is not a readable bag, or the writer was misused; the message names the path."""


class BagTruncatedWarning(UserWarning):
    """A bag file ends without its footer (the recorder was killed); complete records were kept."""


@dataclass(frozen=True, slots=True)
class BagMessage:
    """One recorded message, still CDR-serialised."""

    topic: str
    type_name: str
    """ROS type, e.g. ``geometry_msgs/msg/TwistStamped``."""
    stamp_ns: int
    """Log time [ns, sim time]."""
    data: bytes


@dataclass(frozen=True)
class TopicInfo:
    name: str
    type_name: str
    message_count: int


@dataclass(frozen=True)
class BagFileInfo:
    path: Path
    message_count: int
    start_ns: int
    """First log time [ns, sim time]; 0 when the file holds no message."""
    end_ns: int
    """Last log time [ns, sim time]; 0 when the file holds no message."""
    truncated: bool
    """The file has no footer: it was cut off mid-write; its complete records were read."""


@dataclass(frozen=True)
class BagInfo:
    path: Path
    topics: Mapping[str, TopicInfo]
    """By topic name, in name order; counts are what the files hold (not metadata.yaml)."""
    metadata: Mapping[str, str]
    """Custom metadata (metadata.yaml ``custom_data``, else the files' metadata records)."""
    files: tuple[BagFileInfo, ...]
    truncated: bool
    """Some file was cut off mid-write (see the files' ``truncated``)."""
    message_count: int
    start_ns: int
    """First log time [ns, sim time]; 0 for an empty bag."""
    end_ns: int
    """Last log time [ns, sim time]; 0 for an empty bag."""

    @property
    def message_counts(self) -> dict[str, int]:
        """Topic name -> messages recorded."""
        return {name: t.message_count for name, t in self.topics.items()}


# ------------------------------------------------------------------------------------- shared


def flatten_metadata(metadata: Mapping[str, Any], prefix: str = "") -> dict[str, str]:
    """rosbag2 ``custom_data`` holds strings only: nested keys become ``a.b``, non-strings JSON."""
    out: dict[str, str] = {}
    for key, value in metadata.items():
        name = f"{prefix}{key}"
        if isinstance(value, Mapping):
            out.update(flatten_metadata(value, name + "."))
        elif isinstance(value, str):
            out[name] = value
        else:
            out[name] = json.dumps(value, default=str)
    return out


def _normalize_type(type_name: str) -> str:
    """``pkg/Type`` -> ``pkg/msg/Type`` (rosbag2 stores the three-part name)."""
    if re.fullmatch(r"\w+/\w+", type_name):
        pkg, name = type_name.split("/")
        return f"{pkg}/msg/{name}"
    return type_name


def _infinite() -> dict[str, int]:
    # RMW_DURATION_INFINITE as rosbag2 (v9) writes it; a fresh dict each time so YAML has no aliases
    return {"sec": 9223372036, "nsec": 854775807}


def _qos_profiles(qos: str) -> list[dict[str, Any]]:
    """The offered QoS, as rosbag2 v9 writes it (policy names, not enum values)."""
    reliability, durability, depth = {
        "reliable": ("reliable", "volatile", 10),
        "best_effort": ("best_effort", "volatile", 10),
        "latched": ("reliable", "transient_local", 1),
    }[qos]
    return [
        {
            "history": "keep_last",
            "depth": depth,
            "reliability": reliability,
            "durability": durability,
            "deadline": _infinite(),
            "lifespan": _infinite(),
            "liveliness": "automatic",
            "liveliness_lease_duration": _infinite(),
            "avoid_ros_namespace_conventions": False,
        }
    ]


# libyaml's safe dumper/loader when present: the pure-Python ones take ~0.5 s for 200 topics,
# a visible stall at every split
_SafeDumper = getattr(yaml, "CSafeDumper", yaml.SafeDumper)
_SafeLoader = getattr(yaml, "CSafeLoader", yaml.SafeLoader)


@functools.cache
def _qos_yaml(qos: str) -> str:
    """The offered QoS as the YAML string an MCAP channel's metadata carries."""
    return _dump_yaml(_qos_profiles(qos))


def _dump_yaml(data: Any) -> str:
    return yaml.dump(
        data, Dumper=_SafeDumper, sort_keys=False, default_flow_style=False, width=1 << 30
    )


def _load_yaml(text: str) -> Any:
    return yaml.load(text, Loader=_SafeLoader)  # noqa: S506 - a safe loader


_TYPESTORE: Any = None
_MSGDEFS: dict[str, str] = {}


def _msgdef(type_name: str) -> str:
    """rosbag2's "ros2msg" schema text: the type's .msg, then each dependency after a ==== line."""
    global _TYPESTORE
    if type_name not in _MSGDEFS:
        if _TYPESTORE is None:
            from rosbags.typesys import Stores, get_typestore

            _TYPESTORE = get_typestore(Stores.ROS2_JAZZY)
        _MSGDEFS[type_name] = _TYPESTORE.generate_msgdef(type_name, ros_version=2)[0]
    return _MSGDEFS[type_name]


# ------------------------------------------------------------------------------------- writer


@dataclass(frozen=True)
class _Topic:
    name: str
    type_name: str
    qos: str


class _FileStats:
    """What one file holds so far (mutable: updated per write)."""

    __slots__ = ("name", "counts", "start_ns", "end_ns")

    def __init__(self, name: str) -> None:
        self.name = name
        self.counts: dict[str, int] = {}
        self.start_ns = _NO_START
        self.end_ns = -1

    @property
    def message_count(self) -> int:
        return sum(self.counts.values())


class BagWriter:
    """Records already-serialised messages into a rosbag2 directory (MCAP storage).

    Log time and publish time are the given ``stamp_ns`` (sim time); splitting and flushing
    follow ``clock`` (wall time [s], injectable for tests). The flush and split checks run inside
    `write`; call `poll` from an idle timer if writes can stop for long. Thread-safe.
    """

    def __init__(
        self,
        path: Path | str,
        *,
        split_seconds: float = 30.0,
        flush_seconds: float = 1.0,
        compression: str | None = "zstd",
        metadata: Mapping[str, Any] | None = None,
        clock: Callable[[], float] = time.monotonic,
        fsync: bool = False,
    ) -> None:
        """
        Args:
            path: bag directory to create; an existing empty directory is used, a non-empty one
                is refused.
            split_seconds: start a new file after this much wall time [s] (math.inf: never).
            flush_seconds: write the chunk in progress to the OS after this much wall time [s].
            compression: chunk compression, "zstd", "lz4" or "none".
            metadata: custom metadata (scenario, seed, ...), flattened to strings.
            clock: wall clock [s].
            fsync: also fsync at every flush (survives a power cut, costs a few ms each time).
        """
        self.path = Path(path)
        if not split_seconds > 0 or not flush_seconds > 0:
            raise BagError(f"{self.path}: split_seconds and flush_seconds must be > 0")
        if compression not in _COMPRESSION:
            raise BagError(f"{self.path}: unknown compression {compression!r} (zstd, lz4, none)")
        if self.path.exists():
            if not self.path.is_dir():
                raise BagError(f"{self.path}: exists and is not a directory")
            if any(self.path.iterdir()):
                raise BagError(f"{self.path}: directory exists and is not empty; not overwriting")
        self.path.mkdir(parents=True, exist_ok=True)
        self.split_seconds = float(split_seconds)
        self.flush_seconds = float(flush_seconds)
        self._compression = _COMPRESSION[compression]
        self._clock = clock
        self._fsync = fsync
        self._custom = flatten_metadata(metadata or {})
        self._topics: dict[str, _Topic] = {}
        self._finished: list[_FileStats] = []
        self._lock = threading.Lock()
        self._closed = False
        # per file in progress
        self._stream: BinaryIO | None = None
        self._writer: Writer | None = None
        self._file: _FileStats | None = None
        self._channels: dict[str, int] = {}
        self._schemas: dict[str, int] = {}
        self._split_at = self._next_flush = self._deadline = 0.0
        self._start_file(self._clock())
        self._write_metadata_yaml()

    # ----------------------------------------------------------------------------- public

    def add_topic(self, name: str, type_name: str, qos: str = "reliable") -> None:
        """Register a topic (idempotent for the same type and QoS)."""
        type_name = _normalize_type(type_name)
        with self._lock:
            self._check_open()
            if not name.startswith("/"):
                raise BagError(f"{self.path}: topic {name!r} must be fully qualified ('/...')")
            if qos not in QOS_NAMES:
                raise BagError(f"{self.path}: topic {name}: qos {qos!r} not one of {QOS_NAMES}")
            topic = _Topic(name, type_name, qos)
            known = self._topics.get(name)
            if known is not None:
                if known != topic:
                    raise BagError(
                        f"{self.path}: topic {name} already registered as {known.type_name} "
                        f"({known.qos}), not {type_name} ({qos})"
                    )
                return
            try:
                _msgdef(type_name)
            except Exception as exc:  # rosbags TypesysError and friends
                raise BagError(
                    f"{self.path}: topic {name}: no message definition for {type_name!r} in the "
                    f"Jazzy typestore ({exc})"
                ) from None
            self._topics[name] = topic
            self._register(topic)

    def write(self, topic: str, stamp_ns: int, data: bytes) -> None:
        """Append CDR bytes as they are (log time = publish time = stamp_ns [ns, sim time])."""
        with self._lock:
            now = self._clock()
            if now >= self._deadline:
                self._on_deadline(now)
            channel = self._channels.get(topic)
            if channel is None:
                raise self._unwritable(topic)
            if not 0 <= stamp_ns < _U64:
                raise BagError(f"{self.path}: {topic}: stamp_ns {stamp_ns!r} outside [0, 2**64)")
            writer, stats = self._writer, self._file
            assert writer is not None and stats is not None
            writer.add_message(channel, stamp_ns, data, stamp_ns)
            stats.counts[topic] += 1
            if stamp_ns < stats.start_ns:
                stats.start_ns = stamp_ns
            if stamp_ns > stats.end_ns:
                stats.end_ns = stamp_ns

    def poll(self) -> None:
        """Apply the flush/split policy without writing (for idle periods)."""
        with self._lock:
            if not self._closed:
                now = self._clock()
                if now >= self._deadline:
                    self._on_deadline(now)

    def flush(self) -> None:
        """Write the chunk in progress to the OS now."""
        with self._lock:
            if self._writer is not None:
                self._flush()

    def set_metadata(self, **items: Any) -> None:
        """Add or replace custom metadata; metadata.yaml is rewritten at once."""
        with self._lock:
            self._check_open()
            self._custom.update(flatten_metadata(items))
            self._write_metadata_yaml()

    @property
    def files(self) -> tuple[Path, ...]:
        """Files written so far, the one in progress last."""
        names = [f.name for f in self._finished] + ([self._file.name] if self._file else [])
        return tuple(self.path / n for n in names)

    def close(self) -> None:
        """Finalise the file in progress and metadata.yaml (idempotent)."""
        with self._lock:
            if self._closed:
                return
            writer, stream, stats = self._writer, self._stream, self._file
            assert writer is not None and stream is not None and stats is not None
            self._writer = self._stream = self._file = None
            self._channels = {}
            if stats.message_count == 0 and self._finished:  # opened by a split, never used
                stream.close()
                self._write_metadata_yaml()  # unlist it first: a listed file must exist
                (self.path / stats.name).unlink()
            else:
                self._finished.append(stats)
                self._finalize(writer, stream)
                self._write_metadata_yaml()
            self._closed = True

    def __enter__(self) -> BagWriter:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self.close()

    # ----------------------------------------------------------------------------- internals

    def _check_open(self) -> None:
        if self._closed:
            raise BagError(f"{self.path}: bag writer is closed")

    def _unwritable(self, topic: str) -> BagError:
        if self._closed:
            return BagError(f"{self.path}: bag writer is closed")
        return BagError(f"{self.path}: topic {topic!r} not registered (call add_topic first)")

    def _register(self, topic: _Topic) -> None:
        writer = self._writer
        assert writer is not None and self._file is not None
        schema = self._schemas.get(topic.type_name)
        if schema is None:
            schema = writer.register_schema(
                topic.type_name, "ros2msg", _msgdef(topic.type_name).encode()
            )
            self._schemas[topic.type_name] = schema
        self._channels[topic.name] = writer.register_channel(
            topic.name,
            "cdr",
            schema,
            {"offered_qos_profiles": _qos_yaml(topic.qos)},
        )
        self._file.counts.setdefault(topic.name, 0)

    def _start_file(self, now: float) -> None:
        name = f"{self.path.name}_{len(self._finished)}.mcap"
        stream = open(self.path / name, "xb")  # noqa: SIM115 - closed in _finalize or close
        writer = Writer(stream, compression=self._compression)
        writer.start(profile="ros2", library=LIBRARY)
        if self._custom:
            writer.add_metadata(CUSTOM_RECORD, dict(self._custom))
        self._stream, self._writer, self._file = stream, writer, _FileStats(name)
        self._channels, self._schemas = {}, {}
        for topic in self._topics.values():
            self._register(topic)
        stream.flush()
        self._split_at = now + self.split_seconds
        self._next_flush = now + self.flush_seconds
        self._deadline = min(self._split_at, self._next_flush)

    def _flush(self) -> None:
        assert self._writer is not None and self._stream is not None
        self._writer.flush()
        if self._fsync:
            os.fsync(self._stream.fileno())

    def _on_deadline(self, now: float) -> None:
        """Split or flush."""
        assert self._file is not None
        if now >= self._split_at and self._file.message_count > 0:
            writer, stream = self._writer, self._stream
            assert writer is not None and stream is not None
            writer.flush()  # this file's data reaches the OS first
            self._finished.append(self._file)
            # the next file exists before this one is finalised: at every instant some file is
            # unfinished, so a kill always shows as a truncated bag
            self._start_file(now)
            self._finalize(writer, stream)
            self._write_metadata_yaml()
            return
        self._flush()
        if now >= self._split_at:  # nothing written for a whole period: no split
            self._split_at = now + self.split_seconds
        self._next_flush = now + self.flush_seconds
        self._deadline = min(self._split_at, self._next_flush)

    def _finalize(self, writer: Writer, stream: BinaryIO) -> None:
        """Summary, footer and the rosbag2 record (the file is already in `_finished`).

        The record's YAML is written in flow style (JSON): rosbag2 reads it with yaml-cpp all
        the same, and json costs ~1 ms where a block-style YAML dump costs tens (200 topics).
        """
        writer.flush()  # the last chunk first, so the rosbag2 record follows the data
        info = json.dumps(self._bag_information(), ensure_ascii=False)
        writer.add_metadata("rosbag2", {"serialized_metadata": info})
        writer.finish()
        stream.flush()
        if self._fsync:
            os.fsync(stream.fileno())
        stream.close()

    def _bag_information(self) -> dict[str, Any]:
        """``rosbag2_bagfile_information`` as Jazzy writes it (metadata version 9)."""
        files = self._finished + ([self._file] if self._file is not None else [])
        totals = dict.fromkeys(self._topics, 0)
        for f in files:
            for topic, count in f.counts.items():
                totals[topic] += count
        used = [f for f in files if f.end_ns >= 0]
        start = min((f.start_ns for f in used), default=0)
        end = max((f.end_ns for f in used), default=0)

        def span(f: _FileStats) -> tuple[int, int]:
            return (f.start_ns, f.end_ns - f.start_ns) if f.end_ns >= 0 else (0, 0)

        return {
            "version": METADATA_VERSION,
            "storage_identifier": "mcap",
            "duration": {"nanoseconds": end - start},
            "starting_time": {"nanoseconds_since_epoch": start},
            "message_count": sum(totals.values()),
            "topics_with_message_count": [
                {
                    "topic_metadata": {
                        "name": t.name,
                        "type": t.type_name,
                        "serialization_format": "cdr",
                        "offered_qos_profiles": _qos_profiles(t.qos),
                        "type_description_hash": "",
                    },
                    "message_count": totals[t.name],
                }
                for t in self._topics.values()
            ],
            "compression_format": "",
            "compression_mode": "",
            "relative_file_paths": [f.name for f in files],
            "files": [
                {
                    "path": f.name,
                    "starting_time": {"nanoseconds_since_epoch": span(f)[0]},
                    "duration": {"nanoseconds": span(f)[1]},
                    "message_count": f.message_count,
                }
                for f in files
            ],
            "custom_data": dict(self._custom),
            "ros_distro": ROS_DISTRO,
        }

    def _write_metadata_yaml(self) -> None:
        text = _dump_yaml({"rosbag2_bagfile_information": self._bag_information()})
        tmp = self.path / (METADATA_FILE + ".tmp")
        with open(tmp, "w", encoding="utf-8") as f:
            f.write(text)
            f.flush()
            if self._fsync:
                os.fsync(f.fileno())
        os.replace(tmp, self.path / METADATA_FILE)


# ------------------------------------------------------------------------------------- reader


def _bag_files(path: Path) -> tuple[Path, list[Path], dict[str, Any] | None]:
    """(bag directory or file, its .mcap files in order, metadata.yaml's information or None)."""
    if not path.exists():
        raise BagError(f"{path}: no such file or directory")
    if path.is_file():
        if path.name == METADATA_FILE:
            path = path.parent
        elif path.suffix == ".mcap":
            return path, [path], None
        else:
            raise BagError(f"{path}: not a bag (expected a rosbag2 directory or an .mcap file)")
    meta = _load_metadata(path / METADATA_FILE) if (path / METADATA_FILE).exists() else None
    found = sorted(path.glob("*.mcap"), key=_file_order)
    if meta is None:
        if not found:
            raise BagError(f"{path}: not a bag (no {METADATA_FILE} and no .mcap files)")
        return path, found, None
    listed = [path / PurePath(str(p)).name for p in meta["relative_file_paths"]]
    missing = [p.name for p in listed if not p.is_file()]
    if missing:
        raise BagError(f"{path}: files listed in {METADATA_FILE} are missing: {missing}")
    # a file opened after the last metadata.yaml rewrite is still part of the bag
    return path, listed + [p for p in found if p not in listed], meta


def _file_order(p: Path) -> tuple[int, str]:
    m = re.search(r"_(\d+)\.mcap$", p.name)
    return (int(m.group(1)) if m else -1, p.name)


def _load_metadata(path: Path) -> dict[str, Any]:
    try:
        doc = _load_yaml(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, yaml.YAMLError) as exc:
        raise BagError(f"{path}: unreadable: {exc}") from None
    info = doc.get("rosbag2_bagfile_information") if isinstance(doc, dict) else None
    if not isinstance(info, dict):
        raise BagError(f"{path}: not rosbag2 metadata (no rosbag2_bagfile_information)")
    storage = info.get("storage_identifier")
    if storage != "mcap":
        raise BagError(f"{path}: storage {storage!r} not supported (only mcap)")
    if not isinstance(info.get("relative_file_paths"), list):
        raise BagError(f"{path}: relative_file_paths missing")
    if info.get("compression_mode") not in (None, "", "none", "None", "NONE"):
        raise BagError(f"{path}: file/message compression not supported (only MCAP chunk)")
    return info


_RECORD_HEAD = struct.Struct("<BQ")  # opcode, body length [bytes]
_MESSAGE_HEAD = struct.Struct("<HIQQ")  # channel id, sequence, log time, publish time
_MESSAGE_HEAD_SIZE = 22


def _decompress(chunk: Chunk) -> bytes:
    """A chunk's records, CRC-checked."""
    if chunk.compression == "zstd":
        raw: bytes = zstandard.decompress(chunk.data, max_output_size=chunk.uncompressed_size)
    elif chunk.compression == "lz4":
        if lz4_frame is None:
            raise ValueError("lz4 chunk but the lz4 package is missing")
        raw = lz4_frame.decompress(chunk.data)
    elif chunk.compression == "":
        raw = chunk.data
    else:
        raise ValueError(f"unsupported chunk compression {chunk.compression!r}")
    if len(raw) != chunk.uncompressed_size:
        raise ValueError(f"chunk holds {len(raw)} bytes, expected {chunk.uncompressed_size}")
    if chunk.uncompressed_crc and zlib.crc32(raw) != chunk.uncompressed_crc:
        raise ValueError("chunk CRC mismatch")
    return raw


def _read_chunk(f: BinaryIO, offset: int) -> Chunk:
    f.seek(offset)
    head = f.read(_RECORD_HEAD.size)
    if len(head) != _RECORD_HEAD.size:
        raise ValueError(f"no chunk record at byte {offset}")
    opcode, length = _RECORD_HEAD.unpack(head)
    if opcode != Opcode.CHUNK:
        raise ValueError(f"expected a chunk at byte {offset}, found {_opname(opcode)}")
    body = f.read(length)
    if len(body) != length:
        raise ValueError(f"chunk at byte {offset} is cut off")
    return Chunk.read(ReadDataStream(io.BytesIO(body)))


def _chunk_messages(
    raw: bytes, schemas: dict[int, Schema], channels: dict[int, Channel]
) -> list[tuple[int, int, bytes]]:
    """(log time, channel id, data) of a decompressed chunk's messages, in chunk order; schema
    and channel records found on the way are added to `schemas` and `channels`."""
    out: list[tuple[int, int, bytes]] = []
    append = out.append
    head, message = _RECORD_HEAD.unpack_from, _MESSAGE_HEAD.unpack_from
    pos, n = 0, len(raw)
    while pos < n:
        opcode, length = head(raw, pos)
        body = pos + _RECORD_HEAD.size
        pos = body + length
        if pos > n:
            raise ValueError("a record overruns its chunk")
        if opcode == Opcode.MESSAGE:
            channel, _, log_time, _ = message(raw, body)
            append((log_time, channel, raw[body + _MESSAGE_HEAD_SIZE : pos]))
        elif opcode == Opcode.SCHEMA:
            schema = Schema.read(ReadDataStream(io.BytesIO(raw[body:pos])))
            schemas[schema.id] = schema
        elif opcode == Opcode.CHANNEL:
            record = Channel.read(ReadDataStream(io.BytesIO(raw[body:pos])))
            channels[record.id] = record
    return out


def _opname(opcode: int) -> str:
    try:
        return Opcode(opcode).name
    except ValueError:
        return f"opcode 0x{opcode:02x}"


def _has_footer(path: Path) -> bool:
    """The file ends with a footer record and the magic (it was finalised)."""
    size = path.stat().st_size
    tail = _RECORD_HEAD.size + _FOOTER_LENGTH + len(MCAP_MAGIC)
    if size < len(MCAP_MAGIC) + tail:
        return False
    with open(path, "rb") as f:
        head = f.read(len(MCAP_MAGIC))
        f.seek(-tail, os.SEEK_END)
        end = f.read(tail)
    return (
        head == MCAP_MAGIC
        and end[-len(MCAP_MAGIC) :] == MCAP_MAGIC
        and _RECORD_HEAD.unpack_from(end) == (Opcode.FOOTER, _FOOTER_LENGTH)
    )


class _McapFile:
    """One file of a bag, indexed: from its summary when finalised, else by scanning its records
    (which keeps every complete record before a cut)."""

    def __init__(self, path: Path, index: int) -> None:
        self.path = path
        self.index = index
        self.schemas: dict[int, Schema] = {}
        self.channels: dict[int, Channel] = {}
        self.counts: dict[int, int] = {}
        self.start_ns, self.end_ns = _NO_START, -1
        self.chunks: list[tuple[int, int]] = []
        """(first log time [ns], byte offset) of each chunk."""
        self.loose: list[tuple[int, int, bytes]] = []
        """Messages outside chunks (other writers), as (log time, channel id, data)."""
        self.metadata: list[Metadata] | None = None
        """Metadata records, when scanned (read from the index on demand otherwise)."""
        self.problem: str | None = None
        """Why the file is truncated; None when it is complete."""
        if not (_has_footer(path) and self._read_summary()):
            self._scan()

    def _read_summary(self) -> bool:
        try:
            with open(self.path, "rb") as f:
                summary = SeekingReader(f).get_summary()
        except Exception:  # an unusable summary: scan instead
            return False
        if summary is None or summary.statistics is None:
            return False
        stats = summary.statistics
        if stats.message_count and not summary.chunk_indexes:
            return False  # unchunked
        self.schemas, self.channels = dict(summary.schemas), dict(summary.channels)
        self.counts = dict(stats.channel_message_counts)
        if stats.message_count:
            self.start_ns, self.end_ns = stats.message_start_time, stats.message_end_time
        self.chunks = [(c.message_start_time, c.chunk_start_offset) for c in summary.chunk_indexes]
        return True

    def _scan(self) -> None:
        path = self.path
        try:
            data = path.read_bytes()
        except OSError as exc:
            raise BagError(f"{path}: unreadable: {exc}") from None
        self.metadata = []
        n = len(data)
        if n < len(MCAP_MAGIC) and MCAP_MAGIC.startswith(data):
            self.problem = f"cut off after {n} bytes, inside the magic"
            return
        if data[: len(MCAP_MAGIC)] != MCAP_MAGIC:
            raise BagError(f"{path}: not an MCAP file (bad magic)")
        pos = len(MCAP_MAGIC)
        while True:
            if pos + _RECORD_HEAD.size > n:
                where = "" if pos == n else f", inside a record header at byte {pos}"
                self.problem = f"cut off after {n} bytes{where} (no footer)"
                return
            opcode, length = _RECORD_HEAD.unpack_from(data, pos)
            if pos == len(MCAP_MAGIC) and opcode != Opcode.HEADER:
                raise BagError(f"{path}: not an MCAP file (no header record)")
            end = pos + _RECORD_HEAD.size + length
            if end > n:
                self.problem = (
                    f"cut off after {n} bytes, inside a {_opname(opcode)} record at byte {pos}"
                )
                return
            stream = ReadDataStream(io.BytesIO(data[pos + _RECORD_HEAD.size : end]))
            try:
                if opcode == Opcode.HEADER:
                    Header.read(stream)
                elif opcode == Opcode.CHUNK:
                    chunk = Chunk.read(stream)
                    found = _chunk_messages(_decompress(chunk), self.schemas, self.channels)
                    for log_time, channel, _ in found:
                        self._count(log_time, channel)
                    if found:
                        self.chunks.append((chunk.message_start_time, pos))
                elif opcode == Opcode.MESSAGE:
                    msg = Message.read(stream, length)
                    self._count(msg.log_time, msg.channel_id)
                    self.loose.append((msg.log_time, msg.channel_id, msg.data))
                elif opcode == Opcode.SCHEMA:
                    schema = Schema.read(stream)
                    self.schemas[schema.id] = schema
                elif opcode == Opcode.CHANNEL:
                    channel = Channel.read(stream)
                    self.channels[channel.id] = channel
                elif opcode == Opcode.METADATA:
                    self.metadata.append(Metadata.read(stream))
            except Exception as exc:  # mcap, zstd, struct, unicode: an unreadable record
                self.problem = f"unreadable {_opname(opcode)} record at byte {pos} ({exc})"
                return
            pos = end
            if opcode == Opcode.FOOTER:
                if data[pos:] != MCAP_MAGIC:
                    self.problem = f"cut off after {n} bytes, inside the closing magic"
                return

    def _count(self, log_time: int, channel: int) -> None:
        self.counts[channel] = self.counts.get(channel, 0) + 1
        self.start_ns = min(self.start_ns, log_time)
        self.end_ns = max(self.end_ns, log_time)

    def warn(self) -> None:
        if self.problem is not None:
            warnings.warn(
                f"{self.path}: {self.problem}; recovered the {self.info().message_count} "
                "complete messages before the cut",
                BagTruncatedWarning,
                stacklevel=3,
            )

    def info(self) -> BagFileInfo:
        count = sum(self.counts.values())
        start, end = (self.start_ns, self.end_ns) if count else (0, 0)
        return BagFileInfo(self.path, count, start, end, self.problem is not None)

    def names(self) -> dict[int, tuple[str, str]]:
        """channel id -> (topic, type name)."""
        out = {}
        for cid, channel in self.channels.items():
            schema = self.schemas.get(channel.schema_id)
            out[cid] = (channel.topic, schema.name if schema else "")
        return out

    def topics(self) -> dict[str, tuple[str, int]]:
        """topic -> (type name, message count)."""
        out: dict[str, tuple[str, int]] = {}
        for cid, (topic, type_name) in self.names().items():
            known_type, count = out.get(topic, (type_name, 0))
            out[topic] = (known_type, count + self.counts.get(cid, 0))
        return out

    def custom_metadata(self) -> dict[str, str]:
        """Custom metadata from the file's records: the opening record, then rosbag2's."""
        records = self.metadata
        if records is None:
            with open(self.path, "rb") as f:
                records = list(SeekingReader(f).iter_metadata())
        out: dict[str, str] = {}
        for record in records:
            if record.name == CUSTOM_RECORD:
                out.update(record.metadata)
            elif record.name == "rosbag2" and "serialized_metadata" in record.metadata:
                try:
                    info = _load_yaml(record.metadata["serialized_metadata"])
                    out.update({str(k): str(v) for k, v in (info.get("custom_data") or {}).items()})
                except (yaml.YAMLError, AttributeError):
                    pass
        return out

    def refs(self) -> list[tuple[int, int, int, _McapFile]]:
        """(first log time, file index, offset, file) per chunk; offset -1: the loose messages."""
        out = [(start, self.index, offset, self) for start, offset in self.chunks]
        if self.loose:
            out.append((min(m[0] for m in self.loose), self.index, -1, self))
        return out

    def load(self, f: BinaryIO, offset: int) -> list[BagMessage]:
        """The messages of the chunk at `offset` (-1: the loose ones), in chunk order."""
        if offset < 0:
            found = self.loose
        else:
            raw = _decompress(_read_chunk(f, offset))
            found = _chunk_messages(raw, self.schemas, self.channels)
        names = self.names()
        return [
            BagMessage(*names[channel], log_time, data)
            for log_time, channel, data in found
            if channel in names  # a message whose channel record was lost cannot be named
        ]


def _open_files(path: Path | str) -> tuple[Path, list[_McapFile], dict[str, Any] | None]:
    root, paths, meta = _bag_files(Path(path))
    return root, [_McapFile(p, i) for i, p in enumerate(paths)], meta


def read_bag(path: Path | str) -> Iterator[BagMessage]:
    """Every message of a bag (directory or single .mcap file) in log-time order across files;
    equal stamps keep their write order.

    A file cut off mid-write yields its complete records and a `BagTruncatedWarning`. Raises
    `BagError` for a path that is not a bag or a file that is not MCAP.
    """
    _, files, _ = _open_files(path)
    for f in files:
        f.warn()
    return _merge(files)


def _merge(files: list[_McapFile]) -> Iterator[BagMessage]:
    """Chunks in order of their first stamp; a message is released once no chunk still to be
    read can hold an earlier one, so memory stays near one chunk."""
    refs = sorted(ref for f in files for ref in f.refs())
    handles: dict[int, BinaryIO] = {}
    buffer: list[BagMessage] = []
    stamp = attrgetter("stamp_ns")
    try:
        for start, index, offset, f in refs:
            if buffer and buffer[0].stamp_ns < start:
                cut = bisect.bisect_left(buffer, start, key=stamp)
                yield from buffer[:cut]
                del buffer[:cut]
            if index not in handles:
                handles[index] = open(f.path, "rb")  # noqa: SIM115 - closed below
            try:
                buffer.extend(f.load(handles[index], offset))
            except Exception as exc:
                raise BagError(f"{f.path}: corrupt chunk at byte {offset} ({exc})") from None
            buffer.sort(key=stamp)  # stable: equal stamps keep chunk order
        yield from buffer
    finally:
        for handle in handles.values():
            handle.close()


def bag_info(path: Path | str) -> BagInfo:
    """Topics, counts, custom metadata and files of a bag, from its files (metadata.yaml may be
    stale after a crash). Warns (`BagTruncatedWarning`) for each file cut off mid-write."""
    root, files, meta = _open_files(path)
    for f in files:
        f.warn()
    infos = tuple(f.info() for f in files)
    topics: dict[str, tuple[str, int]] = {}
    if meta is not None:  # topics registered but never written still belong to the bag
        for entry in meta.get("topics_with_message_count") or []:
            tm = entry.get("topic_metadata") if isinstance(entry, dict) else None
            if isinstance(tm, dict) and "name" in tm:
                topics[str(tm["name"])] = (str(tm.get("type", "")), 0)
    for f in files:
        for name, (type_name, count) in f.topics().items():
            known_type, known = topics.get(name, (type_name, 0))
            topics[name] = (known_type or type_name, known + count)
    if meta is not None and isinstance(meta.get("custom_data"), dict):
        custom = {str(k): str(v) for k, v in meta["custom_data"].items()}
    else:
        custom = {}
        for f in files:
            custom.update(f.custom_metadata())
    used = [i for i in infos if i.message_count]
    return BagInfo(
        path=root,
        topics={n: TopicInfo(n, t, c) for n, (t, c) in sorted(topics.items())},
        metadata=custom,
        files=infos,
        truncated=any(i.truncated for i in infos),
        message_count=sum(i.message_count for i in infos),
        start_ns=min((i.start_ns for i in used), default=0),
        end_ns=max((i.end_ns for i in used), default=0),
    )
