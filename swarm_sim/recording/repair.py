"""Repairing a bag whose recorder was killed: every complete record kept, every file finalised.

Our reader already recovers what a cut-off file holds, but rosbags' ``AnyReader`` and
``ros2 bag`` need every file to end with its summary and footer. `repair_bag` rewrites the bag
from what can be read: same topics, types, offered QoS, custom metadata and messages (log
times and bytes unchanged), one finalised file, a fresh ``metadata.yaml``, and
``repaired_from`` in the custom metadata naming the files it was rebuilt from. The new bag is
written beside the old one and swapped in only when complete, so a repair that fails leaves
the original untouched.
"""

from __future__ import annotations

import math
import shutil
import warnings
from pathlib import Path

from swarm_sim.recording.metadata import (
    METADATA_FILE,
    BagError,
    BagTruncatedWarning,
    _load_yaml,
)
from swarm_sim.recording.reader import _merge, _open_files
from swarm_sim.recording.writer import BagWriter


def _qos_name(channel_metadata: dict[str, str]) -> str:
    """Our QoS name for a channel's ``offered_qos_profiles`` YAML (reliable when unreadable)."""
    try:
        profiles = _load_yaml(channel_metadata.get("offered_qos_profiles", "")) or []
        first = profiles[0] if isinstance(profiles, list) and profiles else {}
    except Exception:  # noqa: BLE001 - untrusted text: fall back to the common case
        first = {}
    if str(first.get("durability", "")) in ("transient_local", "1"):
        return "latched"
    if str(first.get("reliability", "")) in ("best_effort", "2"):
        return "best_effort"
    return "reliable"


def repair_bag(path: Path | str) -> bool:
    """Finalise a bag cut off mid-write (see the module docstring). Returns False (and changes
    nothing) when every file is already complete; raises BagError if `path` is not a bag."""
    path = Path(path)
    if not path.is_dir():
        raise BagError(f"{path}: not a bag directory")
    root, files, _ = _open_files(path)
    if not any(f.problem is not None for f in files):
        return False
    custom: dict[str, str] = {}
    for f in files:
        custom.update(f.custom_metadata())
    custom["repaired_from"] = ", ".join(f.path.name for f in files)
    staging = root.parent / f".{root.name}.repair"
    shutil.rmtree(staging, ignore_errors=True)
    target = staging / root.name
    try:
        with BagWriter(target, split_seconds=math.inf, flush_seconds=math.inf, metadata=custom) as out:
            seen: set[str] = set()
            for f in files:
                for channel in f.channels.values():
                    schema = f.schemas.get(channel.schema_id)
                    if schema is not None and channel.topic not in seen:
                        seen.add(channel.topic)
                        out.add_topic(channel.topic, schema.name, _qos_name(dict(channel.metadata)))
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", BagTruncatedWarning)
                for m in _merge(files):
                    out.write(m.topic, m.stamp_ns, m.data)
        for other in root.iterdir():  # plots and notes beside the recording stay with it
            if other.suffix != ".mcap" and other.name != METADATA_FILE and not (target / other.name).exists():
                shutil.move(str(other), target / other.name)
        old = root.parent / f".{root.name}.cut"
        root.rename(old)
        target.rename(root)
        shutil.rmtree(old)
    finally:
        shutil.rmtree(staging, ignore_errors=True)
    return True
