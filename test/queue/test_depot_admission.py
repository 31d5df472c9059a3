"""Depot admission (queue_depot_traffic.md secs. III-V): cells, rules, FCFS + counter-clockwise
right of way, and, in a tiny kinematic simulator, the invariants: one robot per dock, two per
inner queue, no conflicting ownership (centre distances, and no robot drives along its line
within a robot diameter of another's cell), keep-clear, lookahead, FCFS, no gridlock (every
robot leaves in time).

Gridlock bound used below: after every step some robot inside either has a grant beyond its
cell or is unloading at its dock (checked every tick). A robot with a grant moves with
probability >= p_min each tick, so while anyone is inside, the expected number of ticks is at
most sum_i (T_unload + 1) + sum_i L_i / p_min (L_i: cells of robot i's route from where it
joined). Every robot must leave within twice that (+10 ticks) of joining.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from functools import lru_cache

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scipy.spatial import cKDTree

from depot_manager.admission import DepotAdmission
from depot_manager.codec import OUTPUTS
from depot_manager.config import QueueConfig
from depot_manager.geometry import (
    DepotGeometryConfig,
    Dock,
    Polyline,
    QueueLayout,
    make_layout,
)
from depot_manager.protocol import DepotGrant, DepotReport, Refusal, ReportKind
from depot_manager.server import DepotServer
from swarm_controllers.spiral.protocol import ProgressReport
from swarm_sim.outputs import StateWatch
from swarm_sim.scenario import ControllerConfig, DepotConfig, Scenario

P_MIN = 0.3
T_UNLOAD = 4
LOOKAHEAD = 8

CONFIGS = {
    "default": DepotGeometryConfig(),
    "small": DepotGeometryConfig(perimeter_radius=1.5),
    "two_docks": DepotGeometryConfig(docks=2, perimeter_radius=1.6),
    "six_docks": DepotGeometryConfig(docks=6, depot_radius=0.8, perimeter_radius=2.1),
}


@lru_cache(maxsize=None)
def layout(kind: str, size: str) -> QueueLayout:
    return make_layout(kind, CONFIGS[size])


# ------------------------------------------------------------------ independent view of the cells


class Geo:
    """Every (line, cell) label of a layout, with centre coordinates and the admission's conflict
    relation as a matrix, so that the simulator's checks are cheap."""

    def __init__(self, lay: QueueLayout) -> None:
        adm = DepotAdmission(lay)
        cfg = lay.config
        self.cfg = cfg
        self.thr = (cfg.robot_diameter + cfg.lane_spacing) / 2
        self.labels = [(ln, i) for ln in adm.lines() for i in range(len(adm.cells(ln)))]
        self.index = {lab: k for k, lab in enumerate(self.labels)}
        self.xy = np.array([adm.cells(ln)[i] for ln, i in self.labels])
        d = np.linalg.norm(self.xy[:, None] - self.xy[None], axis=2)
        self.dist = d
        self.conf = np.zeros(d.shape, bool)
        for i, j in zip(*np.nonzero(d < 0.6)):
            self.conf[i, j] = adm.conflict(self.labels[i], self.labels[j])
        self.keep_clear = np.array([adm.keep_clear(*lab) for lab in self.labels])
        # neighbours along a line, through the aliases where lines meet (same point)
        adj = np.zeros(d.shape)
        for a, b in zip(self.labels[:-1], self.labels[1:]):
            if a[0] == b[0]:
                adj[self.index[a], self.index[b]] = adj[self.index[b], self.index[a]] = 1
        same = (d < 1e-9).astype(float)
        self.adjacent = (same @ adj @ same) > 0
        self.dock = {
            lab for lab, p in zip(self.labels, self.xy)
            if any(np.linalg.norm(p - dk.stop) < 1e-6 for dk in lay.docks)
        }
        self.dock_of = {
            lab: k for lab, p in zip(self.labels, self.xy)
            for k, dk in enumerate(lay.docks) if np.linalg.norm(p - dk.stop) < 1e-6
        }
        self.entry_ends = {(ln.name, len(adm.cells(ln.name)) - 1) for ln in lay.entry_lines}
        # the stretch of its line a robot drives along to reach (line, j) from (line, j - 1)
        self.path: dict[tuple[str, int], np.ndarray] = {}
        for line in lay.lines():
            grid, pts = line.sample(0.002)
            s = grid[cKDTree(pts).query(adm.cells(line.name))[1]]
            assert (np.diff(s) > 0).all(), line.name
            for j in range(1, len(s)):
                self.path[(line.name, j)] = line.point_at(np.linspace(s[j - 1], s[j], 25))
        self.bearing = {
            lab: math.atan2(*(p - cfg.center)[::-1]) % (2 * math.pi)
            for lab, p in zip(self.labels, self.xy)
        }


@lru_cache(maxsize=None)
def geo(kind: str, size: str) -> Geo:
    return Geo(layout(kind, size))


# ------------------------------------------------------------------ the kinematic simulator


@dataclass
class Bot:
    name: str
    arrive: int
    entry: int
    tail: bool
    p: float
    pos: tuple[str, int] | None = None
    key: float = 0.0
    joined: int = -1
    join_at: tuple[str, int] | None = None
    left: int = -1
    docked: int = -1
    unloaded: bool = False
    route_len: int = 0


