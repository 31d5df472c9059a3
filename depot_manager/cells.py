"""The cell model of a queue layout: robot-sized cells along every line, which cells
conflict (too close, or swept by a robot driving between two others), which are keep-clear
(intersections), and each dock's route through them. Immutable and built once per layout
object; `depot_manager.admission` (the FCFS authority) grants runs of these cells. The rules
they implement are set out in the admission module's docstring.
"""

from __future__ import annotations

import heapq
import math
import weakref
from dataclasses import dataclass

import numpy as np

from depot_manager.geometry import ARC_STEP, Polyline, QueueLayout

SAME_POINT = 1e-6
"""Two cells closer than this [m] are the same point (aliases at line junctions)."""
TOL = 1e-6
"""Distance comparisons [m] are strict by this margin (slots are exactly one pitch apart)."""
LINE_TOL = 1e-3
"""Cells lie on their line to within the arc discretisation (geometry.ARC_STEP) [m]."""
SWEEP_STEP = 0.01
"""Sampling step along a line between two cells when looking for swept conflicts [m]."""


def line_cells(points: np.ndarray | Polyline, pitch: float, min_gap: float) -> np.ndarray:
    """Slots of a line every `pitch` [m] from its start, ending exactly at its end: trailing
    slots closer than `min_gap` to the end are dropped and the end appended, (n, 2) [m]."""
    line = points if isinstance(points, Polyline) else Polyline("_", np.asarray(points, float))
    s = line.slots(pitch)
    end = line.end
    keep = len(s)
    while keep > 1 and np.linalg.norm(s[keep - 1] - end) < min_gap:
        keep -= 1
    return np.concatenate([s[:keep], end[None, :]])


def _project(line: Polyline, pts: np.ndarray) -> np.ndarray:
    """Arc length [m] of the point of `line` nearest to each of `pts`, searched forwards from
    the previous one (cells lie on their line, in order)."""
    a, b = line.points[:-1], line.points[1:]
    v = b - a
    vv = np.maximum((v * v).sum(axis=1), 1e-18)
    cum = line.cumulative
    out = []
    lo = 0
    for p in pts:
        t = np.clip(((p - a) * v).sum(axis=1) / vv, 0.0, 1.0)
        d = np.linalg.norm(a + t[:, None] * v - p, axis=1)
        d[:lo] = np.inf
        j = int(np.argmin(d))
        lo = j
        out.append(cum[j] + t[j] * math.sqrt(vv[j]))
    return np.array(out)


def _bearing(p: np.ndarray, c: np.ndarray) -> float:
    return math.atan2(p[1] - c[1], p[0] - c[0]) % (2 * math.pi)


