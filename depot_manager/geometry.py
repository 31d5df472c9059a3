"""Queue geometry around the central depot (queue_depot_traffic.md, sections III, IV, VII).

ROS-free. Everything is in metres in the world frame; angles are radians, counter-clockwise from
+x about the depot centre. A *line* (sec. IV-A) is a `Polyline` that robots follow from its first
to its last waypoint; `Polyline.slots(pitch)` gives robot-sized waiting positions along it.

Choices the paper leaves open (its Figs. 3, 4, 6, 7 are not reproduced in the text we have):
- Docks sit on the depot boundary, K evenly spaced counter-clockwise from +x (Fig. 2). A robot
  unloads at the dock's *stop*: its centre one robot radius outside the boundary.
- Single queue (sec. IV-A, Fig. 6), as the authors built it (`single_queue_layout`): the entry
  line is concentric arcs a lane apart that leave a gap, the exit line runs out through the gap
  and crosses nothing, and each inner queue goes from the queue head along a ring lane to its
  dock, then to the inner exit point near the depot centre. Inner queues overlap on the ring.
- Multi queue (sec. IV-B, Fig. 7): sector k is the wedge of angular width 2*pi/K centred on
  dock k. Its entry line is a serpentine of concentric arcs (lanes one lane spacing apart,
  alternating direction) from the perimeter down to the dock; its exit line continues along the
  dock-level arc counter-clockwise to a radial corridor at the sector's counter-clockwise edge
  and out to the perimeter. Lines keep half a lane spacing from the sector edges, so lines of
  neighbouring sectors are a full lane spacing apart, and entry and exit never intersect.
- The multi-queue "inner region" (sec. V-B, "if we define the inner region appropriately") is
  the disc holding the dock-level arc and the innermost serpentine lane.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Literal

import numpy as np

from depot_manager.config import DockingConfig, QueueConfig
from depot_manager.docks import Dock, docks

if TYPE_CHECKING:
    from swarm_sim.scenario.schema import Scenario

ARC_STEP = 0.04
"""Maximum waypoint spacing along discretised arcs [m]; chords cut inside an arc by at most
ARC_STEP**2 / (8 r), under 0.5 mm here, which is the tolerance on every lane distance."""


@dataclass(frozen=True)
class DepotGeometryConfig:
    """Depot and queue dimensions (sec. III and Table I / sec. VII of the paper).

    A view of the scenario's `depot` and `robots` sections and the queue strategies'
    ``controller.queue`` section (`from_scenario`), which are the one place these facts live; constructing it directly is for tests and the drawing command.
    """

    depot_center: tuple[float, float] = (0.0, 0.0)
    """Centre of the depot disc [m, world frame]."""
    depot_radius: float = 0.5
    """Radius of the central depot disc (black circle, Fig. 2) [m]."""
    perimeter_radius: float = 2.0
    """Radius of the perimeter (red circle; 2 m in Table I) [m]."""
    docks: int = 4
    """Number K of docks on the depot boundary (K >= 1)."""
    lane_spacing: float = 0.20
    """Distance between adjacent lanes where a line turns (sec. VII) [m]."""
    robot_diameter: float = 0.17
    """Foot-bot diameter (sec. VII) [m]."""
    slot_pitch: float | None = None
    """Arc-length distance between queue slots along a line [m]; None = lane_spacing."""

    @classmethod
    def from_scenario(cls, scenario: Scenario) -> DepotGeometryConfig:
        d, k = scenario.depot, DockingConfig.of(scenario)
        return cls(
            depot_center=tuple(d.center), depot_radius=d.radius, perimeter_radius=k.perimeter_radius,
            docks=k.docks, lane_spacing=QueueConfig.of(scenario).lane_spacing,
            robot_diameter=scenario.robots.diameter, slot_pitch=QueueConfig.of(scenario).slot_pitch,
        )

    @property
    def pitch(self) -> float:
        """Effective slot pitch [m]."""
        return self.lane_spacing if self.slot_pitch is None else self.slot_pitch

    @property
    def center(self) -> np.ndarray:
        return np.asarray(self.depot_center, dtype=float)

    @property
    def dock_stop_radius(self) -> float:
        """Distance from the depot centre of a robot's centre at a dock [m]."""
        return self.depot_radius + self.robot_diameter / 2.0

    def validate(self) -> None:
        """Raise ValueError naming the first parameter that makes any layout impossible."""
        if self.docks < 1:
            raise ValueError(f"docks must be >= 1, got {self.docks}")
        if self.depot_radius <= 0:
            raise ValueError(f"depot_radius must be > 0, got {self.depot_radius}")
        if self.robot_diameter <= 0:
            raise ValueError(f"robot_diameter must be > 0, got {self.robot_diameter}")
        if self.lane_spacing < self.robot_diameter:
            raise ValueError(
                f"lane_spacing {self.lane_spacing} m is below robot_diameter "
                f"{self.robot_diameter} m: robots on adjacent lanes would collide"
            )
        if self.pitch < self.robot_diameter:
            raise ValueError(
                f"slot_pitch {self.pitch} m is below robot_diameter {self.robot_diameter} m"
            )
        if self.perimeter_radius <= self.depot_radius:
            raise ValueError(
                f"perimeter_radius {self.perimeter_radius} m must exceed depot_radius "
                f"{self.depot_radius} m"
            )
        # Dock stops must not overlap each other.
        if self.docks > 1:
            gap = 2 * self.dock_stop_radius * math.sin(math.pi / self.docks)
            if gap < self.lane_spacing:
                raise ValueError(
                    f"docks={self.docks} too many for depot_radius {self.depot_radius} m: "
                    f"dock stops {gap:.3f} m apart < lane_spacing {self.lane_spacing} m"
                )