@dataclass
class Run:
    ticks: int = 0
    contests: int = 0
    bound: float = 0.0
    max_inner: int = 0
    max_stay: int = 0
    bots: list[Bot] = field(default_factory=list)


def simulate(
    kind: str, size: str, arrivals, seed: int, max_ticks: int = 6000, inner_rule: str = "any",
    join_order: str = "behind_tail",
) -> Run:
    """arrivals: [(tick, entry line index, tail joining?)]. Checks every invariant each tick.
    With `join_order` ``anywhere`` a tail joiner asks for a random cell of the whole line."""
    lay, g = layout(kind, size), geo(kind, size)
    adm = DepotAdmission(lay, lookahead=LOOKAHEAD, inner_rule=inner_rule, join_order=join_order)
    rng = np.random.default_rng(seed)
    n_entry = len(lay.entry_lines)
    bots = [
        Bot(f"robot_{i}", a, e % n_entry, tail, float(rng.uniform(P_MIN, 1.0)))
        for i, (a, e, tail) in enumerate(arrivals)
    ]
    by_name = {b.name: b for b in bots}
    run = Run(bots=bots)
    work = 0.0
    reported: set[str] = set()
    seen = (-1, None)  # (admission version, its snapshot without the time)
    for tick in range(max_ticks):
        t = float(tick)
        # arrivals join (entry point: cell 0; tail: a random cell behind the tail)
        for b in bots:
            if b.pos is not None or b.left >= 0 or b.arrive > tick:
                continue
            line = lay.entry_lines[b.entry].name
            cell = 0
            if b.tail:
                owned = [c for ln, c, _ in adm.snapshot().occupied if ln == line]
                tail = len(adm.cells(line)) if join_order == "anywhere" else min(owned, default=len(adm.cells(line)))
                if tail == 0:
                    continue
                cell = int(rng.integers(0, tail))
            reason = adm.join(b.name, line, cell, t)
            assert reason in (Refusal.NONE, Refusal.OCCUPIED, Refusal.NOT_BEHIND_TAIL, Refusal.KEEP_CLEAR), reason
            if reason is Refusal.NONE:
                b.pos, b.key, b.joined, b.join_at = (line, cell), t, tick, (line, cell)
                assert adm.grant(b.name) == (line, cell)
        # moves: at most one cell towards the grant, with probability p
        for b in bots:
            if b.pos is None:
                continue
            if b.pos in g.dock and not b.unloaded:
                if b.docked < 0:
                    b.docked = tick
                if tick - b.docked >= T_UNLOAD:
                    adm.unloaded(b.name, t)
                    b.unloaded = True
                continue
            route = adm.route(b.name)
            i, gi = where(route, b.pos), where(route, adm.grant(b.name))
            if i < gi and rng.random() < b.p:
                b.pos, b.key = route[i + 1], t
                adm.arrived(b.name, *b.pos, t)
                if b.name not in adm.robots_inside:
                    assert i + 1 == len(route) - 1 and route[-1][0] in {
                        ln.name for ln in lay.exit_lines
                    }
                    b.pos, b.left = None, tick
                    run.max_stay = max(run.max_stay, tick - b.joined)
        # step, with the FCFS check around it
        before = {}
        for b in bots:
            if b.pos is not None:
                route = adm.route(b.name)
                before[b.name] = (route, where(route, b.pos), where(route, adm.grant(b.name)))
        changed = adm.step(t)
        after = {b.name: adm.grant(b.name) for b in bots if b.pos is not None}
        assert set(changed) <= set(after)
        for name in after:
            route, _, gi = before[name]
            assert (name in changed) == (after[name] != route[gi] or name not in reported), name
            assert changed.get(name, after[name]) == after[name]
        reported |= set(changed)
        run.contests += check_fcfs(adm, g, before, by_name)
        check_invariants(adm, lay, g, bots)
        snap = replace(adm.snapshot(), t=0.0)
        # Readers keep their last snapshot while the version stands (`DepotServer.state`).
        assert adm.version != seen[0] or snap == seen[1], "the depot changed without a new version"
        seen = (adm.version, snap)
        run.max_inner = max([run.max_inner, *snap.inner_queue_counts])
        # route lengths, for the bound (a single-queue route is known once dispatched)
        for b in bots:
            if b.pos is not None and b.route_len == 0:
                route = adm.route(b.name)
                if route[-1][0].startswith("exit_line"):
                    b.route_len = len(route) - where(route, b.join_at)
                    work += b.route_len / P_MIN + T_UNLOAD + 1
                    run.bound = 2 * work + 10
        for b in bots:
            if b.pos is not None and b.route_len:
                assert tick - b.joined <= run.bound, f"{b.name} inside for too long (gridlock?)"
        if all(b.left >= 0 for b in bots):
            run.ticks = tick
            assert adm.robots_inside == () and adm.snapshot().left == len(bots)
            assert adm.snapshot().occupied == ()
            return run
    raise AssertionError(f"not all robots left in {max_ticks} ticks")


_ROUTE_INDEX: dict[int, tuple[tuple, dict]] = {}


def where(route: tuple, label: tuple[str, int]) -> int:
    """route.index(label), cached per route (the admission hands out shared route tuples)."""
    hit = _ROUTE_INDEX.get(id(route))
    if hit is None or hit[0] is not route:
        hit = _ROUTE_INDEX[id(route)] = (route, {lab: i for i, lab in enumerate(route)})
    return hit[1][label]


