"""`BagWriter`: a rosbag2 directory of MCAP files, flushed on wall time so a killed run keeps
almost everything (see `swarm_sim.recording`): one file per run by default, as ``ros2 bag record``
leaves it; splitting into several files on wall time stays an option (``split_seconds``)."""

from __future__ import annotations

import json
import math
import os
import struct
import threading
import time
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path
from types import TracebackType
from typing import Any, BinaryIO

from mcap.records import MessageIndex
from mcap.writer import Writer

try:
    import lz4.frame as lz4_frame
except ImportError:  # pragma: no cover - lz4 is optional, as in mcap
    lz4_frame = None

from swarm_sim.recording.metadata import (
    _COMPRESSION,
    _NO_START,
    _U64,
    CUSTOM_RECORD,
    LIBRARY,
    METADATA_FILE,
    METADATA_VERSION,
    QOS_NAMES,
    ROS_DISTRO,
    BagError,
    _dump_yaml,
    _msgdef,
    _normalize_type,
    _qos_profiles,
    _qos_yaml,
    _type_hash,
    flatten_metadata,
)

_MESSAGE_HEAD = struct.Struct("<BQHIQQ")
"""An MCAP Message record's head: opcode 0x05, record length, channel id, sequence, log time,
publish time (the data follows)."""


class _Index(MessageIndex):
    """mcap's `MessageIndex` written in two steps (mcap writes each entry's two numbers one call
    at a time when it finishes a chunk): the same bytes."""

    def write(self, stream) -> None:
        records = self.records
        stream.write(_INDEX_HEAD.pack(0x07, 6 + 16 * len(records), self.channel_id, 16 * len(records)))
        stream.write(struct.pack(f"<{2 * len(records)}Q", *(n for record in records for n in record)))


_INDEX_HEAD = struct.Struct("<BQHI")
"""An MCAP Message Index record's head: opcode 0x07, record length, channel id, entries' length."""


