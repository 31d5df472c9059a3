"""The vocabulary every layer speaks: the data types shared by the codecs beside this module,
the world, the behaviours and the analysis.

ROS-free on purpose, and at the bottom of the house: the world core, every behaviour and the
batch runner exchange these frozen dataclasses; the codecs of this package convert them to and
from ROS messages' bytes.

Frames: "world" is the arena frame, origin at the arena centre, x east, y north, z up.
Times are simulation time. A tick k happens at ``k * dt`` seconds; stamps are integer
nanoseconds so that graph and batch runs compare exactly.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Annotated, Any, TypeVar

import numpy as np

T = TypeVar("T")

class _RobotIdMark:
    """Marks a message field that names a robot, so a node can refuse ids of no robot of the
    run (`swarm_sim.inbound`)."""

    def __repr__(self) -> str:
        return "robot id"


ROBOT_ID = _RobotIdMark()
RobotId = Annotated[str, ROBOT_ID]
"""A robot's name, which is also its ROS namespace (``robot_0``, ``robot_1``, ...)."""


class _CoordinateMark:
    """Marks a message field that holds a position coordinate [m, world frame], so a node can
    refuse one beyond the arena before any core computes with it (`swarm_sim.inbound`)."""

    def __repr__(self) -> str:
        return "coordinate"


COORDINATE = _CoordinateMark()
Coordinate = Annotated[float, COORDINATE]
"""An x or y position [m, world frame] in a message from another node."""

NS_PER_S = 1_000_000_000


def robot_name(index: int) -> RobotId:
    return f"robot_{index}"


def robot_index(robot: RobotId) -> int:
    """Inverse of `robot_name`; raises ValueError naming the bad id."""
    prefix, _, number = robot.rpartition("_")
    if prefix != "robot" or not number.isdigit():
        raise ValueError(f"unknown robot id {robot!r}: expected 'robot_<index>'")
    return int(number)


def tick_stamp_ns(tick: int, dt_ns: int) -> int:
    return tick * dt_ns


@dataclass(frozen=True, slots=True)
class Pose2D:
    """Planar pose. x, y [m, world frame]; yaw [rad, counter-clockwise from +x, in (-pi, pi]]."""

    x: float
    y: float
    yaw: float


@dataclass(frozen=True, slots=True)
class Command:
    """What a behaviour asks of its robot for one tick.

    linear [m/s, body frame, forward positive]; angular [rad/s, counter-clockwise positive].
    `messages` are sent to other nodes this tick and arrive at their receivers one tick later
    (see `swarm_sim.messaging`).
    """

    linear: float = 0.0
    angular: float = 0.0
    messages: tuple[object, ...] = ()


STOP = Command()


@dataclass(frozen=True, slots=True, eq=False)
class Observation:
    """Everything one robot senses at one tick, exactly as it arrives over ROS.

    The world core already applies the wire's rounding (float32 ranges, yaw through a
    quaternion) so that a batch run and a graph run feed behaviours bit-identical inputs.
    """

    robot: RobotId
    stamp_ns: int
    """Sim time of the tick [ns]."""
    pose: Pose2D
    """Odometry estimate [m, rad; world frame] (encoder noise included if configured)."""
    linear_velocity: float
    """Measured forward speed [m/s, body frame]."""
    angular_velocity: float
    """Measured turn rate [rad/s]."""
    ranges: np.ndarray
    """Laser scan ranges [m], float32, ray i at angle ``angle_min + i * angle_increment``
    relative to the heading; ``inf`` where nothing is within range (REP 117)."""
    sensed: Any
    """What the world task lets the robot sense besides odometry and scan, e.g.
    `swarm_sim.world.tasks.foraging.ForagingSense` (resources in range, gripper)."""
    messages: tuple[object, ...] = ()
    """Messages from other nodes stamped before this tick, in a deterministic order."""

    @property
    def t(self) -> float:
        """Sim time [s]."""
        return self.stamp_ns / NS_PER_S

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Observation):
            return NotImplemented
        return (
            self.robot == other.robot
            and self.stamp_ns == other.stamp_ns
            and self.pose == other.pose
            and self.linear_velocity == other.linear_velocity
            and self.angular_velocity == other.angular_velocity
            and np.array_equal(self.ranges, other.ranges)
            and self.sensed == other.sensed
            and self.messages == other.messages
        )

    __hash__ = None  # type: ignore[assignment]


@dataclass(frozen=True, slots=True)
class PickupEvent:
    """A robot's gripper took a resource. x, y: where the resource lay [m, world frame]."""

    robot: RobotId
    stamp_ns: int
    resource: int
    x: float
    y: float