def check_invariants(adm: DepotAdmission, lay: QueueLayout, g: Geo, bots: list[Bot]) -> None:
    inside = [b for b in bots if b.pos is not None]
    snap = adm.snapshot()
    assert snap.inside == tuple(sorted(b.name for b in inside))
    routes = {b.name: adm.route(b.name) for b in inside}
    grants = {b.name: adm.grant(b.name) for b in inside}
    at = {b.name: (where(routes[b.name], b.pos), where(routes[b.name], grants[b.name]))
          for b in inside}
    # no conflicting ownership, checked on centre distances (independent of the admission)
    owned = [(g.index[(ln, c)], r, ln, c) for ln, c, r in snap.occupied]
    idx = np.array([o[0] for o in owned], dtype=int)
    owner = np.array([o[1] for o in owned])
    if len(owned) > 1:
        d = g.dist[np.ix_(idx, idx)]
        for a, b in zip(*np.nonzero(d < g.thr - 1e-6)):
            (_, ra, la, ca), (_, rb, lb, cb) = owned[a], owned[b]
            if ra == rb:
                continue
            assert g.adjacent[idx[a], idx[b]] and d[a, b] >= g.cfg.robot_diameter - 1e-6, (
                f"{ra} owns {la}/{ca} and {rb} owns {lb}/{cb}, {d[a, b]:.3f} m apart"
            )
        # and on the admission's own conflict relation
        clash = g.conf[np.ix_(idx, idx)] & (owner[:, None] != owner[None, :])
        assert not clash.any()
    # robots sit on their own cells; a robot driving to its next cell passes no one else's
    own_cells = {(ln, c, r) for ln, c, r in snap.occupied}
    for b in inside:
        assert (*b.pos, b.name) in own_cells
        i, gi = at[b.name]
        others = idx[owner != b.name] if len(owned) else idx
        if gi > i and len(others):
            path = g.path[routes[b.name][i + 1]]
            gap = np.linalg.norm(path[:, None] - g.xy[others][None], axis=2).min()
            assert gap >= g.cfg.robot_diameter - 2e-3, f"{b.name} drives {gap:.3f} m from a robot"
    # at most one robot per dock (by position and by ownership)
    docked = [(g.dock_of[b.pos], b.name) for b in inside if b.pos in g.dock_of]
    assert len({k for k, _ in docked}) == len(docked)
    for k, name in docked:
        assert snap.dock_occupants[k] == name
    # at most two robots per inner queue, counted from the robots' own positions and grants
    count = [0] * len(lay.inner_queues)
    for b in inside:
        line = b.pos[0] if b.pos[1] >= 1 else ""
        if b.pos[0].startswith("entry"):
            line = grants[b.name][0]
        if line.startswith("inner_queue_"):
            count[int(line.rsplit("_", 1)[1])] += 1
    assert max(count, default=0) <= 2, count
    assert snap.inner_queue_counts == tuple(count)
    # keep clear, lookahead, liveness
    live = False
    for b in inside:
        route, (i, gi) = routes[b.name], at[b.name]
        assert gi >= i
        end = route[gi]
        assert not g.keep_clear[g.index[end]] or gi == len(route) - 1, f"{b.name} stops at {end}"
        if gi > i + LOOKAHEAD:
            assert all(g.keep_clear[g.index[lab]] for lab in route[i + LOOKAHEAD : gi])
        live |= gi > i or (b.pos in g.dock and not b.unloaded)
    assert live or not inside, "gridlock: nobody inside can move"
    # queue lengths and last robot
    for e, ln in enumerate(lay.entry_lines):
        on = [b for b in inside if b.pos[0] == ln.name]
        assert snap.entry_queue_lengths[e] == len(on)
        tail = min((b.pos[1] for b in on), default=-1)
        for b in on:
            assert adm.is_last(b.name) == (b.pos[1] == tail)
    assert adm.last_robots() == {name for name in adm.robots_inside if adm.is_last(name)}  # all at once


def check_fcfs(adm: DepotAdmission, g: Geo, before, bots: dict[str, Bot]) -> int:
    """A robot standing at its grant end whose next run (the next cell, through keep-clear
    cells to the next cell where it may stop) was free, yet got nothing, must have lost it to a
    robot served before it (earlier wait, or same wait and smaller bearing): one that was granted
    or claimed a conflicting cell. Returns how many such contests happened."""

    def order(name: str):
        route, i, _ = before[name]
        return (bots[name].key, g.bearing[route[i]], name)

    owned = [(g.index[lab], name) for name, (route, i, gi) in before.items()
             for lab in route[i : gi + 1]]

    def run_of(route, gi) -> list[int]:
        out = []
        for lab in route[gi + 1 :]:
            out.append(g.index[lab])
            if not g.keep_clear[g.index[lab]] or lab == route[-1]:
                break
        return out

    def rule_free(name: str) -> bool:
        route, i, gi = before[name]
        if route[i] in g.dock:
            return False
        return not (route[i] in g.entry_ends and not route[-1][0].startswith("exit_line"))

    def new_and_claimed(name: str) -> list[int]:
        route, i, gi = before[name]
        now = adm.route(name)
        grant = adm.grant(name)
        cells = [g.index[lab] for lab in now[where(now, route[gi]) + 1 : where(now, grant) + 1]]
        if gi == i:  # standing at its grant end: it may claim what it waits for
            if rule_free(name):
                cells += run_of(route, gi)
            elif route[i] in g.dock and bots[name].unloaded:
                cells += run_of(route, gi)
                ln = route[i][0]
                if ln.startswith("inner"):  # the leave-the-dock rule's cells
                    n = len([lab for lab in g.labels if lab[0] == ln])
                    cells += [g.index[(ln, c)] for c in range(route[i][1] + 1, n)]
        return cells

    contests = 0
    for name, (route, i, gi) in before.items():
        if gi != i or not rule_free(name) or adm.grant(name) != route[gi]:
            continue
        run = run_of(route, gi)
        others = np.array([c for c, o in owned if o != name], dtype=int)
        if len(others) and g.conf[np.ix_(run, others)].any():
            continue  # its run was not free: nothing to check
        contests += 1
        earlier = [o for o in before if order(o) < order(name)]
        assert any(
            g.conf[np.ix_(run, new_and_claimed(o))].any() for o in earlier if new_and_claimed(o)
        ), f"{name} was not granted its free run {[g.labels[c] for c in run]}"
    return contests


