"""Region assignment of the MDBSA center (Lu & Luna, CRV 2023, Sec. IV; ../shared/papers/mdbsa_spiral_search.md).

ROS-free core of the center (its node is the generic server node, `swarm_sim.nodes.server_node`):
`RegionAssigner` (the book-keeping below), `CenterServer` (the assigner behind the
`swarm_sim.protocol` messages, with the ``/center/state`` it publishes, end of file), `draw` (its
regions and planned spirals) and `region_paths` (the regions' spirals, shared with the MDBSA behaviours). The center is a hub
robots talk to only while they are at it: there a robot reports how far it walked
(`report_progress`) and, when its walk is over (or at the start), asks for a new one (`request`). Deterministic: no rng, every tie goes to the region
earliest in the hand-out order (``regions.order``: region id, or nearest the centre first as the
authors' code has it); `t` [s, sim time] is only recorded, never used to decide.

Arc length s is always measured from the spiral's start (its region center, `SpiralPath.start`)
whatever the walking direction. A region's progress is two covered intervals, one grown from each
end: [0, fwd] by the forward walker (direction +1, outward from the start) and [rev, L] by the
reverse walker (direction -1, inward from the far end). Both walkers move monotonically, so this
is all the state a path needs.

Rules (the paper's, Sec. IV) and the choices the paper leaves open:

* **robots <= regions**: robot k (k-th id in the order given, the node passes robot_0..robot_n-1)
  is allocated the k-th region of the hand-out order, forward. The others stay unassigned.
* **robots > regions**: robot k < N_R gets the k-th region forward, robot N_R <= k < 2 N_R the
  (k - N_R)-th from its far end (reverse); robots k >= 2 N_R start idle.
* The initial allocation is made at construction (t = 0; the paper's center allocates at the
  start), so a robot's initial slot counts as taken before the robot first asks; its first
  `request` returns it.
* **Later requests** (a robot's walk is over, or it is idle), in this order, for both cases:
  1. an *unassigned* region (no walker, not finished): the one with the longest remaining path,
     ties to the earliest in the hand-out order (fresh regions all have the same length, so this
     is "the next in order"); the robot
     walks forward from the start-side frontier (a region left by an early-ending walker is
     resumed where coverage stopped);
  2. else a region with exactly one walker and the *longest remaining path*, ties as in 1:
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

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from swarm_controllers.spiral.config import SpiralConfig
from swarm_controllers.spiral.geometry import (
    SpiralPath,
    mdbsa_leg_steps,
    region_centers,
    region_side,
    segments_overlap_collinear,
)
from swarm_controllers.spiral.protocol import ProgressReport, RegionAssignment
from swarm_controllers.spiral.regions import RegionConfig, region_order
from swarm_controllers.spiral.state import RegionView
from swarm_msgs_py.types import NS_PER_S, RobotId, robot_index
from swarm_sim.inbound import Reason, Rejections
from swarm_sim.protocol import Drawing, Lines
from swarm_sim.scenario import Scenario

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
                 finish_tolerance: float = 1e-6, order: Sequence[int] | None = None) -> None:
        """paths: one spiral per region, indexed by region id. robots: ids in allocation order
        (robot k gets region order[k]). finish_tolerance [m]: remaining length treated as nothing.
        order: the region ids in hand-out order (`regions.region_order`; None: by id), which
        also breaks ties between equally long regions later."""
        if len(paths) == 0:
            raise ValueError("need at least one region")
        if len(set(robots)) != len(robots):
            raise ValueError(f"duplicate robot ids in {list(robots)}")
        self._order = tuple(range(len(paths))) if order is None else tuple(order)
        if sorted(self._order) != list(range(len(paths))):
            raise ValueError(f"order {list(self._order)} is not a permutation of the {len(paths)} region ids")
        self._rank = {rid: k for k, rid in enumerate(self._order)}
        self._tol = float(finish_tolerance)
        self._regions = [_Region(p.length) for p in paths]
        self._robots = tuple(robots)
        self._current: dict[RobotId, Assignment] = {}
        self._pending: set[RobotId] = set()  # initial assignments not yet handed out
        self._last_walk: dict[tuple[RobotId, int], int] = {}  # (robot, region) -> direction
        self._gone: set[RobotId] = set()  # removed robots
        n_regions = len(paths)
        for k, robot in enumerate(self._robots):
            if k < n_regions:
                self._assign(robot, self._order[k], FORWARD, 0.0)
            elif k < MAX_WALKERS * n_regions:  # only reached with more robots than regions
                self._assign(robot, self._order[k - n_regions], REVERSE, 0.0)
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

    def remove(self, robot: RobotId) -> None:
        """`robot` is gone (declared dead): its walk ends where it last reported, so its region
        can be given to another robot (its coverage is kept); it gets nothing more."""
        self._check_robot(robot)
        self._pending.discard(robot)
        self._release(robot)
        self._gone.add(robot)

    def _check_robot(self, robot: RobotId) -> None:
        if robot not in self._robots or robot in self._gone:
            raise ValueError(f"unknown robot {robot!r}")

    def _release(self, robot: RobotId) -> None:
        a = self._current.pop(robot, None)
        if a is not None:
            self._regions[a.region].walkers.pop(robot, None)

    def _choose(self) -> tuple[int, int] | None:
        """(region, direction) by the rules: unassigned first, then share; longest remaining,
        ties (within finish_tolerance: equal spirals differ by float rounding) to the earliest in
        the hand-out order."""
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
        return min((rid for rid, reg in candidates if reg.remaining >= best - self._tol), key=self._rank.__getitem__)

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


# --------------------------------------------------------------------------- region spirals

_HEADINGS = ((0.0, 1.0), (1.0, 0.0), (0.0, -1.0), (-1.0, 0.0))  # N, E, S, W: clockwise
_EPS = 1e-9


def region_bounds(scenario: Scenario) -> list[tuple[np.ndarray, np.ndarray]]:
    """(lo, hi) corners [m, world frame] of the box each region's spiral is clipped to.

    The box is the region square shrunk by g/2 on every side, intersected with the arena
    shrunk by ``controller.spiral.arena_margin``: the outermost lines of two neighbouring
    regions are then one gap apart, like the lines within a spiral (no stripe left between
    regions, none walked twice), and a wall keeps the same margin as in DDSA.
    """
    sp = SpiralConfig.of(scenario)
    size, regions = scenario.arena.size, RegionConfig.of(scenario).count
    half_side = region_side(regions, size) / 2.0 - sp.gap / 2.0
    wall = size / 2.0 - sp.arena_margin
    return [(np.maximum(c - half_side, -wall), np.minimum(c + half_side, wall))
            for c in region_centers(regions, size)]


def region_spiral(center: np.ndarray, lo: np.ndarray, hi: np.ndarray, gap: float,
                  redundant: float = 0.0) -> np.ndarray:
    """(K, 2) waypoints of a region's spiral, eqs. (4)-(5) with r = 1, clipped to [lo, hi].

    `spiral.mdbsa_path` generalised to a box not centred on the region center (a region by a
    wall keeps the wall margin there, g/2 elsewhere): circuits inside the box are kept as they
    are and later waypoints are clamped onto the box. A clamped leg is *useless* when it
    re-walks a line already walked or (``redundant`` > 0 [m]) runs parallel to a walked one
    nearer than ``redundant``, which adds almost no new ground. With an off-centre box one side
    is clamped circuits before the opposite one, so useless legs are walked through (they lead
    to the sides still open) and the path ends after the last useful leg, once a whole circuit
    adds nothing. For a centred box this is ``mdbsa_path`` (tested).
    """
    c0 = np.asarray(center, dtype=float)
    lo, hi = np.asarray(lo, dtype=float), np.asarray(hi, dtype=float)
    if not (np.all(lo <= c0) and np.all(c0 <= hi)):
        raise ValueError(f"region center {c0} is outside its box {lo}..{hi}")
    circuits = int(np.ceil(float(np.max(hi - lo)) / gap)) + 3
    pts = [c0.copy()]
    p_raw = c0.copy()
    last_useful = 0
    for c in range(1, circuits + 1):
        useful_circuit = False
        for k, steps in enumerate(mdbsa_leg_steps(c, 1)):
            p_raw = p_raw + np.array(_HEADINGS[k]) * steps * gap
            q = np.clip(p_raw, lo, hi)
            a = pts[-1]
            if np.linalg.norm(q - a) < _EPS:
                continue
            clamped = not np.array_equal(q, p_raw)
            useless = len(pts) > 1 and _rewalks(a, q, pts, redundant if clamped else 0.0)
            pts.append(q)
            if not useless:
                last_useful = len(pts) - 1
                useful_circuit = True
        if not useful_circuit:
            break
    return np.array(pts[: last_useful + 1])


def _rewalks(a: np.ndarray, q: np.ndarray, pts: list[np.ndarray], within: float) -> bool:
    """Whether the axis-parallel leg a-q runs along a walked leg of `pts` (sharing a piece of
    positive length) on the same line or, when within > 0, on a parallel line nearer than that."""
    if within <= 0.0:
        return segments_overlap_collinear(np.array([a, q]), np.array(pts))
    ax = 0 if abs(a[1] - q[1]) < _EPS else 1  # the axis the leg runs along
    other = 1 - ax
    lo, hi = min(a[ax], q[ax]), max(a[ax], q[ax])
    for b0, b1 in zip(pts[:-1], pts[1:]):
        if abs(b0[other] - b1[other]) >= _EPS or abs(b0[other] - a[other]) >= within:
            continue
        if min(hi, max(b0[ax], b1[ax])) - max(lo, min(b0[ax], b1[ax])) > 1e-7:
            return True
    return False


def region_paths(scenario: Scenario) -> list[SpiralPath]:
    """The spiral of every region, indexed by region id (row-major as `spiral.region_centers`).

    The one definition the center server and the MDBSA behaviours share, so both measure the
    same arc lengths. Region centers from eq. (3), boxes from `region_bounds`. A clamped line
    nearer than (detection radius - g/2) to a parallel line already walked is left out: that
    line's detection already reaches the region's edge (g/2 beyond the box), so it would add
    nothing. With the experiment 1 scenarios every point where a resource may lie
    (``resources.margin`` = 0.3 m from the walls) is then within detection range of some
    spiral (tested for 4, 16 and 64 regions).
    """
    sp = SpiralConfig.of(scenario)
    centers = region_centers(RegionConfig.of(scenario).count, scenario.arena.size)
    redundant = scenario.sensors.resource_detection_radius - sp.gap / 2.0
    return [SpiralPath(region_spiral(c, lo, hi, sp.gap, redundant))
            for c, (lo, hi) in zip(centers, region_bounds(scenario))]


# --------------------------------------------------------------------------- the center server


class CenterServer:
    """The MDBSA center's core (`swarm_sim.protocol.Server`): region assignment over messages.

    The center is a hub robots talk to only near it (paper Sec. IV): a `ProgressReport` counts
    only if its sender was within ``controller.spiral.center_range`` of the depot centre when
    sending; others (and reports from unknown or dead robots, or about unknown regions) are
    dropped and counted in `rejections`. A robot the world declared dead (`robot_lost`) loses
    its walk, so its region can go to another robot. For each report that counts, in the order received:

    * the progress of its region is recorded (region >= 0) with `RegionAssigner.report_progress`;
    * if ``done`` or the robot holds no walk, it gets a new one (`RegionAssigner.request`) in a
      `RegionAssignment` (region -1: idle, ask again later);
    * otherwise (an MDBSA-C robot passing the center on a delivery) and if the stop of its walk
      moved since it was last told (its partner reported meanwhile), it is told again: same
      region and direction, ``s0`` = the reported s, the new ``stop_s``. This is how the center
      "shares the search progress of other robots" (Sec. IV) with a walker it sees again.

    At most one answer per robot per tick (the last one), sorted by robot index.
    Deterministic; time is the tick stamp.
    """

    def __init__(self, scenario: Scenario) -> None:
        self.paths: list[SpiralPath] = region_paths(scenario)
        """One spiral per region [m, world frame]."""
        self.assigner = RegionAssigner(self.paths, scenario.robot_names, order=region_order(scenario))
        cx, cy = scenario.depot.center
        self._center = (float(cx), float(cy))
        self._range = float(SpiralConfig.of(scenario).center_range)
        self._told_stop: dict[RobotId, float] = {}
        self.rejections = Rejections()
        """Reports dropped: sent out of range, from an unknown or dead robot, about an unknown region."""
        self.lost: set[RobotId] = set()
        self.regions, self.arena_size = RegionConfig.of(scenario).count, scenario.arena.size

    def snapshot(self) -> list[RegionState]:
        """Per-region state (walkers, covered arc lengths, remaining) for publishing."""
        return self.assigner.snapshot()

    def state(self) -> dict[str, tuple[RegionView, ...]]:
        """``regions``: every region's walkers and progress, as ``/center/state`` carries them."""
        return {"regions": tuple(RegionView(s.region, s.length, s.remaining, s.finished, s.walkers, s.covered)
                                 for s in self.assigner.snapshot())}

    def in_range(self, x: float, y: float) -> bool:
        """Whether a robot at (x, y) [m, world frame] can talk to the center."""
        return math.hypot(x - self._center[0], y - self._center[1]) <= self._range

    def robot_lost(self, robot: RobotId, stamp_ns: int) -> None:
        """`robot` was declared dead: free its region's walker slot, refuse its later reports."""
        if robot in self.assigner.robots and robot not in self.lost:
            self.lost.add(robot)
            self.assigner.remove(robot)
            self._told_stop.pop(robot, None)

    @property
    def ignored(self) -> int:
        """Reports dropped so far."""
        return self.rejections.total

    def step(self, stamp_ns: int, messages: Sequence[object]) -> tuple[RegionAssignment, ...]:
        t = stamp_ns / NS_PER_S
        out: dict[RobotId, RegionAssignment] = {}
        for m in messages:
            if not isinstance(m, ProgressReport):
                continue
            reason = (Reason.UNKNOWN_ROBOT if m.robot not in self.assigner.robots
                      else Reason.DEAD if m.robot in self.lost
                      else Reason.REFUSED if m.region >= self.assigner.n_regions or not self.in_range(m.x, m.y)
                      else None)
            if reason is not None:
                self.rejections.add("ProgressReport", reason, f"t={t:.3f} {m.robot[:40]} region {m.region}")
                continue
            stop = None
            if m.region >= 0:
                stop = self.assigner.report_progress(m.robot, m.region, m.s, t, done=m.done)
            if m.done or self.assigner.current(m.robot) is None:
                out[m.robot] = self._tell(stamp_ns, m.robot, self.assigner.request(m.robot, t))
            elif stop is not None and abs(stop - self._told_stop.get(m.robot, stop)) > _EPS:
                a = self.assigner.current(m.robot)
                assert a is not None
                self._told_stop[m.robot] = stop
                out[m.robot] = RegionAssignment(
                    stamp_ns=stamp_ns, robot=m.robot, region=a.region, direction=a.direction,
                    s0=float(m.s), stop_s=float(stop),
                    shared=len(self.assigner.snapshot()[a.region].walkers) > 1)
        return tuple(out[r] for r in sorted(out, key=robot_index))

    def _tell(self, stamp_ns: int, robot: RobotId, a: Assignment | None) -> RegionAssignment:
        if a is None:
            self._told_stop.pop(robot, None)
            return RegionAssignment(stamp_ns=stamp_ns, robot=robot, region=-1, direction=0,
                                    s0=0.0, stop_s=0.0, shared=False)
        self._told_stop[robot] = a.stop_s
        return RegionAssignment(stamp_ns=stamp_ns, robot=robot, region=a.region,
                                direction=a.direction, s0=float(a.s0), stop_s=float(a.stop_s),
                                shared=a.shared)


_REGION = (0.6, 0.6, 0.6, 1.0)
_PATH = (0.2, 0.6, 1.0, 0.8)


def draw(server: CenterServer, stamp_ns: int) -> Drawing:
    """The regions' squares and their planned spirals (static: drawn once)."""
    half = region_side(server.regions, server.arena_size) / 2
    squares = [
        [(x - half, y - half), (x + half, y - half), (x + half, y + half), (x - half, y + half), (x - half, y - half)]
        for x, y in region_centers(server.regions, server.arena_size)
    ]
    return (Lines("regions", squares, _REGION, 0.02),
            Lines("planned_paths", [p.waypoints for p in server.paths], _PATH, 0.01))


def planned_paths(scenario: Scenario) -> list[np.ndarray]:
    """Every region's spiral waypoints [m, world frame] (drawn under recorded trajectories)."""
    return [p.waypoints for p in region_paths(scenario)]


def region_count(trace) -> int:
    """The run's number of regions N_R (a JSON result field of MDBSA runs)."""
    return RegionConfig.of(trace.config).count