@dataclass(frozen=True, slots=True)
class DropEvent:
    """A robot delivered its resource in drop zone `zone`. x, y: robot position [m, world]."""

    robot: RobotId
    stamp_ns: int
    resource: int
    zone: str
    x: float
    y: float


@dataclass(frozen=True, slots=True)
class NodeDownEvent:
    """The world declared a node dead: it missed its lockstep answers `ticks` times in a row
    (``dead_after``, each after the tick timeout). `kind` is ``robot`` (a controller: its robot
    stands still for the rest of the run and the servers free what it held) or ``server``
    (a server's channel, e.g. ``depot``: the run ends here, incomplete)."""

    node: str
    stamp_ns: int
    kind: str
    ticks: int


NODE_KINDS = ("robot", "server")
FINISHED = "finished"
"""A run's ``run_ended`` when it stopped because every behaviour's task was over
(``sim.stop_when_finished``)."""


@dataclass(slots=True)
class RobotStats:
    """Per-robot counters owned by the world (the behaviours own their own counters)."""

    collision_time_s: float = 0.0
    """Time spent in physical contact with another robot [s]."""
    pickups: int = 0
    deliveries: int = 0
    clamped_commands: int = 0
    """Commands that were NaN/inf or above the speed limits and had to be clamped."""
    stale_ticks: int = 0
    """Lockstep ticks for which the robot's controller did not answer in time."""
    avoidance_time_s: float = 0.0
    """Time its proximity ring saw something ahead [s]: the ticks on which an ARGoS foot-bot
    controller's collision detection fires (the queue and spiral papers' *collision time*; see
    `swarm_sim.world.proximity`)."""


@dataclass(frozen=True, slots=True)
class BehaviourStatus:
    """A behaviour's own counters and state, published when they change."""

    robot: RobotId
    stamp_ns: int
    state: str
    obstacle_avoidance_events: int
    trips: int
    extra: tuple[tuple[str, str], ...] = field(default=())
    finished: bool = False
    """The behaviour's task is over (its ``finished``): what ``sim.stop_when_finished`` waits for,
    in batch runs and on the graph alike."""


# ---------------------------------------------------------------------- fast constructors


def slot_setters(cls: type) -> tuple[Callable[[Any, Any], None], ...] | None:
    """The setters of frozen slotted dataclass `cls`'s slots, in field order, or None when building
    one takes more than setting its fields (a ``__post_init__``, a field left out of ``__init__``
    or made by a ``default_factory``, no slots).

    A frozen dataclass's generated ``__init__`` sets each field through ``object.__setattr__``;
    a slot's descriptor sets it for a fraction of that. The world builds an `Observation` and a
    `Pose2D` per robot per tick, a behaviour a `Command`: what `slot_constructor` and the world's
    field-by-field build (`swarm_sim.world.observations`) use.
    """
    if not dataclasses.is_dataclass(cls) or "__slots__" not in cls.__dict__ or hasattr(cls, "__post_init__"):
        return None
    fields = dataclasses.fields(cls)
    if any(not f.init or f.default_factory is not dataclasses.MISSING for f in fields):
        return None
    return tuple(getattr(cls, f.name).__set__ for f in fields)


def slot_constructor(cls: type[T]) -> Callable[..., T]:
    """A constructor of `cls` taking its fields positionally (with their defaults) and filling
    the slots through `slot_setters`: the same object as ``cls(...)``'s for about a third of
    the cost (`Command`, measured ~0.33 vs ~0.89 us). `cls` itself when `slot_setters` says no.

    The function is generated, as dataclasses generate ``__init__``: one setter call per field,
    no loop (a loop over the setters costs as much as it saves)."""
    setters = slot_setters(cls)
    if setters is None:
        return cls
    fields = dataclasses.fields(cls)
    names = [f"_{f.name}" for f in fields]  # no clash with the helpers' names below
    scope: dict[str, Any] = {"_new": object.__new__, "_cls": cls}
    params = []
    for name, f, setter in zip(names, fields, setters):
        scope[f"_set{name}"] = setter
        if f.default is dataclasses.MISSING:
            params.append(name)
        else:
            scope[f"_default{name}"] = f.default
            params.append(f"{name}=_default{name}")
    body = "".join(f"    _set{name}(o, {name})\n" for name in names)
    source = f"def new_{cls.__name__}({', '.join(params)}):\n    o = _new(_cls)\n{body}    return o\n"
    exec(source, scope)  # noqa: S102 - our own source text, built from the dataclass's field names
    make = scope[f"new_{cls.__name__}"]
    make.__doc__ = f"``{cls.__name__}({', '.join(f.name for f in fields)})``, its slots filled directly."
    return make