# ------------------------------------------------------------------ cells


@pytest.mark.parametrize("kind", ["single", "multi"])
@pytest.mark.parametrize("size", list(CONFIGS))
def test_cells_follow_the_lines_and_end_at_docks(kind, size):
    lay = layout(kind, size)
    adm = DepotAdmission(lay)
    cfg = lay.config
    names = {ln.name: ln for ln in lay.lines()}
    assert set(adm.lines()) == set(names)
    assert adm.lines()[: len(lay.entry_lines)] == tuple(ln.name for ln in lay.entry_lines)
    for name in adm.lines():
        cells, line = adm.cells(name), names[name]
        np.testing.assert_allclose(cells[0], line.start, atol=1e-9)
        np.testing.assert_allclose(cells[-1], line.end, atol=1e-9)
        gaps = np.linalg.norm(np.diff(cells, axis=0), axis=1)
        assert gaps.min() >= cfg.robot_diameter - 1e-6
        assert gaps.max() <= cfg.pitch + cfg.robot_diameter + 1e-3
        _, pts = line.sample(0.001)
        off = cKDTree(pts).query(cells)[0]
        assert off.max() < 2e-3, name  # on the line (ring cells: within the arc discretisation)
    for k, dock in enumerate(lay.docks):
        if kind == "multi":
            np.testing.assert_array_equal(adm.cells(f"entry_line_{k}")[-1], dock.stop)
            np.testing.assert_array_equal(adm.cells(f"exit_line_{k}")[0], dock.stop)
        else:
            cells = adm.cells(f"inner_queue_{k}")
            assert (np.linalg.norm(cells - dock.stop, axis=1) < 1e-12).sum() == 1
        dock_cell = next(lab for lab, d in geo(kind, size).dock_of.items() if d == k)
        assert not adm.keep_clear(*dock_cell)


@pytest.mark.parametrize("size", list(CONFIGS))
def test_conflicts_cover_crossings_but_not_adjacent_lanes(size):
    g = geo("single", size)
    # centre distance below (d + lane)/2 between different lines is always a conflict
    close = (g.dist < g.thr - 1e-6) & (g.dist > 1e-6) & ~g.adjacent
    assert (g.conf | ~close).all()
    assert g.conf[(g.dist < g.cfg.robot_diameter - 1e-6)].all()  # a fortiori, any overlap
    # no line crosses the entry line (the exit leaves through the arcs' gap); the inner queues'
    # last legs merge at the inner exit point, whose approach cells are keep-clear
    lay = layout("single", size)
    assert lay.crossings == ()
    entry = [k for k, lab in enumerate(g.labels) if lab[0] == "entry_line"]
    assert not any(g.keep_clear[k] for k in entry[:-2])  # only by the head (the step to the ring)
    ends = [g.index[(q.name, max(c for ln, c in g.labels if ln == q.name))] for q in lay.inner_queues]
    assert all(g.dist[ends[0], e] < 1e-9 for e in ends)  # one shared inner exit point
    # robots of different inner queues share ring cells: the overlap is not a conflict
    ring = [lab for lab in g.labels if lab[0] == "inner_queue_0"][1:4]
    assert all(g.conf[g.index[lab], g.index[lab]] for lab in ring)
    # the multi layout's lanes are a lane spacing apart: nothing conflicts, nothing is keep-clear
    gm = geo("multi", size)
    assert not gm.keep_clear.any()
    assert (gm.dist[gm.conf] < 1e-6).all()  # only aliases (same physical cell)


# ------------------------------------------------------------------ reports


def test_join_order_anywhere_takes_a_free_cell_ahead_of_the_tail():
    """The queue authors' Q_ST boards wherever it gets in (`QueueConfig.join_order`)."""
    adm = DepotAdmission(layout("multi", "small"), join_order="anywhere")
    assert adm.join("a", "entry_line_0", 5, 0.0) is Refusal.NONE
    assert adm.join("b", "entry_line_0", 5, 0.0) is Refusal.OCCUPIED
    assert adm.join("b", "entry_line_0", 7, 0.0) is Refusal.NONE  # ahead of a
    assert adm.is_last("a") and not adm.is_last("b")
    with pytest.raises(ValueError, match="join_order"):
        DepotAdmission(layout("multi", "small"), join_order="front")