@dataclass(frozen=True, eq=False)
class Polyline:
    """A line (sec. IV-A): a path robots follow from `points[0]` to `points[-1]`."""

    name: str
    points: np.ndarray
    """(n, 2) waypoints [m, world frame]."""

    def __post_init__(self) -> None:
        pts = np.asarray(self.points, dtype=float)
        if pts.ndim != 2 or pts.shape[1] != 2 or len(pts) < 2:
            raise ValueError(f"line {self.name}: need (n>=2, 2) points, got {pts.shape}")
        pts.setflags(write=False)
        object.__setattr__(self, "points", pts)

    @property
    def cumulative(self) -> np.ndarray:
        """Arc length at each waypoint [m]."""
        seg = np.linalg.norm(np.diff(self.points, axis=0), axis=1)
        return np.concatenate([[0.0], np.cumsum(seg)])

    @property
    def length(self) -> float:
        return float(self.cumulative[-1])

    @property
    def start(self) -> np.ndarray:
        return self.points[0]

    @property
    def end(self) -> np.ndarray:
        return self.points[-1]

    def point_at(self, s: np.ndarray | float) -> np.ndarray:
        """Point(s) at arc length s from the start (clipped to the line) [m, world frame]."""
        cum = self.cumulative
        s_arr = np.clip(np.atleast_1d(np.asarray(s, dtype=float)), 0.0, cum[-1])
        x = np.interp(s_arr, cum, self.points[:, 0])
        y = np.interp(s_arr, cum, self.points[:, 1])
        out = np.stack([x, y], axis=1)
        return out[0] if np.ndim(s) == 0 else out

    def slots(self, pitch: float) -> np.ndarray:
        """Slot centres from the start, each exactly `pitch` metres (straight line) after the
        previous one along the line, (m, 2) [m].

        Straight-line rather than arc-length spacing, so neighbours are one pitch apart even
        across a corner or a lane turn, where arc-length spacing would crowd them.
        """
        return self.point_at(self.slot_arclengths(pitch))

    def slot_arclengths(self, pitch: float) -> np.ndarray:
        """Arc lengths of the slots of `slots(pitch)` [m]."""
        if pitch <= 0:
            raise ValueError(f"pitch must be > 0, got {pitch}")
        # Between consecutive samples the line is straight (samples include every waypoint),
        # so the slot is where that segment meets the circle of radius `pitch` around `cur`.
        grid, pts = self.sample(pitch / 10.0)
        out = [0.0]
        i, cur = 0, pts[0]
        while True:
            d = np.linalg.norm(pts[i + 1 :] - cur, axis=1)
            ahead = np.nonzero(d >= pitch)[0]
            if len(ahead) == 0:
                break
            j = i + 1 + int(ahead[0])
            p0, v = pts[j - 1], pts[j] - pts[j - 1]
            w = p0 - cur
            a, b, c = v @ v, 2 * (v @ w), w @ w - pitch * pitch
            t = (-b + math.sqrt(max(b * b - 4 * a * c, 0.0))) / (2 * a)
            t = min(max(t, 0.0), 1.0)
            out.append(grid[j - 1] + t * (grid[j] - grid[j - 1]))
            cur = p0 + t * v
            i = j - 1
        return np.array(out)

    def sample(self, step: float) -> tuple[np.ndarray, np.ndarray]:
        """(arc lengths, points) at most `step` apart, including every waypoint."""
        cum = self.cumulative
        n = np.maximum(1, np.ceil(np.diff(cum) / step).astype(int))
        seg = np.repeat(np.arange(len(n)), n)
        frac = (np.arange(n.sum()) - np.repeat(np.cumsum(n) - n, n) + 1) / np.repeat(n, n)
        s = np.concatenate([[0.0], cum[seg] + frac * np.diff(cum)[seg]])
        return s, self.point_at(s)


