"""The swarm's observations, built every tick: many small frozen objects, made cheaply.

`Observation` and `Pose2D` are frozen slotted dataclasses. Their generated ``__init__`` sets
each field through ``object.__setattr__``, which made constructing them most of the cost of
`World.observe` (1000 robots: 1.1 ms a tick). Here the slots are filled through their
descriptors directly (`swarm_msgs_py.types.slot_setters`): field by field for the whole swarm
(`observations`, 1000 robots: 0.7 ms), or one object at a time (`with_messages`: the batch
runner's copies carrying a tick's inbox). Both fall back to the ordinary constructor should the
classes ever gain fields or a ``__post_init__`` (test_world checks both give equal objects).
"""

from __future__ import annotations

import dataclasses
import math
from collections import deque
from collections.abc import Callable, Iterable, Sequence
from itertools import repeat
from typing import Any

import numpy as np

from swarm_msgs_py.types import Observation, Pose2D, RobotId, slot_constructor, slot_setters
from swarm_sim.world.jit import kernel

_TWO_PI = 2.0 * math.pi
_OBSERVATION_FIELDS = ("robot", "stamp_ns", "pose", "linear_velocity", "angular_velocity", "ranges",
                       "sensed", "messages")
_POSE_FIELDS = ("x", "y", "yaw")


def _wire_yaw(
    yaw: float, sin=math.sin, cos=math.cos, atan2=math.atan2, remainder=math.remainder
) -> float:
    """`geometry.wire_yaw` inlined (the same operations in the same order, so bit-identical) -
    it runs for every robot on every tick."""
    wrapped = remainder(2.0 * atan2(sin(yaw / 2), cos(yaw / 2)), _TWO_PI)
    return math.pi if wrapped == -math.pi else wrapped


def _wire_yaws(yaws: np.ndarray) -> list[float]:
    """`_wire_yaw` of every yaw: the quaternion round trip in one compiled loop
    (`_quaternion_yaws`; 112 robots 17 -> 5 us a tick, 1000 robots 141 -> 29 us), the wrap in Python only where it
    is not the identity.

    The kernel's sin, cos and atan2 are the C library's, as `math`'s are (numba calls libm; not
    numpy's own versions, `swarm_sim.world.jit`): bit for bit the same values (measured on 15
    million yaws in [-pi, pi]; test_world compares the two on random yaws and edge cases). The wrap,
    ``remainder(w, 2 pi)``, leaves every w with ``|w| < pi`` as it is (the quotient rounds to 0),
    which is every world yaw (odometry yaws lie in [-pi, pi]: w = 2 atan2(., cos >= 0)); any
    other value, and NaN, takes the Python route."""
    w = np.empty(len(yaws))
    _quaternion_yaws(yaws, w)
    if not (np.abs(w) < math.pi).all():
        return list(map(_wire_yaw, yaws.tolist()))
    return w.tolist()


@kernel
def _quaternion_yaws(yaws: np.ndarray, out: np.ndarray) -> None:
    """``2 atan2(sin(yaw / 2), cos(yaw / 2))`` of every yaw into `out` (`_wire_yaw` before its
    wrap)."""
    for i in range(yaws.shape[0]):
        half = yaws[i] / 2
        out[i] = 2.0 * math.atan2(math.sin(half), math.cos(half))


def _setters(cls: type, expected: tuple[str, ...]) -> tuple[Callable[[Any, Any], None], ...] | None:
    """`slot_setters` of `cls` if its fields are `expected`, the columns `observations` passes."""
    return slot_setters(cls) if tuple(f.name for f in dataclasses.fields(cls)) == expected else None


_OBSERVATION_SETTERS = _setters(Observation, _OBSERVATION_FIELDS)
_POSE_SETTERS = _setters(Pose2D, _POSE_FIELDS)


def _build(cls: type, setters: tuple | None, columns: Sequence[Iterable[Any]], n: int) -> list:
    """`n` objects of `cls`, field k of object i from ``columns[k]``'s i-th item: each field set
    for all objects by one map over its slot's setter (C-level loops, no Python call per
    object)."""
    if setters is None:
        return [cls(*row) for row in zip(*columns)]
    objects = list(map(object.__new__, repeat(cls, n)))
    for setter, column in zip(setters, columns):
        deque(map(setter, objects, column), maxlen=0)  # consume: the setters return None
    return objects


def observations(
    robots: Sequence[RobotId], stamp_ns: int, odometry: np.ndarray, speeds: np.ndarray,
    turn_rates: np.ndarray, ranges: np.ndarray, sensed: Sequence[Any],
) -> dict[RobotId, Observation]:
    """Every robot's observation, without messages: `odometry` (n, 3) x, y, yaw [m, rad] (the
    yaw rounded as on the wire here), measured forward `speeds` and `turn_rates` (n,), `ranges`
    (n, rays) (each robot gets its row), `sensed` the task's readings."""
    n = len(robots)
    x, y = odometry[:, 0].tolist(), odometry[:, 1].tolist()
    poses = _build(Pose2D, _POSE_SETTERS, (x, y, _wire_yaws(odometry[:, 2])), n)
    columns = (robots, repeat(stamp_ns), poses, speeds.tolist(), turn_rates.tolist(), list(ranges), sensed,
               repeat(()))
    return dict(zip(robots, _build(Observation, _OBSERVATION_SETTERS, columns, n)))


def with_messages(obs: Observation, messages: tuple[object, ...]) -> Observation:
    """A copy of `obs` carrying `messages` (what ``dataclasses.replace`` gives, for a fifth of its
    cost)."""
    return _new_observation(obs.robot, obs.stamp_ns, obs.pose, obs.linear_velocity, obs.angular_velocity,
                            obs.ranges, obs.sensed, messages)


_new_observation = slot_constructor(Observation)
"""``Observation(...)``, positional, for a fraction of its cost (`swarm_msgs_py.types.slot_constructor`)."""
