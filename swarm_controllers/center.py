"""Region assignment of the MDBSA center (Lu & Luna, CRV 2023, Sec. IV; ../shared/papers/mdbsa_spiral_search.md).

ROS-free core of the future center node. The center is a hub robots talk to only while they are
at it: there a robot reports how far it walked (`report_progress`) and, when its walk is over (or
at the start), asks for a new one (`request`). Deterministic: no rng, every tie goes to the lowest
region id; `t` [s, sim time] is only recorded, never used to decide.

Arc length s is always measured from the spiral's start (its region center, `SpiralPath.start`)
whatever the walking direction. A region's progress is two covered intervals, one grown from each
end: [0, fwd] by the forward walker (direction +1, outward from the start) and [rev, L] by the
reverse walker (direction -1, inward from the far end). Both walkers move monotonically, so this
is all the state a path needs.

Rules (the paper's, Sec. IV) and the choices the paper leaves open:

* **robots <= regions**: robot k (k-th id in the order given, the node passes robot_0..robot_n-1)
  is allocated region k, forward. Regions k >= n_robots stay unassigned.
* **robots > regions**: robot k < N_R gets region k forward, robot N_R <= k < 2 N_R gets region
  k - N_R from its far end (reverse); robots k >= 2 N_R start idle.
* The initial allocation is made at construction (t = 0; the paper's center allocates at the
  start), so a robot's initial slot counts as taken before the robot first asks; its first
  `request` returns it.
* **Later requests** (a robot's walk is over, or it is idle), in this order, for both cases:
  1. an *unassigned* region (no walker, not finished): the one with the longest remaining path,
     ties lowest id (fresh regions all have the same length, so this is "lowest id"); the robot
     walks forward from the start-side frontier (a region left by an early-ending walker is
     resumed where coverage stopped);
  2. else a region with exactly one walker and the *longest remaining path*, ties lowest id:
     the robot walks the other way from the free end's frontier, so normally from the far end;
  3. else idle (None); an idle robot asks again later.
  The paper's "robots > regions" wording only mentions sharing; rule 1 is vacuous there unless a
  walker left a region early, in which case re-covering it before sharing is the obvious reading.
* **At most two walkers per region**, in opposite directions; a robot walks at most one region.
* **Remaining** length = the uncovered middle rev - fwd [m] from the last reports, whether one or
  two robots walk the path (the paper's "longest spiral path that has not been completed by an
  assigned robot"). With two walkers nothing is sharable anyway.
* **Finished** region: remaining <= `finish_tolerance` (the two covered intervals meet). Finished
  regions are never assigned again.
* **Meeting point**: not planned. Robots in one region can talk (paper), so the two walkers stop
  where they meet. The center only knows a bound: `Assignment.stop_s` is the partner side's
  frontier when assigned, and `stop_for` / the return value of `report_progress` give the current
  one when the robot is back at the center.
* A `request` ends the robot's current walk (its walker slot is freed; coverage it reported is
  kept). A walk that ends where it met its partner is reported with ``done=True``: the partner is
  at the same s, so both intervals are closed there and the region is finished even if the
  partner has not reported yet.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from swarm_controllers.spiral import SpiralPath
from swarm_sim.types import RobotId

FORWARD = 1
"""Walk from the spiral's start (region center), outward, clockwise."""
REVERSE = -1
"""Walk from the spiral's far end, inward, counter-clockwise."""
MAX_WALKERS = 2
"""Paper: "Each region can accommodate up to two robots"."""


@dataclass(frozen=True)
class Assignment:
    """One walk handed to a robot at the center."""

    robot: RobotId
    region: int
    """Region id (index into the list of paths; row-major as `spiral.region_centers`)."""
    direction: int
    """+1: forward from the spiral's start; -1: backward from its far end."""
    s0: float
    """Arc length where the walk begins [m from the spiral's start]."""
    stop_s: float
    """Arc length where the walk must end at the latest [m from the spiral's start]: the path's
    other end, or the partner's frontier when assigned; the walkers stop earlier where they meet."""
    shared: bool
    """True if another robot walks the same region (the other way) at assignment time."""
    t: float
    """Time of the assignment [s, sim time]."""