def segment_intersections(a: np.ndarray, b: np.ndarray, eps: float = 1e-12) -> np.ndarray:
    """Proper intersection points between polylines `a` (n,2) and `b` (m,2), as (k, 2)."""
    p, r = a[:-1][:, None, :], np.diff(a, axis=0)[:, None, :]
    q, s = b[:-1][None, :, :], np.diff(b, axis=0)[None, :, :]
    rxs = r[..., 0] * s[..., 1] - r[..., 1] * s[..., 0]
    qp = q - p
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (qp[..., 0] * s[..., 1] - qp[..., 1] * s[..., 0]) / rxs
        u = (qp[..., 0] * r[..., 1] - qp[..., 1] * r[..., 0]) / rxs
    hit = (np.abs(rxs) > eps) & (t >= 0) & (t <= 1) & (u >= 0) & (u <= 1)
    i, j = np.nonzero(hit)
    pts = a[:-1][i] + t[i, j][:, None] * np.diff(a, axis=0)[i]
    if len(pts) == 0:
        return np.zeros((0, 2))
    # Merge duplicates where a crossing falls on a shared waypoint.
    keep: list[np.ndarray] = []
    for pt in pts:
        if all(np.linalg.norm(pt - k) > 1e-9 for k in keep):
            keep.append(pt)
    return np.array(keep)


@dataclass(frozen=True, eq=False)
class Crossing:
    """Where two lines intersect (sec. IV-D: FCFS, ties counter-clockwise)."""

    line_a: str
    line_b: str
    point: np.ndarray
    """[m, world frame]"""


@dataclass(frozen=True, eq=False)
class QueueLayout:
    """A queue wrapping layout (sec. IV): single spiral (Fig. 3/6) or multi serpentine (4/7)."""

    kind: Literal["single", "multi"]
    config: DepotGeometryConfig
    docks: tuple[Dock, ...]
    inner_radius: float
    """Radius of the inner region (purple circle, Fig. 3) [m]."""
    entry_lines: tuple[Polyline, ...]
    """Single: one spiral; multi: one per sector, index = dock index."""
    exit_lines: tuple[Polyline, ...]
    inner_queues: tuple[Polyline, ...] = ()
    """Single only: inner entry point -> dock k -> inner exit point, index = dock index."""
    sectors: tuple[tuple[float, float], ...] = ()
    """Multi only: (start, end) bearing of sector k, CCW, end - start = 2*pi/K [rad]."""
    crossings: tuple[Crossing, ...] = field(default=())

    @property
    def entry_points(self) -> np.ndarray:
        """Entry points on the perimeter (black dots), (n, 2) [m]."""
        return np.array([ln.start for ln in self.entry_lines])

    @property
    def exit_points(self) -> np.ndarray:
        """Exit points on the perimeter (blue dots), (n, 2) [m]."""
        return np.array([ln.end for ln in self.exit_lines])

    @property
    def inner_entry_point(self) -> np.ndarray | None:
        return self.inner_queues[0].start if self.inner_queues else None

    @property
    def inner_exit_point(self) -> np.ndarray | None:
        return self.inner_queues[0].end if self.inner_queues else None

    def lines(self) -> tuple[Polyline, ...]:
        return self.entry_lines + self.exit_lines + self.inner_queues

    def entry_slots(self) -> list[np.ndarray]:
        """Waiting slots on each entry line, from its entry point towards the dock(s)."""
        return [ln.slots(self.config.pitch) for ln in self.entry_lines]

    @property
    def capacity(self) -> int:
        """Robots that can wait on the entry lines plus two per inner queue (sec. IV-A)."""
        return sum(len(s) for s in self.entry_slots()) + 2 * len(self.inner_queues)


