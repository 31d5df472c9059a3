"""Depot admission: the depot manager's single authority over queue slots
(queue_depot_traffic.md secs. III, IV-A/B/D, V).

ROS-free and deterministic; `t` is sim time [s] and only orders requests (FCFS).

Cell model
----------
Every line of the layout (entry lines, inner queues, exit lines) is cut into *cells*: robot-sized
slots `Polyline.slots(pitch)` from the line's start (index 0), then made to end exactly at the
line's end: trailing slots closer than one robot diameter to the end are dropped and the end
itself is appended, so neighbouring cells are between one robot diameter and pitch + diameter
apart. Consequences:

- multi: the last cell of ``entry_line_k`` is dock k's stop; ``exit_line_k`` cell 0 is the
  same physical cell (an alias).
- single: the last cell of ``entry_line`` is the inner entry point, which is also cell 0 of every
  inner queue; the last cell of every inner queue is the inner exit point, which is also
  ``exit_line`` cell 0.
- single inner queues overlap on the ring lane. Their ring cells are taken from one common
  *ring grid* (the cells of inner entry point -> ring -> inner exit point, without any V), so an
  overlap is the *same* cell on several inner queues, not a conflict, and robots of different
  inner queues follow each other along the ring. Around its own dock an inner queue leaves the
  grid: the slots of its V from the last grid cell before the V down to the dock stop, the dock
  stop, and the slots of its V from the dock up to the first grid cell after it (each part made
  to end exactly as above). The skipped grid cells above the V conflict with the V's cells.

Physical cells are identified only through these aliases and the ring grid, never by accident of
position: two cells of different lines that happen to lie on each other *conflict*.

Conflicts: two distinct cells conflict if their centres are closer than (robot_diameter +
lane_spacing)/2, or, for cells adjacent on a line, closer than robot_diameter (adjacent slots
are nose to tail by design). Adjacent lanes, exactly lane_spacing apart, do not conflict;
overlapping or crossing lines do. Our addition, *swept* conflicts: if a robot driving along a
line from a cell to the next passes within a robot diameter of a third cell that conflicts with
neither, that cell conflicts with the destination (with the origin if the destination is a dock,
which must stay clear). Example: leaving a dock up its V passes 0.15 m from the ring cell above
the dock. An *intersection cell* is a cell with any conflict.

A robot *owns* the cells from the one it last reported (`arrived`/`join`) up to its grant.
A cell is *free* for robot r if no other robot owns it or a cell conflicting with it.

Routes: multi: entry_line_k (its last cell is dock k) -> exit_line_k. single: entry_line ->
inner_queue_k (chosen at dispatch) -> exit_line. A robot leaves the perimeter on reaching the
last cell of its exit line.

Rules (the paper's) and the choices it leaves open
---------------------------------------------------
- **join** (sec. V): accepted iff the line is an entry line, the robot is not inside, the cell
  and its conflicts are free, the cell is behind the tail (its index is below every owned cell
  of that line: robots queue towards higher indices), and it is not an intersection cell.
  With ``join_order="anywhere"`` (the queue authors' Q_ST code, `depot_manager.config.QueueConfig`)
  a free cell ahead of the tail is accepted too; the robots behind it then wait for the newcomer,
  which is downstream of them, so the no-gridlock argument below is unchanged.
  Refusals (`depot_manager.protocol.Refusal`), checked in this order: UNKNOWN_LINE,
  ALREADY_INSIDE, UNKNOWN_CELL (index out of range; our addition), OCCUPIED, NOT_BEHIND_TAIL,
  KEEP_CLEAR (an intersection cell: a robot waiting there could close a gridlock; our addition).
- **arrived**: the robot reached a cell of its route (either name of an alias); it releases
  every cell before it. A cell behind its current one, beyond its grant or not on its route, or
  an unknown robot, is a ValueError. Reporting its current cell again is a no-op (it keeps its
  waiting time). Reaching the last cell of the exit line: it has left; everything is released.
- **unloaded**: only while the robot is at its dock cell (else ValueError); repeats are no-ops.
  It does not restart the robot's waiting time, so a robot that waited at its dock keeps its
  place in the FCFS order.
- **step** (grants): robots are served in FCFS order of the time they started waiting for their
  next cell, i.e. the time of their last `arrived`/`join`; ties go counter-clockwise: ascending
  bearing of the robot's current cell about the depot centre, atan2 mapped to [0, 2 pi); then
  robot id. A robot is topped up whenever its grant ends fewer than `lookahead` cells ahead of
  its current cell (a rolling horizon, so robots need not stop at every grant); it is extended
  greedily through free cells along its route to at most `lookahead` cells ahead of its current
  cell, with:
  * **keep clear** (sec. IV-D): a grant never ends on an intersection cell (except the route's
    last cell, where the robot leaves). It extends through a run of intersection cells only if
    the whole run and the non-intersection cell after it are free; such a run is granted at once
    even beyond `lookahead` (stopping inside it is not allowed, so the run is indivisible).
    Otherwise the grant stops before the run.
  * **dock**: a grant never passes a dock cell before `unloaded`.
  * **dispatch** (single, sec. IV-A): a robot whose grant reaches the end of the entry line (the
    inner entry point; it need not have stopped there) is dispatched into inner queue k, which
    fixes the rest of its route, only if no other robot owns the dock
    cell or a cell conflicting with it, and no other robot owns a cell of inner queue k between
    the entry point (exclusive) and the dock. Among the eligible docks the first one
    counter-clockwise from the inner entry point is chosen; if no cell can be granted along it
    this step, the robot is not dispatched yet (and may get another dock later).
  * **leaving the dock** (single, sec. IV-A): after `unloaded` the robot gets cells past its dock
    only if the inner exit point is free and no other robot owns a cell of inner queue k
    between the dock (exclusive) and the inner exit point. Hence at most two robots per inner
    queue: one between the entry point and the dock (inclusive), one after the dock.
    Our inner queues share the ring, so read literally ("other robot" = any robot,
    ``inner_rule="any"``, this class's default; the scenario's is ``own``) both rules also wait for robots of other inner queues
    and the ring nearly serialises; ``inner_rule="own"`` counts only robots dispatched into the
    same inner queue (cell ownership and keep-clear keep the others apart), which about doubles
    the inner region's throughput in our tests and keeps the two-robot bound.
  * **FCFS claims**: a robot standing at its grant end whose next cells cannot be granted claims
    them (the run it needs, or for a robot held at its dock the cells of the leave-the-dock
    rule) against robots served after it *that are upstream of it* (an earlier cell in the
    topological order of the route graph). Claims are never made against downstream robots:
    a downstream robot may be the one the claimer waits for, and such a claim would close a
    wait cycle. Claims last one step.
- **No gridlock.** Cells along every route strictly increase in a topological order of the
  route graph (checked at construction). A robot that has stopped does so on a non-intersection
  cell (docks and the inner entry point must be such cells: checked at construction), so it
  only blocks robots that want that very cell, which are upstream of it; claims, the dispatch
  and the leave-the-dock rules also only make robots wait for downstream ones. So after every
  step some robot inside has a grant beyond its cell or is unloading at its dock (the most
  downstream stopped robot is unloading or gets its cells, unless a robot served before it took
  them): some robot can always move, and since routes are finite every robot leaves once
  arrivals stop. Waiting is not bounded per robot under endless arrivals (the paper's rules
  allow a robot at a dock to wait while the ring is busy); claims make it FCFS against upstream
  robots.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from depot_manager.cells import _bearing, _model
from depot_manager.geometry import QueueLayout
from depot_manager.protocol import Refusal


@dataclass(frozen=True)
class DepotState:
    """What the depot manager knows at one instant (for `/depot/state` and metrics)."""

    t: float
    """Sim time of the last `step` [s]."""
    entry_lines: tuple[str, ...]
    entry_queue_lengths: tuple[int, ...]
    """Per entry line, robots whose current cell is on it (its last cell included)."""
    dock_occupants: tuple[str, ...]
    """Per dock, the robot owning its cell, '' if none."""
    inner_queue_counts: tuple[int, ...]
    """Per inner queue (single only), robots dispatched into it and not yet past its exit
    point."""
    occupied: tuple[tuple[str, int, str], ...]
    """Every owned cell as (line, cell, robot), named along the owner's route, sorted."""
    inside: tuple[str, ...]
    """Robots inside the perimeter (joined, not left), sorted."""
    left: int
    """Robots that have left the perimeter so far."""