def test_cell_release_on_departure_lets_the_follower_close_up():
    """`QueueConfig.cell_release`: on ``departure`` the robot behind is granted the cell of a robot
    that holds a grant beyond it (the queue authors' robots follow one another with no cells); on
    ``arrival`` only once that robot has reported its next cell. The leaver's arrival does not
    take the cell back from its follower."""
    grants = {}
    for release in ("arrival", "departure"):
        adm = DepotAdmission(layout("multi", "small"), lookahead=2, cell_release=release)
        assert adm.join("a", "entry_line_0", 5, 0.0) is Refusal.NONE
        assert adm.join("b", "entry_line_0", 4, 1.0) is Refusal.NONE
        adm.step(2.0)
        assert adm.grant("a")[1] > 5
        adm.step(3.0)
        grants[release] = adm.grant("b")
        if release == "departure":
            adm.arrived("a", "entry_line_0", 6, 4.0)
            assert adm.join("c", "entry_line_0", 5, 4.0) is Refusal.OCCUPIED
            adm.arrived("b", "entry_line_0", 5, 5.0)
    assert grants == {"arrival": ("entry_line_0", 4), "departure": ("entry_line_0", 5)}
    with pytest.raises(ValueError, match="cell_release"):
        DepotAdmission(layout("multi", "small"), cell_release="never")


def test_join_refusals_and_is_last():
    adm = DepotAdmission(layout("multi", "small"))
    n = len(adm.cells("entry_line_0"))
    assert adm.join("a", "exit_line_0", 0, 0.0) is Refusal.UNKNOWN_LINE
    assert adm.join("a", "nowhere", 0, 0.0) is Refusal.UNKNOWN_LINE
    assert adm.join("a", "entry_line_0", n, 0.0) is Refusal.UNKNOWN_CELL
    assert adm.join("a", "entry_line_0", 5, 0.0) is Refusal.NONE
    assert adm.join("a", "entry_line_1", 0, 0.0) is Refusal.ALREADY_INSIDE
    assert adm.join("b", "entry_line_0", 5, 0.0) is Refusal.OCCUPIED
    assert adm.join("b", "entry_line_0", 7, 0.0) is Refusal.NOT_BEHIND_TAIL
    assert adm.join("b", "entry_line_0", 4, 0.0) is Refusal.NONE  # right behind the tail
    assert adm.is_last("b") and not adm.is_last("a") and not adm.is_last("nobody")
    assert adm.join("c", "entry_line_0", 0, 1.0) is Refusal.NONE
    assert adm.is_last("c") and not adm.is_last("b")
    assert adm.join("d", "entry_line_1", 0, 1.0) is Refusal.NONE  # other lines are independent
    assert adm.robots_inside == ("a", "b", "c", "d")
    snap = adm.snapshot()
    assert snap.entry_queue_lengths == (3, 1, 0, 0)
    assert snap.occupied == tuple(sorted(
        [("entry_line_0", 5, "a"), ("entry_line_0", 4, "b"), ("entry_line_0", 0, "c"),
         ("entry_line_1", 0, "d")]))
    changed = adm.step(2.0)
    assert changed["a"] == ("entry_line_0", 5 + LOOKAHEAD)
    assert changed["b"] == ("entry_line_0", 4) and changed["c"][1] == 3
    assert adm.step(2.0) == {}  # nothing changed since


def test_single_queue_join_refuses_keep_clear_cells():
    g = geo("single", "default")
    adm = DepotAdmission(layout("single", "default"))
    kc = [lab for lab in g.labels if lab[0] == "entry_line" and g.keep_clear[g.index[lab]]]
    assert kc
    assert adm.join("a", *kc[-1], 0.0) is Refusal.KEEP_CLEAR
    assert adm.join("a", "entry_line", 0, 0.0) is Refusal.NONE


def test_arrived_and_unloaded_errors():
    adm = DepotAdmission(layout("multi", "small"))
    n = len(adm.cells("entry_line_0"))
    with pytest.raises(ValueError, match="unknown robot"):
        adm.arrived("ghost", "entry_line_0", 1, 0.0)
    assert adm.join("a", "entry_line_0", n - 3, 0.0) is Refusal.NONE
    adm.step(0.0)
    with pytest.raises(ValueError, match="not on its route"):
        adm.arrived("a", "entry_line_1", n - 2, 0.1)
    with pytest.raises(ValueError, match="not on its route"):
        adm.arrived("a", "exit_line_0", 99, 0.1)
    with pytest.raises(ValueError, match="beyond its grant"):
        adm.arrived("a", "exit_line_0", 2, 0.1)  # the dock stops it until unloaded
    with pytest.raises(ValueError, match="not at its dock"):
        adm.unloaded("a", 0.1)
    adm.arrived("a", "entry_line_0", n - 1, 0.2)  # skipping a granted cell is fine
    with pytest.raises(ValueError, match="behind"):
        adm.arrived("a", "entry_line_0", n - 2, 0.3)
    adm.arrived("a", "exit_line_0", 0, 0.3)  # the dock's other name: no-op
    assert adm.step(0.3) == {}  # nothing past the dock before unloading
    adm.unloaded("a", 0.4)
    out = adm.step(0.4)
    assert out["a"][0] == "exit_line_0"
    last = len(adm.cells("exit_line_0")) - 1
    for c in range(1, last + 1):
        adm.step(0.5)
        adm.arrived("a", "exit_line_0", c, 0.5)
    assert adm.robots_inside == () and adm.snapshot().left == 1 and adm.grant("a") is None
    assert adm.step(0.6) == {}  # a robot that has left is not reported
    assert adm.join("a", "entry_line_0", 0, 1.0) is Refusal.NONE  # and may come back


