"""The bag's vocabulary: constants, errors, message and info records, rosbag2 metadata.yaml
and QoS text, message definitions."""

from __future__ import annotations

import functools
import json
import re
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml
from mcap.writer import LIBRARY_IDENTIFIER, CompressionType

try:
    import lz4.frame as lz4_frame
except ImportError:  # pragma: no cover - lz4 is optional, as in mcap
    lz4_frame = None

MCAP_MAGIC = b"\x89MCAP0\r\n"
METADATA_FILE = "metadata.yaml"
METADATA_VERSION = 9
ROS_DISTRO = "jazzy"
LIBRARY = f"swarm_sim.recording; {LIBRARY_IDENTIFIER}"
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
    lost: tuple[str, ...] = ()
    """What the bag lost, one line per damaged file: cut off mid-write, or fewer messages readable
    than metadata.yaml lists (empty: every message written is there)."""

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
_HASHES: dict[str, str] = {}


def _typestore() -> Any:
    global _TYPESTORE
    if _TYPESTORE is None:
        from rosbags.typesys import Stores, get_typestore

        _TYPESTORE = get_typestore(Stores.ROS2_JAZZY)
    return _TYPESTORE


def _type_hash(type_name: str) -> str:
    """The type description hash (``RIHS01_...``, REP 2011) of a Jazzy message type, as the graph
    reports it for a publisher and ``ros2 bag record`` writes it."""
    if type_name not in _HASHES:
        _HASHES[type_name] = _typestore().hash_rihs01(type_name)
    return _HASHES[type_name]


def _msgdef(type_name: str) -> str:
    """rosbag2's "ros2msg" schema text: the type's .msg, then each dependency after a ==== line."""
    if type_name not in _MSGDEFS:
        _MSGDEFS[type_name] = _typestore().generate_msgdef(type_name, ros_version=2)[0]
    return _MSGDEFS[type_name]


# ------------------------------------------------------------------------------------- writer