# ---------------------------------------------------------------------------------------------
# helpers


def _polar(cfg: DepotGeometryConfig, r: np.ndarray | float, phi: np.ndarray | float) -> np.ndarray:
    r_a, phi_a = np.broadcast_arrays(np.asarray(r, float), np.asarray(phi, float))
    pts = np.stack([r_a * np.cos(phi_a), r_a * np.sin(phi_a)], axis=-1)
    return pts + cfg.center


def _arc(cfg: DepotGeometryConfig, r: float, phi0: float, phi1: float) -> np.ndarray:
    """Waypoints on the circle of radius r from bearing phi0 to phi1 (either direction)."""
    n = max(1, int(math.ceil(abs(phi1 - phi0) * r / ARC_STEP)))
    return _polar(cfg, r, np.linspace(phi0, phi1, n + 1))


def _join(*parts: np.ndarray) -> np.ndarray:
    """Concatenate waypoint arrays, dropping repeated junction points."""
    out = [np.atleast_2d(parts[0])]
    for p in parts[1:]:
        p = np.atleast_2d(p)
        if np.linalg.norm(p[0] - out[-1][-1]) < 1e-12:
            p = p[1:]
        out.append(p)
    return np.concatenate(out)


def make_docks(cfg: DepotGeometryConfig) -> tuple[Dock, ...]:
    """K docks evenly spaced on the depot boundary, CCW from +x (Fig. 2): the scenario's sites."""
    return docks(cfg.depot_center, cfg.depot_radius, cfg.robot_diameter, cfg.docks)


# ---------------------------------------------------------------------------------------------
# single queue (sec. IV-A, Figs. 3 and 6)