# ------------------------------------------------------------------ right of way


def crossing_layout(rotation: float) -> QueueLayout:
    """Two docks whose exit lines cross at (0, 0.8) (rotated by `rotation` about the origin):
    the smallest layout with a contested cell."""
    cfg = DepotGeometryConfig()
    c, s = math.cos(rotation), math.sin(rotation)
    rot = np.array([[c, -s], [s, c]])

    def pts(*p):
        return np.array(p, float) @ rot.T

    stops = pts((0.3, 0.5), (-0.3, 0.5))
    docks = tuple(
        Dock(k, math.atan2(p[1], p[0]), p * 0.5 / np.linalg.norm(p), p) for k, p in enumerate(stops)
    )
    entries = (Polyline("entry_line_0", pts((1.5, 0.5), (0.3, 0.5))),
               Polyline("entry_line_1", pts((-1.5, 0.5), (-0.3, 0.5))))
    exits = (Polyline("exit_line_0", pts((0.3, 0.5), (-0.9, 1.7))),
             Polyline("exit_line_1", pts((-0.3, 0.5), (0.9, 1.7))))
    return QueueLayout("multi", cfg, docks, 1.0, entries, exits)


def _both_at_docks(rotation: float, t0: float, t1: float) -> DepotAdmission:
    adm = DepotAdmission(crossing_layout(rotation))
    for k, t in ((0, t0), (1, t1)):
        line = f"entry_line_{k}"
        assert adm.join(f"r{k}", line, len(adm.cells(line)) - 1, t) is Refusal.NONE  # at the dock
        adm.unloaded(f"r{k}", t)
    return adm


def _winner(adm: DepotAdmission) -> str:
    """Step once; the robot granted through the crossing (the other must stop before it)."""
    adm.step(5.0)
    through = []
    for k in range(2):
        line, cell = adm.grant(f"r{k}")
        cells = adm.cells(f"exit_line_{k}")
        if line == f"exit_line_{k}" and np.linalg.norm(cells[cell] - cells[0]) > 0.6:
            through.append(f"r{k}")  # past the crossing, 0.42 m from the dock
    assert len(through) == 1, through
    loser = "r1" if through == ["r0"] else "r0"
    line, cell = adm.grant(loser)
    assert not any(adm.keep_clear(line, c) for c in range(cell + 1))
    return through[0]


def test_crossing_is_contested():
    g = Geo(crossing_layout(0.0))
    assert g.keep_clear.sum() >= 2
    assert not any(g.keep_clear[g.index[lab]] for lab in g.dock)


def test_fcfs_earlier_waiter_wins_regardless_of_bearing():
    assert _winner(_both_at_docks(0.0, t0=1.0, t1=0.0)) == "r1"  # r1 waited first
    assert _winner(_both_at_docks(0.0, t0=0.0, t1=1.0)) == "r0"


def test_tie_goes_counter_clockwise():
    # dock 0 at bearing 59 deg, dock 1 at 121 deg: ascending bearing in [0, 2 pi) -> r0
    assert _winner(_both_at_docks(0.0, 0.0, 0.0)) == "r0"
    # rotated by 270 deg: dock 0 at 329 deg, dock 1 at 31 deg -> r1 comes first
    assert _winner(_both_at_docks(1.5 * math.pi, 0.0, 0.0)) == "r1"
    # rotated by 180 deg: 239 deg vs 301 deg -> r0
    assert _winner(_both_at_docks(math.pi, 0.0, 0.0)) == "r0"


def test_single_queue_dispatch_goes_to_first_free_dock_ccw():
    lay = layout("single", "default")
    adm = DepotAdmission(lay)
    e_end = len(adm.cells("entry_line")) - 1
    e_in = adm.cells("entry_line")[-1]
    a0 = math.atan2(e_in[1], e_in[0]) % (2 * math.pi)
    ccw = sorted(range(len(lay.docks)), key=lambda k: (lay.docks[k].angle - a0) % (2 * math.pi))
    got = []
    for r in range(len(lay.docks)):
        name = f"r{r}"
        assert adm.join(name, "entry_line", e_end, float(r)) is Refusal.NONE
        adm.step(float(r))
        line, _ = adm.grant(name)
        got.append(int(line.rsplit("_", 1)[1]))
        route = adm.route(name)  # drive it to its dock, where it stays (not unloaded)
        while route.index(adm.position(name)) < route.index(adm.grant(name)):
            adm.arrived(name, *route[route.index(adm.position(name)) + 1], float(r))
            adm.step(float(r))
        assert adm.position(name) in geo("single", "default").dock
        assert adm.snapshot().dock_occupants[got[-1]] == name
    assert got == ccw
    # every dock taken: the next robot waits at the inner entry point
    assert adm.join("late", "entry_line", e_end, 9.0) is Refusal.NONE
    adm.step(9.0)
    assert adm.grant("late") == ("entry_line", e_end)
    assert adm.snapshot().inner_queue_counts == (1,) * len(lay.docks)


