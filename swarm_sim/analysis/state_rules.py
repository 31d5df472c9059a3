"""Metrics counted where the authors count them: by the state each robot reports.

The world counts collision time by one rule in every state (`swarm_sim.world.proximity`): it cannot
see a controller's state. Some authors count in their controllers, by state: the queue paper's
count the ring's readings within +-30 deg while a robot follows a queue path or exits and not at
all while it waits at a dock; the DRTM paper's M_T2 counts the OAEs of returning robots. Those
rules are computed here, beside the world's count, from what every run already has: the ring's
readings (the scan) and the state each robot reports (`BehaviourStatus`, ``/<robot>/status``).
The batch runner feeds them tick by tick; the bag replay feeds them from the recorded scans and
statuses (a robot's state at tick k is the last status it published at or before k: a
controller publishes its status after each tick's step when it changed), so a batch run and the
bag of a graph run give the same numbers. A paper declares its rule and its fields in its own
registration (`swarm_sim.registry.Algorithm.collision_rule`, ``trace_status`` and ``metrics``).
"""

from __future__ import annotations

import bisect
import math
from collections.abc import Callable, Iterable, Sequence

import numpy as np

from swarm_msgs_py.types import BehaviourStatus, RobotId

Rule = Callable[[BehaviourStatus], "float | None"]
"""A robot's state -> the half-angle [deg] about its heading within which the ring's reading counts
as collision time, None where nothing counts. It may say the widest angle it ever gives as a
``widest`` attribute [deg], so that robots whose reading lies outside it are not asked their state."""


class RuleLog:
    """Per robot, the ticks on which the ring's reading counted as collision time by a `Rule`."""

    def __init__(self, robots: Sequence[RobotId], rule: Rule, dt: float) -> None:
        self.robots = tuple(robots)
        self._rule = rule
        self._dt = dt
        self._ticks = [0] * len(self.robots)
        self._cos: dict[float, float] = {}
        self._cos_widest = math.cos(math.radians(min(getattr(rule, "widest", 180.0), 180.0)))

    def add(self, i: int, x: float, y: float, status: BehaviourStatus | None) -> None:
        """One robot's tick: its ring's reading vector (x, y) [body frame] and its state then."""
        norm = math.hypot(x, y)
        if not norm > 0.0 or status is None:
            return
        cone = self._rule(status)
        if cone is None:
            return
        c = self._cos.get(cone)
        if c is None:
            c = self._cos[cone] = math.cos(math.radians(cone))
        if x >= c * norm:
            self._ticks[i] += 1

    def update(self, x: np.ndarray, y: np.ndarray, status_of: Callable[[int], BehaviourStatus | None]) -> None:
        """One tick of the swarm: `x`, `y` (n,) the ring vectors (`ProximityRing.vectors`);
        `status_of(i)` robot i's state, asked only of robots whose reading lies within the rule's
        widest angle (`add` decides the rest)."""
        norm = np.hypot(x, y)
        for i in np.flatnonzero((norm > 0.0) & (x >= (self._cos_widest - 1e-9) * norm)).tolist():
            self.add(i, float(x[i]), float(y[i]), status_of(i))

    def seconds(self) -> dict[RobotId, float]:
        """Per robot, the collision time counted [s]."""
        return {r: n * self._dt for r, n in zip(self.robots, self._ticks)}


class StatusLog:
    """Per robot, every status it published, in order: as a controller node publishes them
    (after a tick's step, when state, counters or extras changed)."""

    def __init__(self, robots: Sequence[RobotId]) -> None:
        self.log: dict[RobotId, list[BehaviourStatus]] = {r: [] for r in robots}
        self._stamps: dict[RobotId, list[int]] = {r: [] for r in robots}
        self._keys: dict[RobotId, tuple] = {}

    def published(self, status: BehaviourStatus) -> None:
        """A status as published (a bag's ``/<robot>/status`` message, in stamp order)."""
        self.log.setdefault(status.robot, []).append(status)
        self._stamps.setdefault(status.robot, []).append(status.stamp_ns)

    def update(self, statuses: Iterable[BehaviourStatus]) -> None:
        """Every robot's status after a tick's step; kept when it changed."""
        for st in statuses:
            key = (st.state, st.obstacle_avoidance_events, st.trips, st.extra)
            if self._keys.get(st.robot) != key:
                self._keys[st.robot] = key
                self.published(st)

    def at(self, robot: RobotId, stamp_ns: int) -> BehaviourStatus | None:
        """The robot's last status published at or before `stamp_ns` (None before its first)."""
        k = bisect.bisect_right(self._stamps.get(robot, ()), stamp_ns)
        return self.log[robot][k - 1] if k else None


def events_by_state(log: dict[RobotId, list[BehaviourStatus]]) -> dict[str, int]:
    """Obstacle-avoidance events by the state the robot was in when it counted them: each status's
    increase of the counter goes to that status's state (a behaviour counts an event during the
    tick's step, and the status after the step carries it)."""
    out: dict[str, int] = {}
    for statuses in log.values():
        before = 0
        for st in statuses:
            gained = st.obstacle_avoidance_events - before
            if gained:
                out[st.state] = out.get(st.state, 0) + gained
            before = st.obstacle_avoidance_events
    return dict(sorted(out.items()))