class _Robot:
    """A robot inside the perimeter (mutable bookkeeping of `DepotAdmission`)."""

    __slots__ = (
        "name", "entry", "route", "labels", "lookup", "pos", "end", "key", "unloaded",
        "complete", "inner", "dock_pos", "entry_len", "inner_end",
    )

    def __init__(self, name: str, entry: int, t: float) -> None:
        self.name = name
        self.entry = entry
        self.route: tuple[int, ...] = ()
        self.labels: tuple[tuple[str, int], ...] = ()
        self.lookup: dict[tuple[str, int], int] = {}
        self.pos = self.end = 0
        self.key = t
        self.unloaded = False
        self.complete = False
        self.inner = -1
        self.dock_pos = -1
        self.entry_len = 0
        self.inner_end = -1  # route index of the inner exit point (single)


class DepotAdmission:
    """Grants queue cells to robots: FCFS, keep-clear, one robot per dock, two per inner
    queue (see the module docstring for every rule)."""

    def __init__(
        self, layout: QueueLayout, *, lookahead: int = 8, inner_rule: str = "any", join_order: str = "behind_tail",
        cell_release: str = "arrival",
    ) -> None:
        if lookahead < 1:
            raise ValueError(f"lookahead must be >= 1, got {lookahead}")
        if inner_rule not in ("any", "own"):
            raise ValueError(f"inner_rule must be 'any' or 'own', got {inner_rule!r}")
        if join_order not in ("behind_tail", "anywhere"):
            raise ValueError(f"join_order must be 'behind_tail' or 'anywhere', got {join_order!r}")
        if cell_release not in ("arrival", "departure"):
            raise ValueError(f"cell_release must be 'arrival' or 'departure', got {cell_release!r}")
        self.behind_tail = join_order == "behind_tail"
        """A join must be behind every robot on the line (else any free cell will do)."""
        self.layout = layout
        self.lookahead = lookahead
        self.inner_rule = inner_rule
        """Who counts in the single-queue dispatch and leave-the-dock rules: ``any`` robot
        owning a cell of the inner queue (the paper read literally; our inner queues overlap on
        the ring, so robots of other inner queues count too and the ring nearly serialises), or
        only robots dispatched into that same inner queue (``own``; others are kept apart by
        cell ownership and keep-clear alone). Both keep at most two robots per inner queue."""
        self._m = _model(layout)
        m = self._m
        self._rank: list[int] = m.rank.tolist()
        self._bearing: list[float] = m.bearing.tolist()
        self._intersection: list[bool] = m.intersection.tolist()
        """The model's per-cell arrays as lists: `step` reads them cell by cell every tick
        (a numpy element costs ~5x a list item)."""
        self._owner: list[str | None] = [None] * len(self._m.xy)
        self._on_departure: list[bool] = [False] * len(m.xy)
        """Cells released when their robot moves off (``cell_release="departure"``): the entry lines'
        cells that are no intersection cells (`depot_manager.config.QueueConfig.cell_release`)."""
        if cell_release == "departure":
            for name in m.entry_names:
                for c in m.line_ids[name].tolist():
                    self._on_departure[c] = not self._intersection[c]
        self._robots: dict[str, _Robot] = {}
        self._reported: dict[str, tuple[str, int]] = {}
        self._left = 0
        self._t = 0.0
        self.version = 0
        """Bumped by every change of what `snapshot` reports (cells owned, robots' places and
        routes, robots inside): a reader may keep its last snapshot while this is unchanged."""
        if m.kind == "single":
            e_in = m.xy[m.line_ids[m.entry_names[0]][-1]]
            a0 = _bearing(e_in, m.center)
            self._dock_order = sorted(
                range(len(layout.docks)),
                key=lambda k: ((layout.docks[k].angle - a0) % (2 * math.pi), k),
            )
            self._dock_index = [
                int(np.flatnonzero(m.line_ids[q] == m.dock_ids[k])[0])
                for k, q in enumerate(m.inner_names)
            ]

    # ------------------------------------------------------------------ geometry queries

    def cells(self, line: str) -> np.ndarray:
        """Cell centres of `line`, (n, 2) [m, world frame], index 0 at the line's start."""
        if line not in self._m.line_xy:
            raise ValueError(f"unknown line {line!r} (lines: {', '.join(self._m.lines)})")
        return self._m.line_xy[line].copy()

    def lines(self) -> tuple[str, ...]:
        """Entry lines, inner queues, exit lines."""
        return self._m.lines

    def dock_slots(self) -> frozenset[tuple[str, int]]:
        """Every (line, cell) that is a dock's stop (a line may reach a dock at one of its cells)."""
        m = self._m
        docks = {int(d) for d in m.dock_ids}
        return frozenset((line, i) for line in m.lines for i, c in enumerate(m.line_ids[line].tolist()) if c in docks)

    def keep_clear(self, line: str, cell: int) -> bool:
        """The cell is an intersection cell: no grant ends there (sec. IV-D)."""
        return bool(self._m.intersection[self._id(line, cell)])

    def conflict(self, a: tuple[str, int], b: tuple[str, int]) -> bool:
        """Cells a and b, each (line, cell), are the same cell or conflict: two robots may not
        own them at once."""
        i, j = self._id(*a), self._id(*b)
        return i == j or j in self._m.conflicts[i]

    def route(self, robot: str) -> tuple[tuple[str, int], ...]:
        """The robot's route as (line, cell) from its join cell's line start; for a single-queue
        robot not yet dispatched, only the entry line. Empty if the robot is not inside."""
        r = self._robots.get(robot)
        return tuple(r.labels) if r else ()

    def position(self, robot: str) -> tuple[str, int] | None:
        """The cell the robot last reported (or joined at)."""
        r = self._robots.get(robot)
        return r.labels[r.pos] if r else None

    # ------------------------------------------------------------------ reports

    def join(self, robot: str, line: str, cell: int, t: float) -> Refusal:
        """Ask to join entry line `line` at `cell`; Refusal.NONE if accepted, else why not."""
        m = self._m
        if line not in m.entry_names:
            return Refusal.UNKNOWN_LINE
        if robot in self._robots:
            return Refusal.ALREADY_INSIDE
        ids = m.line_ids[line]
        if not 0 <= cell < len(ids):
            return Refusal.UNKNOWN_CELL
        c = int(ids[cell])
        if not self._free(c, robot):
            return Refusal.OCCUPIED
        if self.behind_tail:
            owned = [i for i, cid in enumerate(ids) if self._owner[cid] is not None]
            if owned and cell >= min(owned):
                return Refusal.NOT_BEHIND_TAIL
        if m.intersection[c]:
            return Refusal.KEEP_CLEAR
        r = _Robot(robot, m.entry_names.index(line), t)
        if m.kind == "multi":
            self._set_route(r, r.entry)
        else:
            self._set_route(r, None)
        r.pos = r.end = cell
        self._owner[c] = robot
        self._robots[robot] = r
        self.version += 1
        return Refusal.NONE

    def arrived(self, robot: str, line: str, cell: int, t: float) -> None:
        """The robot reached (line, cell) of its route: release the cells behind it."""
        r = self._robots.get(robot)
        if r is None:
            raise ValueError(f"unknown robot {robot!r}: not inside the depot perimeter")
        p = r.lookup.get((line, cell))
        if p is None:
            raise ValueError(
                f"{robot}: ({line}, {cell}) is not on its route "
                f"(now at {r.labels[r.pos]}, granted up to {r.labels[r.end]})"
            )
        if p < r.pos:
            raise ValueError(
                f"{robot}: ({line}, {cell}) is behind its current cell {r.labels[r.pos]}"
            )
        if p > r.end:
            raise ValueError(f"{robot}: ({line}, {cell}) is beyond its grant {r.labels[r.end]}")
        if p == r.pos:
            return
        self.version += 1
        for c in r.route[r.pos : p]:
            if self._owner[c] == robot:  # (a cell released on departure may be the follower's already)
                self._owner[c] = None
        r.pos, r.key = p, t
        if r.complete and p == len(r.route) - 1:
            for c in r.route[p : r.end + 1]:
                self._owner[c] = None
            del self._robots[robot]
            self._reported.pop(robot, None)
            self._left += 1

    def unloaded(self, robot: str, t: float) -> None:
        """The robot's resource was dropped: it may leave its dock (when the rules allow)."""
        r = self._robots.get(robot)
        if r is None:
            raise ValueError(f"unknown robot {robot!r}: not inside the depot perimeter")
        if r.dock_pos < 0 or r.pos != r.dock_pos:
            raise ValueError(f"{robot}: unloaded while not at its dock (at {r.labels[r.pos]})")
        r.unloaded = True

    def remove(self, robot: str) -> bool:
        """Take `robot` out of the depot wherever it is (it was declared dead): every cell it
        owns, its dock and its inner queue are free again. False if it was not inside."""
        r = self._robots.pop(robot, None)
        if r is None:
            return False
        self.version += 1
        for c, owner in enumerate(self._owner):
            if owner == robot:
                self._owner[c] = None
        self._reported.pop(robot, None)
        return True

    # ------------------------------------------------------------------ grants

    def step(self, t: float) -> dict[str, tuple[str, int]]:
        """Extend grants (FCFS, ties counter-clockwise); -> robots whose grant changed since the
        last step -> (line, furthest granted cell)."""
        self._t = t
        bearing = self._bearing
        order = sorted(self._robots.values(), key=lambda r: (r.key, bearing[r.route[r.pos]], r.name))
        claims = [-1] * len(bearing)
        for r in order:
            self._advance(r, claims)
        changed = {}
        for name, r in self._robots.items():
            g = r.labels[r.end]
            if self._reported.get(name) != g:
                self._reported[name] = g
                changed[name] = g
        return changed

    def grant(self, robot: str) -> tuple[str, int] | None:
        """(line, furthest granted cell) of the robot; None if it is not inside."""
        r = self._robots.get(robot)
        return r.labels[r.end] if r else None

    def is_last(self, robot: str) -> bool:
        """The robot is on an entry line and no robot on that line is at a lower cell."""
        r = self._robots.get(robot)
        if r is None or r.pos >= r.entry_len:
            return False
        return not any(
            o.entry == r.entry and o.pos < r.pos and o.pos < o.entry_len
            for o in self._robots.values()
        )

    def last_robots(self) -> frozenset[str]:
        """The robots `is_last` says are last, for all robots at once (the server asks every
        tick): on an entry line, at the lowest cell of the robots on that line."""
        lowest: dict[int, int] = {}
        for o in self._robots.values():
            if o.pos < o.entry_len and o.pos < lowest.get(o.entry, o.pos + 1):
                lowest[o.entry] = o.pos
        return frozenset(r.name for r in self._robots.values() if r.pos < r.entry_len and r.pos == lowest[r.entry])

    @property
    def robots_inside(self) -> tuple[str, ...]:
        return tuple(sorted(self._robots))

    def entry_queue_lengths(self) -> tuple[int, ...]:
        n = [0] * len(self._m.entry_names)
        for r in self._robots.values():
            if r.pos < r.entry_len:
                n[r.entry] += 1
        return tuple(n)

    def snapshot(self) -> DepotState:
        m = self._m
        inner = [0] * len(m.inner_names)
        occupied = []
        for r in self._robots.values():
            if r.inner >= 0 and r.pos <= r.inner_end:
                inner[r.inner] += 1
            occupied.extend((*r.labels[p], r.name) for p in range(r.pos, r.end + 1))
        return DepotState(
            t=self._t,
            entry_lines=m.entry_names,
            entry_queue_lengths=self.entry_queue_lengths(),
            dock_occupants=tuple(self._owner[d] or "" for d in m.dock_ids),
            inner_queue_counts=tuple(inner),
            occupied=tuple(sorted(occupied)),
            inside=self.robots_inside,
            left=self._left,
        )

    # ------------------------------------------------------------------ internals

    def _id(self, line: str, cell: int) -> int:
        ids = self._m.line_ids.get(line)
        if ids is None:
            raise ValueError(f"unknown line {line!r} (lines: {', '.join(self._m.lines)})")
        if not 0 <= cell < len(ids):
            raise ValueError(f"{line} has cells 0..{len(ids) - 1}, not {cell}")
        return int(ids[cell])

    def _set_route(self, r: _Robot, k: int | None) -> None:
        """Route of template k (None: single-queue entry line only, before dispatch)."""
        tpl = self._m.template(k)
        self.version += 1
        r.route, r.labels, r.lookup = tpl.ids, tpl.labels, tpl.lookup
        r.entry_len, r.complete = tpl.entry_len, tpl.complete
        r.inner, r.dock_pos, r.inner_end = tpl.inner, tpl.dock_pos, tpl.inner_end

    def _free(self, c: int, robot: str) -> bool:
        own = self._owner
        o = own[c]
        if o is not None and o != robot and not self._vacated(c, o):
            return False
        for x in self._m.conflicts[c]:
            o = own[x]
            if o is not None and o != robot:
                return False
        return True

    def _vacated(self, c: int, owner: str) -> bool:
        """Cell c is its owner's current cell on an entry line, released on departure, and the owner
        holds a grant beyond it (it is moving off)."""
        if not self._on_departure[c]:
            return False
        o = self._robots[owner]
        return o.route[o.pos] == c and o.end > o.pos

    def _stoppable(self, r: _Robot, i: int) -> bool:
        return not self._intersection[r.route[i]] or (r.complete and i == len(r.route) - 1)

    def _extension(self, r: _Robot, claims: list[int]) -> int:
        """Furthest route index the robot can be granted now (r.end if none)."""
        rank = self._rank[r.route[r.pos]]
        limit = r.pos + self.lookahead
        i = best = r.end
        n = len(r.route)
        while i + 1 < n:
            if i >= limit and i == best:
                break
            if i == r.dock_pos and not r.unloaded:
                break
            c = r.route[i + 1]
            if claims[c] > rank or not self._free(c, r.name):
                break
            i += 1
            if self._stoppable(r, i):
                best = i
        return best

    def _needed_run(self, r: _Robot) -> list[int]:
        """The cells the robot needs for its next stop: the next cell, through any run of
        intersection cells to the next stoppable one."""
        out = []
        i = r.end
        while i + 1 < len(r.route):
            i += 1
            out.append(r.route[i])
            if self._stoppable(r, i):
                break
        return out

    def _claim(self, cells, rank: int, claims: list[int]) -> None:
        for c in cells:
            claims[c] = max(claims[c], rank)
            for x in self._m.conflicts[c]:
                claims[x] = max(claims[x], rank)

    def _grant_to(self, r: _Robot, end: int) -> None:
        self.version += 1
        for c in r.route[r.end + 1 : end + 1]:
            self._owner[c] = r.name
        r.end = end

    def _advance(self, r: _Robot, claims: list[int]) -> None:
        m = self._m
        if r.end - r.pos >= self.lookahead:
            return
        stopped = r.end == r.pos
        rank = self._rank[r.route[r.pos]]
        if r.end == r.dock_pos:
            if not r.unloaded:
                return
            if m.kind == "single" and not self._may_leave_dock(r):
                if stopped and self.inner_rule == "any":
                    ids = m.line_ids[m.inner_names[r.inner]]
                    self._claim(ids[self._dock_index[r.inner] + 1 :], rank, claims)
                elif stopped:
                    self._claim(self._needed_run(r), rank, claims)
                return
        end = self._extension(r, claims)
        if end > r.end:
            self._grant_to(r, end)
        elif stopped and r.end < len(r.route) - 1:
            self._claim(self._needed_run(r), rank, claims)
        if not r.complete and r.end == len(r.route) - 1:
            self._dispatch(r, claims)

    def _holds(self, c: int, r: _Robot, k: int) -> bool:
        """Another robot owns cell c of inner queue k, and counts for the inner-queue rules."""
        o = self._owner[c]
        return o is not None and o != r.name and (
            self.inner_rule == "any" or self._robots[o].inner == k
        )

    def _may_leave_dock(self, r: _Robot) -> bool:
        m = self._m
        ids = m.line_ids[m.inner_names[r.inner]]
        if any(self._holds(c, r, r.inner) for c in ids[self._dock_index[r.inner] + 1 :]):
            return False
        return self._free(int(ids[-1]), r.name)

    def _dispatch(self, r: _Robot, claims: list[int]) -> None:
        """Single queue: send a robot granted up to the inner entry point into an inner queue."""
        m = self._m
        for k in self._dock_order:
            ids = m.line_ids[m.inner_names[k]]
            d = self._dock_index[k]
            if any(self._holds(c, r, k) for c in ids[1 : d + 1]):
                continue
            if not self._free(int(ids[d]), r.name):
                continue
            pos, end = r.pos, r.end
            self._set_route(r, k)
            r.pos, r.end = pos, end
            new_end = self._extension(r, claims)
            if new_end > end:
                self._grant_to(r, new_end)
            else:
                self._set_route(r, None)
                r.pos, r.end = pos, end
            return