@dataclass(frozen=True)
class RegionState:
    """Plain snapshot of one region for publishing."""

    region: int
    length: float
    """Arc length of the region's spiral [m]."""
    walkers: tuple[tuple[RobotId, int], ...]
    """(robot, direction) of the robots walking it, sorted by robot id."""
    covered: tuple[tuple[float, float], ...]
    """Covered arc-length intervals [m from the start], empty ones omitted, merged when they meet."""
    remaining: float
    """Uncovered arc length [m]."""
    finished: bool
    last_update: float
    """Time of the last assignment or progress report in this region [s, sim time]; -inf if none."""


class _Region:
    """Mutable progress of one path (internal)."""

    def __init__(self, length: float) -> None:
        self.length = length
        self.fwd = 0.0  # covered [0, fwd]
        self.rev = length  # covered [rev, length]
        self.walkers: dict[RobotId, int] = {}
        self.last_update = float("-inf")

    @property
    def remaining(self) -> float:
        return max(0.0, self.rev - self.fwd)


class RegionAssigner:
    """The MDBSA center's assignment and progress book-keeping (see module docstring)."""

    def __init__(self, paths: Sequence[SpiralPath], robots: Sequence[RobotId], *,
                 finish_tolerance: float = 1e-6) -> None:
        """paths: one spiral per region, indexed by region id. robots: ids in allocation order
        (robot k gets region k). finish_tolerance [m]: remaining length treated as nothing."""
        if len(paths) == 0:
            raise ValueError("need at least one region")
        if len(set(robots)) != len(robots):
            raise ValueError(f"duplicate robot ids in {list(robots)}")
        self._tol = float(finish_tolerance)
        self._regions = [_Region(p.length) for p in paths]
        self._robots = tuple(robots)
        self._current: dict[RobotId, Assignment] = {}
        self._pending: set[RobotId] = set()  # initial assignments not yet handed out
        self._last_walk: dict[tuple[RobotId, int], int] = {}  # (robot, region) -> direction
        n_regions = len(paths)
        for k, robot in enumerate(self._robots):
            if k < n_regions:
                self._assign(robot, k, FORWARD, 0.0)
            elif k < MAX_WALKERS * n_regions:  # only reached with more robots than regions
                self._assign(robot, k - n_regions, REVERSE, 0.0)
            else:
                continue
            self._pending.add(robot)

    # ---------------------------------------------------------------- queries

    @property
    def n_regions(self) -> int:
        return len(self._regions)

    @property
    def robots(self) -> tuple[RobotId, ...]:
        return self._robots

    def current(self, robot: RobotId) -> Assignment | None:
        """The robot's current walk, None if idle."""
        return self._current.get(robot)

    def remaining(self, region: int) -> float:
        """Uncovered arc length of the region's spiral [m], from the last reports."""
        return self._regions[region].remaining

    def finished(self, region: int) -> bool:
        return self._regions[region].remaining <= self._tol

    def stop_for(self, robot: RobotId) -> float | None:
        """Current latest stop of the robot's walk [m from the start]: the other side's frontier."""
        a = self._current.get(robot)
        if a is None:
            return None
        reg = self._regions[a.region]
        return reg.rev if a.direction == FORWARD else reg.fwd

    # ---------------------------------------------------------------- the robot at the center

    def request(self, robot: RobotId, t: float) -> Assignment | None:
        """A robot at the center asks for a walk: its initial one, else a new one by the rules,
        else None (idle). Ends the robot's current walk, if any."""
        self._check_robot(robot)
        if robot in self._pending:
            self._pending.discard(robot)
            return self._current[robot]
        self._release(robot)
        choice = self._choose()
        if choice is None:
            return None
        region, direction = choice
        return self._assign(robot, region, direction, t)

    def report_progress(self, robot: RobotId, region: int, s: float, t: float, *,
                        done: bool = False) -> float | None:
        """The robot has walked region's spiral up to arc length s [m from the start] in the
        direction of its (current or last) walk there. done=True: its walk ended at s because it
        met its partner or reached its stop/the end, i.e. the path beyond s is covered or being
        covered by the partner. Returns the walk's current latest stop (None if the robot holds no
        walk there). A report from a robot that never walked this region is ignored."""
        self._check_robot(robot)
        if not 0 <= region < len(self._regions):
            raise ValueError(f"unknown region {region}")
        direction = self._last_walk.get((robot, region))
        if direction is None:
            return None
        reg = self._regions[region]
        s = min(max(float(s), 0.0), reg.length)
        if direction == FORWARD:
            reg.fwd = max(reg.fwd, s)
            if done:
                reg.rev = min(reg.rev, s)
        else:
            reg.rev = min(reg.rev, s)
            if done:
                reg.fwd = max(reg.fwd, s)
        reg.last_update = float(t)
        cur = self._current.get(robot)
        return self.stop_for(robot) if cur is not None and cur.region == region else None

    # ---------------------------------------------------------------- publishing

    def snapshot(self) -> list[RegionState]:
        """Per region: walkers, covered intervals, remaining length (plain data)."""
        out = []
        for rid, reg in enumerate(self._regions):
            if reg.fwd >= reg.rev:
                covered: tuple[tuple[float, float], ...] = ((0.0, reg.length),)
            else:
                covered = tuple(iv for iv in ((0.0, reg.fwd), (reg.rev, reg.length))
                                if iv[1] > iv[0])
            out.append(RegionState(
                region=rid, length=reg.length,
                walkers=tuple(sorted(reg.walkers.items())),
                covered=covered, remaining=reg.remaining,
                finished=reg.remaining <= self._tol, last_update=reg.last_update))
        return out

    # ---------------------------------------------------------------- internals

    def _check_robot(self, robot: RobotId) -> None:
        if robot not in self._robots:
            raise ValueError(f"unknown robot {robot!r}")

    def _release(self, robot: RobotId) -> None:
        a = self._current.pop(robot, None)
        if a is not None:
            self._regions[a.region].walkers.pop(robot, None)

    def _choose(self) -> tuple[int, int] | None:
        """(region, direction) by the rules: unassigned first, then share; longest remaining,
        ties (within finish_tolerance: equal spirals differ by float rounding) lowest id."""
        open_regions = [(rid, reg) for rid, reg in enumerate(self._regions)
                        if reg.remaining > self._tol]
        unassigned = [(rid, reg) for rid, reg in open_regions if not reg.walkers]
        if unassigned:
            return self._longest(unassigned), FORWARD
        sharable = [(rid, reg) for rid, reg in open_regions if len(reg.walkers) == 1]
        if sharable:
            rid = self._longest(sharable)
            (other_dir,) = self._regions[rid].walkers.values()
            return rid, -other_dir
        return None

    def _longest(self, candidates: list[tuple[int, _Region]]) -> int:
        best = max(reg.remaining for _, reg in candidates)
        return min(rid for rid, reg in candidates if reg.remaining >= best - self._tol)

    def _assign(self, robot: RobotId, region: int, direction: int, t: float) -> Assignment:
        reg = self._regions[region]
        assert len(reg.walkers) < MAX_WALKERS and direction not in reg.walkers.values()
        shared = bool(reg.walkers)
        reg.walkers[robot] = direction
        s0, stop = (reg.fwd, reg.rev) if direction == FORWARD else (reg.rev, reg.fwd)
        a = Assignment(robot=robot, region=region, direction=direction, s0=s0, stop_s=stop,
                       shared=shared, t=float(t))
        self._current[robot] = a
        self._last_walk[(robot, region)] = direction
        reg.last_update = float(t)
        return a