def drive(adm: DepotAdmission, name: str, t: float, target: tuple[str, int] | None = None):
    """Step, then move `name` cell by cell while granted, until it reaches `target`, its grant
    stops it, or it leaves; -> its position (None once it has left)."""
    for _ in range(500):
        adm.step(t)
        pos = adm.position(name)
        if pos is None or pos == target:
            return pos
        route = adm.route(name)
        i = route.index(pos)
        if i == route.index(adm.grant(name)):
            return pos
        adm.arrived(name, *route[i + 1], t)
    raise AssertionError("did not stop")


def test_first_to_finish_unloading_merges_first():
    """Where the inner queues' last legs merge (sec. IV-D): the robot that finished unloading
    first is granted through the inner exit point, and one that finishes while it is on its
    way waits at its dock until the merge is clear."""
    lay, g = layout("single", "default"), geo("single", "default")
    adm = DepotAdmission(lay, inner_rule="own")
    e_end = len([lab for lab in g.labels if lab[0] == "entry_line"]) - 1
    assert adm.join("A", "entry_line", e_end, 0.0) is Refusal.NONE
    dock_a = drive(adm, "A", 0.5)
    assert adm.join("B", "entry_line", e_end, 1.0) is Refusal.NONE
    dock_b = drive(adm, "B", 1.5)
    assert dock_a in g.dock and dock_b in g.dock and dock_a[0] != dock_b[0]
    adm.unloaded("B", 2.0)  # B finished first
    adm.step(2.0)
    adm.unloaded("A", 3.0)
    adm.step(3.0)
    route_b = adm.route("B")
    assert route_b.index(adm.grant("B")) > route_b.index(dock_b)  # B moves on
    assert adm.grant("A") == dock_a  # A waits: the way to the merge is B's
    assert drive(adm, "B", 4.0) is None  # B has left
    adm.step(5.0)
    route_a = adm.route("A")
    assert route_a.index(adm.grant("A")) > route_a.index(dock_a)


# ------------------------------------------------------------------ simulation properties


def arrivals_strategy(max_robots: int, max_tick: int = 30):
    return st.lists(
        st.tuples(st.integers(0, max_tick), st.integers(0, 5), st.booleans()),
        min_size=1, max_size=max_robots,
    )


SIM = settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.too_slow])
SIM_SINGLE = settings(SIM, max_examples=12)


@SIM
@given(arrivals=arrivals_strategy(14), seed=st.integers(0, 2**32 - 1),
       size=st.sampled_from(["default", "small", "two_docks", "six_docks"]),
       same=st.booleans(), join_order=st.sampled_from(["behind_tail", "anywhere"]))
def test_multi_queue_invariants(arrivals, seed, size, same, join_order):
    if same:  # everyone from one direction: one sector
        arrivals = [(a, 0, tail) for a, _, tail in arrivals]
    run = simulate("multi", size, arrivals, seed, join_order=join_order)
    assert run.max_stay <= run.bound


@SIM_SINGLE
@given(arrivals=arrivals_strategy(10), seed=st.integers(0, 2**32 - 1),
       size=st.sampled_from(["small", "two_docks", "six_docks"]), same_time=st.booleans(),
       inner_rule=st.sampled_from(["any", "own"]), join_order=st.sampled_from(["behind_tail", "anywhere"]))
def test_single_queue_invariants(arrivals, seed, size, same_time, inner_rule, join_order):
    if same_time:
        arrivals = [(0, e, tail) for _, e, tail in arrivals]
    run = simulate("single", size, arrivals, seed, inner_rule=inner_rule, join_order=join_order)
    assert run.max_inner <= 2 and run.max_stay <= run.bound


@pytest.mark.parametrize("kind", ["single", "multi"])
def test_everyone_at_once_from_one_direction_default_layout(kind):
    """The paper's worst case for multi-queue: all robots at the same entry line and time."""
    run = simulate(kind, "default", [(0, 0, True)] * 8 + [(0, 0, False)] * 8, seed=3)
    assert run.max_stay <= run.bound
    assert all(b.left >= 0 for b in run.bots)
    if kind == "single":
        assert run.max_inner == 2  # the inner queues were used to the limit