def single_queue_layout(cfg: DepotGeometryConfig | None = None) -> QueueLayout:
    """One entry line of concentric arcs that leave a gap, one exit line out through the gap, and
    one short inner queue per dock (sec. IV-A, as the authors built it).

    The authors' single queue (Tameem786/Collision_Free_CPFA, ``CPFA_loop_functions::
    SetSpiralPathCoordinates``): six concentric arcs 0.2 m apart inside the red circle, each
    turning back on itself (alternate arcs run in opposite directions) and stopping short of a
    20 deg gap, joined by short inward steps; from the queue head at the end of the innermost
    arc a short path to each nest (``SetNestsPredefinedEntryPathCoordinates``) that a robot is
    sent down only while no other robot holds it (``GetAvailablePathToNest``,
    ``AddRobotToPathQueueToNest``; freed once the robot has left its nest), and exit paths from
    the nests out along the gap's bisector (``SetNestsPredefinedExitPathCoordinates``), so no
    exit crosses the entry line. Ours, on our docks:

    - Gap bisector: the bearing halfway between docks 0 and 1 (pi / K; the authors' 45 deg).
      Every arc ends where it is one lane spacing off the bisector, so the exit line (radial
      along the bisector) is a lane clear of the entry line everywhere.
    - Arcs from half a lane inside the perimeter down to one lane outside the ring (below),
      a lane apart; the innermost runs clockwise and ends at the gap's counter-clockwise side:
      that end is the inner entry point (the queue head). The entry point is on the perimeter
      half a dock spacing (pi / K) beyond the gap, where the outermost arc begins (the authors'
      entry at 90 deg, 45 deg from their gap).
    - Inner queue k: from the head a lane inwards to the ring (one lane outside the dock
      stops), counter-clockwise along it (away from the gap) to dock k's V, down to the dock
      stop, then straight to the inner exit point, a lane out from the depot centre on the
      bisector. The ring never reaches the gap, so the exit line crosses no inner queue; the
      inner queues' last legs meet only at the inner exit point (FCFS there, sec. IV-D).
    """
    cfg = cfg or DepotGeometryConfig()
    cfg.validate()
    lane, K = cfg.lane_spacing, cfg.docks
    r_stop = cfg.dock_stop_radius
    r_ring = r_stop + lane  # inner-region lane, one lane outside docked robots
    r_inner = r_ring + lane / 2  # purple circle
    r_end = r_inner + lane / 2  # innermost arc, one lane outside the ring
    r_top = cfg.perimeter_radius - lane / 2  # outermost arc, half a lane inside the perimeter
    n_arcs = int(math.floor((r_top - r_end) / lane + 1e-9)) + 1
    if r_top < r_end:
        raise ValueError(
            f"perimeter_radius {cfg.perimeter_radius} m too small for even one queue arc: "
            f"need >= {r_end + lane / 2:.3f} m with depot_radius {cfg.depot_radius} m and "
            f"lane_spacing {lane} m"
        )
    bisector = math.pi / K

    def off(r: float) -> float:
        """Bearing offset putting a point at radius r one lane off the bisector."""
        return math.asin(min(1.0, lane / r))

    def ccw_side(r: float) -> float:
        return bisector + off(r)

    def cw_side(r: float) -> float:
        return bisector - off(r) + 2 * math.pi

    alpha = lane / r_ring  # half-width of a dock's V on the ring [rad]
    ring_start = ccw_side(r_ring)
    angles = []
    for d in make_docks(cfg):
        th = d.angle
        while th - alpha <= ring_start:
            th += 2 * math.pi
        angles.append(th)
    if K > 1 and (max(angles) + alpha > cw_side(r_ring) or min(angles) - alpha - ring_start < lane / (2 * r_ring)
                  or r_stop * math.sin(bisector) < lane):
        raise ValueError(
            f"docks={K} too many for depot_radius {cfg.depot_radius} m with lane_spacing "
            f"{lane} m: dock approaches and the exit gap do not fit on the ring"
        )

    # Entry line: arcs from the outermost inwards; arc j (0 = innermost) runs clockwise when j
    # is even, so the innermost ends on the gap's counter-clockwise side.
    # The entry point is half a dock spacing beyond the gap (the authors' entry at 90 deg, the
    # gap at 45 deg), so robots coming in keep clear of robots going out.
    radii = [r_end + j * lane for j in range(n_arcs)]
    top = n_arcs - 1
    enter = bisector - math.pi / K + 2 * math.pi if top % 2 == 0 else bisector + math.pi / K
    parts = [_polar(cfg, cfg.perimeter_radius, enter)]
    for j in range(top, -1, -1):
        r = radii[j]
        if j % 2 == 0:
            parts.append(_arc(cfg, r, enter if j == top else cw_side(r), ccw_side(r)))
        else:
            parts.append(_arc(cfg, r, enter if j == top else ccw_side(r), cw_side(r)))
    entry = Polyline("entry_line", _join(*parts))
    e_in = entry.end
    x_in = _polar(cfg, lane, bisector)

    inner = []
    for d, th in zip(make_docks(cfg), angles):
        pts = _join(e_in, _arc(cfg, r_ring, ring_start, th - alpha), d.stop, x_in)
        inner.append(Polyline(f"inner_queue_{d.index}", pts))
    exit_line = Polyline("exit_line", _join(x_in, _polar(cfg, cfg.perimeter_radius, bisector)))
    crossings = tuple(
        Crossing(entry.name, exit_line.name, p)
        for p in segment_intersections(entry.points, exit_line.points)
    )
    return QueueLayout(
        kind="single",
        config=cfg,
        docks=make_docks(cfg),
        inner_radius=r_inner,
        entry_lines=(entry,),
        exit_lines=(exit_line,),
        inner_queues=tuple(inner),
        crossings=crossings,
    )


# ---------------------------------------------------------------------------------------------
# multi queue (sec. IV-B, Figs. 4 and 7)