class _Model:
    """The immutable cell model of one layout (built once per layout object)."""

    def __init__(self, layout: QueueLayout) -> None:
        cfg = layout.config
        self.kind = layout.kind
        self.center = cfg.center
        pitch, diam = cfg.pitch, cfg.robot_diameter
        self._xy: list[np.ndarray] = []
        self.line_ids: dict[str, np.ndarray] = {}

        def add(p: np.ndarray) -> int:
            self._xy.append(np.asarray(p, float))
            return len(self._xy) - 1

        def new_ids(pts: np.ndarray) -> list[int]:
            return [add(p) for p in pts]

        def same(a: np.ndarray, b: np.ndarray, what: str) -> None:
            if np.linalg.norm(np.asarray(a) - np.asarray(b)) > SAME_POINT:
                raise ValueError(f"layout {layout.kind}: {what} do not meet ({a} vs {b})")

        self.entry_names = tuple(ln.name for ln in layout.entry_lines)
        self.exit_names = tuple(ln.name for ln in layout.exit_lines)
        self.inner_names = tuple(ln.name for ln in layout.inner_queues)
        self.dock_ids: list[int] = []
        # route templates: list of (line name, first index used) segments
        self.routes: list[tuple[tuple[str, int], ...]] = []

        if layout.kind == "multi":
            if len(layout.entry_lines) != len(layout.exit_lines) or len(layout.docks) != len(
                layout.entry_lines
            ):
                raise ValueError("multi layout: need one entry line, exit line and dock each")
            for k, (en, ex) in enumerate(zip(layout.entry_lines, layout.exit_lines)):
                e = line_cells(en, pitch, diam)
                same(e[-1], layout.docks[k].stop, f"{en.name} and dock {k}")
                e[-1] = layout.docks[k].stop
                ids_e = new_ids(e)
                x = line_cells(ex, pitch, diam)
                same(x[0], e[-1], f"{en.name} and {ex.name}")
                self.line_ids[en.name] = np.array(ids_e)
                self.line_ids[ex.name] = np.array([ids_e[-1]] + new_ids(x[1:]))
                self.dock_ids.append(ids_e[-1])
                self.routes.append(((en.name, 0), (ex.name, 1)))
        elif layout.kind == "single":
            self._build_single(layout, pitch, diam, add, new_ids, same)
        else:
            raise ValueError(f"unknown layout kind {layout.kind!r}")

        self.xy = np.array(self._xy)
        del self._xy
        self._templates: dict[int | None, _Route] = {}
        n = len(self.xy)
        self.lines = self.entry_names + self.inner_names + self.exit_names
        self.line_xy = {ln: self.xy[ids] for ln, ids in self.line_ids.items()}
        self.bearing = np.array([_bearing(p, self.center) for p in self.xy])

        # conflicts
        adjacent = set()
        for ids in self.line_ids.values():
            for a, b in zip(ids[:-1], ids[1:]):
                adjacent.add((int(a), int(b)))
                adjacent.add((int(b), int(a)))
        thr = (cfg.robot_diameter + cfg.lane_spacing) / 2.0
        d = np.linalg.norm(self.xy[:, None, :] - self.xy[None, :, :], axis=2)
        conflicts: list[list[int]] = [[] for _ in range(n)]
        for i, j in zip(*np.nonzero(d < thr - TOL)):
            i, j = int(i), int(j)
            if i == j:
                continue
            limit = diam if (i, j) in adjacent else thr
            if d[i, j] < limit - TOL:
                conflicts[i].append(j)
        docks = set(self.dock_ids)
        for c, a, b in sorted(self._sweep_hits(layout, diam)):
            if a in conflicts[c] or b in conflicts[c]:
                continue
            x = a if b in docks else b  # the mover owns both ends; docks must stay clear
            conflicts[c].append(x)
            conflicts[x].append(c)
        self.conflicts = tuple(tuple(sorted(c)) for c in conflicts)
        self.intersection = np.array([len(c) > 0 for c in self.conflicts])

        # route graph: topological order (strictly increasing along every route)
        succ: list[set[int]] = [set() for _ in range(n)]
        for k in range(len(self.routes)):
            r = self.route_ids(k)
            for a, b in zip(r[:-1], r[1:]):
                succ[a].add(b)
        indeg = [0] * n
        for s in succ:
            for b in s:
                indeg[b] += 1
        heap = [i for i in range(n) if indeg[i] == 0]
        heapq.heapify(heap)
        order = []
        while heap:
            i = heapq.heappop(heap)
            order.append(i)
            for b in sorted(succ[i]):
                indeg[b] -= 1
                if indeg[b] == 0:
                    heapq.heappush(heap, b)
        if len(order) != n:
            raise ValueError(f"layout {layout.kind}: the route graph has a cycle")
        self.rank = np.empty(n, dtype=int)
        self.rank[order] = np.arange(n)

        # places where robots must be able to stop
        for k, dock in enumerate(self.dock_ids):
            if self.intersection[dock]:
                raise ValueError(f"dock {k} conflicts with another line's cells")
        if self.kind == "single" and self.intersection[self.line_ids[self.entry_names[0]][-1]]:
            raise ValueError("the inner entry point conflicts with another line's cells")

    def _build_single(self, layout, pitch, diam, add, new_ids, same) -> None:
        """Entry line -> inner queue k (ring, V to dock k, leg to the inner exit point) -> exit
        line (`depot_manager.geometry.single_queue_layout`)."""
        (en,), (ex,) = layout.entry_lines, layout.exit_lines
        inner = layout.inner_queues
        if len(inner) != len(layout.docks) or not inner:
            raise ValueError("single layout: need one inner queue per dock")
        c = layout.config.center
        e = line_cells(en, pitch, diam)
        e_in, x_in = inner[0].start, inner[0].end
        same(e[-1], e_in, f"{en.name} and the inner entry point")
        ids_e = new_ids(e)
        self.line_ids[en.name] = np.array(ids_e)
        id_x_in = add(x_in)

        # ring grid: inner entry point -> ring (CCW) as far as the farthest dock's V, shared by
        # every inner queue
        q0 = inner[0].points
        r_ring = float(np.linalg.norm(q0[1] - c))
        phi0 = math.atan2(q0[1][1] - c[1], q0[1][0] - c[0])
        ang = lambda p: phi0 + (_bearing(p, c) - phi0) % (2 * math.pi)  # noqa: E731
        docks_at = []
        for k, (q, dock) in enumerate(zip(inner, layout.docks)):
            v = int(np.argmin(np.linalg.norm(q.points - dock.stop, axis=1)))
            same(q.points[v], dock.stop, f"{q.name} and dock {k}")
            if not 1 < v < len(q.points) - 1:
                raise ValueError(f"{q.name}: dock {k} is not inside the inner queue")
            docks_at.append(v)
        phi1 = max(ang(q.points[v - 1]) for q, v in zip(inner, docks_at))
        m = max(1, math.ceil((phi1 - phi0) * r_ring / ARC_STEP))
        phi = np.linspace(phi0, phi1, m + 1)
        arc = c + r_ring * np.stack([np.cos(phi), np.sin(phi)], axis=1)
        grid = line_cells(np.vstack([e_in, arc]), pitch, diam)
        ids_g = [ids_e[-1]] + new_ids(grid[1:])
        g_ang = np.unwrap([phi0] + [math.atan2(*(p - c)[::-1]) for p in grid[1:]])

        for k, (q, dock, v) in enumerate(zip(inner, layout.docks, docks_at)):
            pts = q.points
            ia = int(np.nonzero(g_ang <= ang(pts[v - 1]) + 1e-9)[0][-1])
            down = [grid[ia]] + [p for p in pts[1:v] if ang(p) > g_ang[ia] + 1e-12] + [dock.stop]
            down_c = line_cells(np.array(down), pitch, diam)
            leg_c = line_cells(np.array(pts[v:]), pitch, diam)
            same(leg_c[-1], x_in, f"{q.name} and the inner exit point")
            dock_id = add(dock.stop)
            ids = ids_g[: ia + 1] + new_ids(down_c[1:-1]) + [dock_id] + new_ids(leg_c[1:-1]) + [id_x_in]
            self.line_ids[q.name] = np.array(ids)
            self.dock_ids.append(dock_id)
            self.routes.append(((en.name, 0), (q.name, 1), (ex.name, 1)))

        x = line_cells(ex, pitch, diam)
        same(x[0], x_in, f"{ex.name} and the inner exit point")
        self.line_ids[ex.name] = np.array([id_x_in] + new_ids(x[1:]))

    def _sweep_hits(self, layout: QueueLayout, diam: float) -> set[tuple[int, int, int]]:
        """(c, a, b): a robot driving along a line from cell a to the next cell b passes within a
        robot diameter of cell c (e.g. leaving a dock up its V, next to a ring cell)."""
        polys = {ln.name: ln for ln in layout.lines()}
        hits: set[tuple[int, int, int]] = set()
        for name, ids in self.line_ids.items():
            poly = polys[name]
            s = _project(poly, self.xy[ids])
            n = np.maximum(2, np.ceil(np.diff(s) / SWEEP_STEP).astype(int) + 1)
            seg = np.repeat(np.arange(len(n)), n)
            frac = (np.arange(n.sum()) - np.repeat(np.cumsum(n) - n, n)) / np.repeat(n - 1, n)
            pts = poly.point_at(s[seg] + frac * np.diff(s)[seg])
            # a, b and their neighbours on this line are not swept past
            near = ids[np.clip(seg[:, None] + np.arange(-1, 3), 0, len(ids) - 1)]
            for lo in range(0, len(pts), 1024):
                blk = slice(lo, lo + 1024)
                diff = pts[blk, None, :] - self.xy[None, :, :]
                d2 = (diff * diff).sum(axis=2)
                d2[np.arange(len(d2))[:, None], near[blk]] = np.inf
                for k, c in zip(*np.nonzero(d2 < (diam - LINE_TOL) ** 2)):
                    j = seg[lo + k]
                    hits.add((int(c), int(ids[j]), int(ids[j + 1])))
        return hits

    def template(self, k: int | None) -> _Route:
        """The route of template k (None: the single-queue entry line alone), cached."""
        tpl = self._templates.get(k)
        if tpl is None:
            tpl = self._templates[k] = _Route.build(self, k)
        return tpl

    def route_ids(self, k: int) -> tuple[int, ...]:
        return self.template(k).ids