@pytest.mark.parametrize("inner_rule", ["any", "own"])
def test_heavy_single_queue_six_docks(inner_rule):
    arrivals = [(i // 2, 0, i % 3 == 0) for i in range(14)]
    run = simulate("single", "six_docks", arrivals, seed=11, inner_rule=inner_rule)
    assert run.max_inner == 2


# ------------------------------------------------------------------ server


def _scenario(wrapping: str, **queue) -> Scenario:
    controller = ControllerConfig(behaviour="queue").with_section("queue", QueueConfig(wrapping=wrapping, **queue))
    return Scenario(depot=DepotConfig(delivery="docks"), controller=controller)


class _Recorded:
    """A depot server stepped as the batch runner steps it: its ``queue_lengths`` series read off
    the state it publishes (`depot_manager.codec.OUTPUTS`)."""

    def __init__(self, srv: DepotServer) -> None:
        self.srv, self.series = srv, {}
        self._watch = StateWatch(OUTPUTS.state)

    def step(self, stamp_ns, messages):
        out = self.srv.step(stamp_ns, messages)
        for st, value in self._watch.changed(self.srv.state()):
            for series in OUTPUTS.series:
                if series.topic == st.topic:
                    series.record(self.series, stamp_ns, value)
        return out

    @property
    def history(self):
        return self.series.get("queue_lengths", [])


def test_server_refusals_grants_history_errors():
    srv = DepotServer(_scenario("multi"))
    rec = _Recorded(srv)
    n = len(srv.admission.cells("entry_line_0"))
    s = 1_000_000_000
    out = rec.step(1 * s, [
        DepotReport(0, "robot_2", ReportKind.JOIN, "entry_line_0", 5),
        DepotReport(0, "robot_1", ReportKind.JOIN, "entry_line_0", 5),
        DepotReport(0, "robot_10", ReportKind.JOIN, "nowhere", 0),
        DepotReport(0, "robot_3", ReportKind.JOIN, "entry_line_0", 9),
        DepotReport(0, "robot_4", ReportKind.JOIN, "entry_line_1", 0),
        ProgressReport(0, "robot_9", 0.0, 0.0, -1, 0.0, False),  # not for the depot: ignored
    ])
    assert [g.robot for g in out] == sorted(g.robot for g in out)
    by = {g.robot: g for g in out}
    assert by["robot_1"] == DepotGrant(s, "robot_1", "entry_line_0", -1, False, Refusal.OCCUPIED)
    assert by["robot_10"].cell == -1 and by["robot_10"].reason is Refusal.UNKNOWN_LINE
    assert by["robot_3"].reason is Refusal.NOT_BEHIND_TAIL
    assert by["robot_2"] == DepotGrant(s, "robot_2", "entry_line_0", 5 + LOOKAHEAD, True)
    assert by["robot_4"] == DepotGrant(s, "robot_4", "entry_line_1", LOOKAHEAD, True)
    assert rec.history == [(1.0, (1, 1, 0, 0))]
    # already inside
    out = rec.step(2 * s, [DepotReport(s, "robot_2", ReportKind.JOIN, "entry_line_2", 0)])
    assert out == (DepotGrant(2 * s, "robot_2", "entry_line_2", -1, False, Refusal.ALREADY_INSIDE),)
    # a robot joining behind robot_2 takes `last` from it: both are told
    out = rec.step(3 * s, [DepotReport(2 * s, "robot_5", ReportKind.JOIN, "entry_line_0", 0)])
    assert [(g.robot, g.last) for g in out] == [("robot_2", False), ("robot_5", True)]
    assert out[0].cell == 5 + LOOKAHEAD  # unchanged grant, re-sent for the flag
    assert rec.history[-1] == (3.0, (2, 1, 0, 0))
    # bad reports are recorded, not raised
    out = rec.step(4 * s, [
        DepotReport(3 * s, "ghost", ReportKind.AT, "entry_line_0", 1),
        DepotReport(3 * s, "robot_2", ReportKind.AT, "entry_line_0", 99),
        DepotReport(3 * s, "robot_2", "teleport"),
        DepotReport(3 * s, "robot_2", ReportKind.UNLOADED),
        DepotReport(3 * s, "robot_2", ReportKind.AT, "entry_line_0", 6),
    ])
    assert srv.rejections.counts == {("DepotReport", "unknown robot"): 1, ("DepotReport", "refused"): 3}
    assert [(g.robot, g.cell) for g in out] == [("robot_2", 6 + LOOKAHEAD), ("robot_5", 5)]
    assert len(rec.history) == 2  # queue lengths unchanged
    # robot_2 all the way through: dock, unloading, exit, gone
    adm = srv.admission
    tick = 5
    while "robot_2" in adm.robots_inside:
        route, pos = adm.route("robot_2"), adm.position("robot_2")
        i = route.index(pos)
        if pos[0] == "entry_line_0" and pos[1] == n - 1 and adm.grant("robot_2") == pos:
            msg = DepotReport(0, "robot_2", ReportKind.UNLOADED)
        else:
            assert route.index(adm.grant("robot_2")) > i
            msg = DepotReport(0, "robot_2", ReportKind.AT, *route[i + 1])
        out = rec.step(tick * s, [msg])
        tick += 1
        assert tick < 100
    assert "robot_2" not in [g.robot for g in out] and adm.snapshot().left == 1
    assert srv.rejections.total == 4
    # robot_2 left the queue when it drove off its dock onto the exit line
    assert [h[1] for h in rec.history] == [(1, 1, 0, 0), (2, 1, 0, 0), (1, 1, 0, 0)]
    times = [h[0] for h in rec.history]
    assert times == sorted(times) and times[-1] < tick - 1


def test_server_single_queue_layout_from_scenario():
    srv = DepotServer(_scenario("single"))
    assert srv.layout.kind == "single" and len(srv.layout.docks) == 4
    assert srv.admission.lines()[0] == "entry_line"
    assert srv.admission.inner_rule == "own"  # the scenario's default
    any_rule = _scenario("single", inner_rule="any")
    assert DepotServer(any_rule).admission.inner_rule == "any"
    with pytest.raises(ValueError):
        DepotServer(_scenario("none"))
    with pytest.raises(ValueError, match="inner_rule"):
        DepotAdmission(srv.layout, inner_rule="some")
    with pytest.raises(ValueError, match="lookahead"):
        DepotAdmission(srv.layout, lookahead=0)