def multi_queue_layout(cfg: DepotGeometryConfig | None = None) -> QueueLayout:
    """K sectors, each with a serpentine entry line, its dock and a short exit line (IV-B)."""
    cfg = cfg or DepotGeometryConfig()
    cfg.validate()
    lane, K = cfg.lane_spacing, cfg.docks
    r_stop = cfg.dock_stop_radius
    r_top = cfg.perimeter_radius - lane / 2
    n_lanes = int(math.floor((r_top - r_stop) / lane + 1e-9))  # serpentine lanes above the dock
    if n_lanes < 1:
        raise ValueError(
            f"perimeter_radius {cfg.perimeter_radius} m too small for even one lane above the "
            f"docks: need >= {r_stop + 1.5 * lane:.3f} m with depot_radius {cfg.depot_radius} m"
        )
    half = math.pi / K

    def edge(r: float, clearance: float) -> float:
        """Angular offset keeping a point at radius r `clearance` metres off a radial line."""
        return math.asin(min(1.0, clearance / r))

    docks = make_docks(cfg)
    entries, exits, sectors = [], [], []
    for d in docks:
        a, b = d.angle - half, d.angle + half
        c = b - edge(r_stop, lane / 2)  # exit corridor bearing, half a lane inside the edge
        lo = lambda r: a + edge(r, lane / 2)  # noqa: E731 - CW end of lanes at radius r
        hi = lambda r: c - edge(r, lane)  # noqa: E731 - CCW end, a lane clear of the corridor
        r1 = r_stop + lane
        if K > 1 and (
            r1 * (hi(r1) - lo(r1)) < lane
            or d.angle - lo(r_stop) <= 0
            or c - d.angle < lane / r_stop
        ):
            raise ValueError(
                f"docks={K} too many for depot_radius {cfg.depot_radius} m with lane_spacing "
                f"{lane} m: a sector is too narrow for a serpentine and an exit corridor"
            )
        radii = [r_stop + j * lane for j in range(n_lanes + 1)]
        parts: list[np.ndarray] = []
        top = n_lanes
        start_phi = lo(radii[top]) if top % 2 == 0 else hi(radii[top])
        parts.append(_polar(cfg, cfg.perimeter_radius, start_phi))
        for j in range(top, 0, -1):
            r = radii[j]
            if j % 2 == 0:  # CCW lane
                parts.append(_arc(cfg, r, lo(r), hi(r)))
            else:  # CW lane
                parts.append(_arc(cfg, r, hi(r), lo(r)))
        parts.append(_arc(cfg, r_stop, lo(r_stop), d.angle))  # dock lane (CCW) up to the dock
        entries.append(Polyline(f"entry_line_{d.index}", _join(*parts)))
        exits.append(
            Polyline(
                f"exit_line_{d.index}",
                _join(_arc(cfg, r_stop, d.angle, c), _polar(cfg, cfg.perimeter_radius, c)),
            )
        )
        sectors.append((a, b))
    return QueueLayout(
        kind="multi",
        config=cfg,
        docks=docks,
        inner_radius=r_stop + 1.5 * lane,
        entry_lines=tuple(entries),
        exit_lines=tuple(exits),
        sectors=tuple(sectors),
    )


def make_layout(
    kind: Literal["single", "multi"], cfg: DepotGeometryConfig | None = None
) -> QueueLayout:
    """Layout by name: `single` (Q_SE, Q_ST) or `multi` (Q_ME, Q_MT)."""
    if kind == "single":
        return single_queue_layout(cfg)
    if kind == "multi":
        return multi_queue_layout(cfg)
    raise ValueError(f"layout kind must be 'single' or 'multi', got {kind!r}")


def check_queue(scenario: Scenario) -> None:
    """The queue strategies' check (`swarm_controllers.queue.registration`; ValueError naming the
    parameter): the searchers' give-up time and the brake patience are positive, the entry reach
    within half a cell, and the queue layout fits the depot."""
    q = QueueConfig.of(scenario)
    for key in ("seek_timeout", "brake_patience"):
        if not getattr(q, key) > 0:
            raise ValueError(f"controller.queue.{key}: must be positive")
    if not 0 < q.entry_reach <= (q.lane_spacing if q.slot_pitch is None else q.slot_pitch) / 2:
        raise ValueError("controller.queue.entry_reach: must be positive and at most half the slot pitch")
    try:
        geometry = DepotGeometryConfig.from_scenario(scenario)
        geometry.validate()
        make_layout(q.wrapping, geometry)
    except ValueError as exc:
        raise ValueError(f"controller.queue: {exc}") from None
