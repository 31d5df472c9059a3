"""Reading a bag directory: its files in order, merged by time (`read_bag`), and what it
holds (`bag_info`)."""

from __future__ import annotations

import bisect
import re
from collections.abc import Iterator
from operator import attrgetter
from pathlib import Path, PurePath
from typing import Any, BinaryIO

import yaml

try:
    import lz4.frame as lz4_frame
except ImportError:  # pragma: no cover - lz4 is optional, as in mcap
    lz4_frame = None

from swarm_sim.recording.mcap_file import _McapFile
from swarm_sim.recording.metadata import (
    METADATA_FILE,
    BagError,
    BagFileInfo,
    BagInfo,
    BagMessage,
    TopicInfo,
    _load_yaml,
)


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
    meta_path = path / METADATA_FILE
    meta = _load_metadata(meta_path) if meta_path.exists() or meta_path.is_symlink() else None
    found = sorted(path.glob("*.mcap"), key=_file_order)
    odd = [p.name for p in found if not p.is_file()]
    if odd:  # a FIFO would block the reader forever
        raise BagError(f"{path}: {odd[0]} is not a regular file")
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


MAX_METADATA_BYTES = 64 << 20
"""metadata.yaml larger than this is refused unread (a 1000-topic bag's is under 2 MB)."""


def _file_order(p: Path) -> tuple[int, str]:
    m = re.search(r"_(\d+)\.mcap$", p.name)
    return (int(m.group(1)) if m else -1, p.name)


def _load_metadata(path: Path) -> dict[str, Any]:
    if not path.is_file():  # a FIFO would block the read forever; a directory, a dangling link
        raise BagError(f"{path}: not a regular file")
    if path.stat().st_size > MAX_METADATA_BYTES:
        raise BagError(f"{path}: {path.stat().st_size} bytes is larger than a bag's metadata can be")
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
        lost=_lost(files, infos, meta),
        path=root,
        topics={n: TopicInfo(n, t, c) for n, (t, c) in sorted(topics.items())},
        metadata=custom,
        files=infos,
        truncated=any(i.truncated for i in infos),
        message_count=sum(i.message_count for i in infos),
        start_ns=min((i.start_ns for i in used), default=0),
        end_ns=max((i.end_ns for i in used), default=0),
    )



def _lost(files: list[_McapFile], infos: tuple[BagFileInfo, ...], meta: dict[str, Any] | None) -> tuple[str, ...]:
    """What a bag lost, one line per file: cut off (no footer: the complete records before the cut
    were read), or holding fewer messages than metadata.yaml says it was written with."""
    listed: dict[str, int] = {}
    for entry in (meta or {}).get("files") or []:
        if isinstance(entry, dict) and isinstance(entry.get("message_count"), int):
            listed[PurePath(str(entry.get("path", ""))).name] = entry["message_count"]
    out = []
    for f, info in zip(files, infos):
        expected = listed.get(f.path.name)
        if expected is not None and info.message_count < expected:
            out.append(f"{f.path.name}: {info.message_count} of the {expected} messages metadata.yaml lists are readable"
                       + (f" ({f.problem})" if f.problem else ""))
        elif f.problem is not None:
            out.append(f"{f.path.name}: {f.problem}")
    return tuple(out)