@dataclass(frozen=True, eq=False)
class _Route:
    """A robot's route: physical cell ids, their (line, cell) names, and route index by name
    (aliases included)."""

    ids: tuple[int, ...]
    labels: tuple[tuple[str, int], ...]
    lookup: dict[tuple[str, int], int]
    entry_len: int
    """Cells of its entry line (the first entry_len route cells)."""
    complete: bool
    """False for a single-queue robot not yet dispatched (entry line only)."""
    inner: int = -1
    dock_pos: int = -1
    inner_end: int = -1
    """Route index of the inner exit point (single)."""

    @classmethod
    def build(cls, m: _Model, k: int | None) -> _Route:
        segments = m.routes[k] if k is not None else ((m.entry_names[0], 0),)
        ids: list[int] = []
        labels: list[tuple[str, int]] = []
        lookup: dict[tuple[str, int], int] = {}
        for line, first in segments:
            line_ids = m.line_ids[line]
            if first == 1:
                lookup[(line, 0)] = len(ids) - 1  # alias of the previous line's last cell
            for i in range(first, len(line_ids)):
                lookup[(line, i)] = len(ids)
                ids.append(int(line_ids[i]))
                labels.append((line, i))
        entry_len = len(m.line_ids[segments[0][0]])
        if k is None:
            return cls(tuple(ids), tuple(labels), lookup, entry_len, False)
        inner = k if m.kind == "single" else -1
        inner_end = entry_len - 2 + len(m.line_ids[m.inner_names[k]]) if inner >= 0 else -1
        return cls(tuple(ids), tuple(labels), lookup, entry_len, True, inner,
                   ids.index(m.dock_ids[k]), inner_end)


_MODELS: weakref.WeakKeyDictionary[QueueLayout, _Model] = weakref.WeakKeyDictionary()


def _model(layout: QueueLayout) -> _Model:
    m = _MODELS.get(layout)
    if m is None:
        m = _MODELS[layout] = _Model(layout)
    return m
