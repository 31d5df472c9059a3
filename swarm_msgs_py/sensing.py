"""How a world task's data travels: its sense, one topic per field, and its world-level state.

The world node publishes, and a controller node subscribes to, the odometry and the scan of
every robot plus the topics of its task's `Sensing`; a controller steps once it holds every one
of them stamped with the same tick. A task's `StateTopic` values are world-level topics the
world node publishes every tick (recorded; analysis reads them back as time series). The records
are data, so adding a task adds no code to the nodes: only its types, its codecs and these values.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any


@dataclass(frozen=True)
class SenseTopic:
    """One field of a sense on its own robot topic."""

    name: str
    """Relative topic name under the robot's namespace (``resources`` -> ``/robot_3/resources``)."""
    type_name: str
    """ROS type string (``geometry_msgs/msg/PoseArray``): standard types only."""
    field: str
    """The sense's field it carries."""
    encode: Callable[[int, Any], bytes]
    """(stamp_ns, value) -> CDR bytes."""
    decode: Callable[[bytes], tuple[int, Any]]
    """CDR bytes -> (stamp_ns, value); raises CodecError (a ValueError) on malformed bytes."""


@dataclass(frozen=True)
class Sensing:
    """A task's sense type and the topics of its fields (every field on exactly one topic)."""

    sense: type
    """The sense type (a NamedTuple or frozen dataclass), built as ``sense(**fields)``."""
    topics: tuple[SenseTopic, ...]

    def __post_init__(self) -> None:
        fields = getattr(self.sense, "_fields", None) or tuple(self.sense.__dataclass_fields__)
        if sorted(t.field for t in self.topics) != sorted(fields):
            raise ValueError(f"{self.sense.__name__}: topics carry {[t.field for t in self.topics]}, "
                             f"expected each of {list(fields)} once")

    def encode_all(self, stamp_ns: int, sense: Any) -> dict[str, bytes]:
        """Topic name -> the bytes of `sense`'s field on it."""
        return {t.name: t.encode(stamp_ns, getattr(sense, t.field)) for t in self.topics}


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