class _Writer(Writer):
    """mcap's `Writer` whose messages go into the open chunk in a few steps: the same bytes,
    index and statistics as mcap's own `add_message` (a dataclass, a dozen method calls and a
    seek back per message, and two calls per index entry), which were a fifth of the world
    node's Python with 112 robots (560 messages recorded a tick); `add_batch` takes a tick's
    messages in one call. Relies on mcap 1.x's private members, checked at import; without them
    it is mcap's own `add_message`."""

    _OWN = hasattr(Writer, "_Writer__maybe_finalize_chunk")

    def add_message(self, channel_id: int, log_time: int, data: bytes, publish_time: int, sequence: int = 0):
        if self._own():
            self._add(((channel_id, data),), log_time, publish_time, sequence)
        else:
            super().add_message(channel_id, log_time, data, publish_time, sequence)

    def add_batch(self, messages: Iterable[tuple[int, bytes]], log_time: int) -> None:
        """`add_message(channel_id, log_time, data, log_time)` for each (channel_id, data)."""
        if self._own():
            self._add(messages, log_time, log_time, 0)
        else:
            for channel_id, data in messages:
                super().add_message(channel_id, log_time, data, log_time)

    def _own(self) -> bool:
        """Whether the fast path applies (mcap's private members found, a chunked file)."""
        return (self._OWN and getattr(self, "_Writer__chunk_builder", None) is not None
                and isinstance(getattr(self, "_Writer__chunk_size", None), int))

    def _add(self, messages: Iterable[tuple[int, bytes]], log_time: int, publish_time: int, sequence: int) -> None:
        stats = self._Writer__statistics
        counts = stats.channel_message_counts
        chunk = self._Writer__chunk_builder
        limit = self._Writer__chunk_size
        pack = _MESSAGE_HEAD.pack
        buffer = chunk.record_writer._buffer
        write, position, indices = buffer.write, buffer.tell(), chunk.message_indices
        for channel_id, data in messages:
            if stats.message_count == 0 or log_time < stats.message_start_time:
                stats.message_start_time = log_time
            if log_time > stats.message_end_time:
                stats.message_end_time = log_time
            counts[channel_id] += 1
            stats.message_count += 1
            if chunk.num_messages == 0 or log_time < chunk.message_start_time:
                chunk.message_start_time = log_time
            if log_time > chunk.message_end_time:
                chunk.message_end_time = log_time
            index = indices.get(channel_id)
            if not index:
                index = indices[channel_id] = _Index(channel_id=channel_id, records=[])
            index.records.append((log_time, position))
            chunk.num_messages += 1
            write(pack(0x05, 22 + len(data), channel_id, sequence, log_time, publish_time))
            write(data)
            position += 31 + len(data)
            if position > limit:  # mcap's __maybe_finalize_chunk; the next chunk has a new buffer
                self._Writer__maybe_finalize_chunk()
                buffer = chunk.record_writer._buffer
                write, position = buffer.write, buffer.tell()


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
        split_seconds: float = math.inf,
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
            split_seconds: start a new file after this much wall time [s] (math.inf, the default:
                never; a cut file loses only what was not flushed, and ``--repair`` recovers every
                complete message before the cut).
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
        self._offered: dict[str, list[dict[str, Any]]] = {}
        """Topic -> the offered QoS profiles its publishers reported (`set_offered_qos`)."""
        self._hashes: dict[str, str] = {}
        """Topic -> type description hash."""
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
                self._hashes[name] = _type_hash(type_name)
            except Exception as exc:  # rosbags TypesysError and friends
                raise BagError(
                    f"{self.path}: topic {name}: no message definition for {type_name!r} in the "
                    f"Jazzy typestore ({exc})"
                ) from None
            self._topics[name] = topic
            self._register(topic)

    def set_offered_qos(self, name: str, profiles: list[Mapping[str, Any]], type_hash: str | None = None) -> None:
        """The QoS profiles `name`'s publishers offer (rosbag2's per-policy dicts, one per
        publisher, as ``ros2 bag record`` writes them) and the type hash the graph reports; they
        replace the defaults `add_topic`'s `qos` implied in metadata.yaml and in the files opened
        from now on."""
        with self._lock:
            self._check_open()
            if name not in self._topics:
                raise BagError(f"{self.path}: topic {name!r} not registered (call add_topic first)")
            self._offered[name] = [dict(p) for p in profiles]
            if type_hash:
                self._hashes[name] = type_hash

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

    def write_all(self, stamp_ns: int, items: list[tuple[str, bytes]]) -> None:
        """`write` for many (topic, data) of one stamp: one lock, one clock read (a tick's
        observations: 4,000 messages with 1000 robots)."""
        with self._lock:
            now = self._clock()
            if now >= self._deadline:
                self._on_deadline(now)
            if not 0 <= stamp_ns < _U64:
                raise BagError(f"{self.path}: stamp_ns {stamp_ns!r} outside [0, 2**64)")
            writer, stats, channels = self._writer, self._file, self._channels
            assert writer is not None and stats is not None
            counts = stats.counts
            batch = []
            for topic, data in items:
                channel = channels.get(topic)
                if channel is None:
                    raise self._unwritable(topic)
                batch.append((channel, data))
                counts[topic] += 1
            writer.add_batch(batch, stamp_ns)
            if items:
                stats.start_ns = min(stats.start_ns, stamp_ns)
                stats.end_ns = max(stats.end_ns, stamp_ns)

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
            {"offered_qos_profiles": _dump_yaml(self._offered[topic.name]) if topic.name in self._offered
             else _qos_yaml(topic.qos)},
        )
        self._file.counts.setdefault(topic.name, 0)

    def _start_file(self, now: float) -> None:
        name = f"{self.path.name}_{len(self._finished)}.mcap"
        stream = open(self.path / name, "xb")  # noqa: SIM115 - closed in _finalize or close
        writer = _Writer(stream, compression=self._compression)
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
                        "offered_qos_profiles": self._offered.get(t.name) or _qos_profiles(t.qos),
                        "type_description_hash": self._hashes.get(t.name, ""),
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


