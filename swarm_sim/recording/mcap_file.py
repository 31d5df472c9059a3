"""One MCAP file read record by record, recovering every complete record of a file that was
cut off mid-write (the storage layer under `swarm_sim.recording.reader`)."""

from __future__ import annotations

import io
import os
import struct
import warnings
import zlib
from pathlib import Path
from typing import BinaryIO

import yaml
import zstandard
from mcap.data_stream import ReadDataStream
from mcap.opcode import Opcode
from mcap.reader import SeekingReader
from mcap.records import Channel, Chunk, Header, Message, Metadata, Schema

try:
    import lz4.frame as lz4_frame
except ImportError:  # pragma: no cover - lz4 is optional, as in mcap
    lz4_frame = None

from swarm_sim.recording.metadata import (
    _FOOTER_LENGTH,
    _NO_START,
    CUSTOM_RECORD,
    MCAP_MAGIC,
    BagError,
    BagFileInfo,
    BagMessage,
    BagTruncatedWarning,
    _load_yaml,
)

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


