"""Square spiral search paths of DDSA and MDBSA (Lu & Luna, CRV 2023; ../shared/papers/mdbsa_spiral_search.md).

ROS-free planning core. Every point is [m, world frame]; leg lengths are integers in units of the
gap g between adjacent spiral lines (0.18 m in the paper, for a 0.13 m detection radius).

Conventions shared by DDSA and MDBSA (the paper's text, Sec. III):
- one circuit c = 1, 2, ... is four legs north, east, south, west, in that order, so the robot
  turns clockwise (north = +y, east = +x of the world frame);
- leg lengths come from eqs. (1)-(2) (DDSA, robot i of r) or (4)-(5) (MDBSA, one spiral per region).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from swarm_controllers.spiral.regions import region_centers  # noqa: F401 - re-exported: the planners' region grid

DEFAULT_GAP = 0.18
"""Distance g between adjacent spiral lines [m] (paper Sec. IV)."""

# Unit vectors north, east, south, west: the clockwise leg order of one circuit.
_HEADINGS = np.array([[0.0, 1.0], [1.0, 0.0], [0.0, -1.0], [-1.0, 0.0]])
_EPS = 1e-9


# --------------------------------------------------------------------------------------------
# Leg lengths
# --------------------------------------------------------------------------------------------


def ddsa_leg_steps(r: int, i: int, c: int) -> tuple[int, int, int, int]:
    """(N, E, S, W) step counts of robot i (1..r) on circuit c (>= 1), eqs. (1)-(2).

    F^N = F^E = i (c = 1), (2c-3) r + 2i (c > 1);  F^S = F^W = 2i (c = 1), F^N + r (c > 1).
    Robot ids are 1-based as in the paper: i = 0 would give zero-length first legs.
    """
    if r < 1 or not 1 <= i <= r:
        raise ValueError(f"need 1 <= i <= r, got r={r}, i={i}")
    if c < 1:
        raise ValueError(f"circuits are numbered from 1, got c={c}")
    north = i if c == 1 else (2 * c - 3) * r + 2 * i
    south = 2 * i if c == 1 else north + r
    return north, north, south, south


def ddsa_legs(r: int, i: int, circuits: int, gap: float = DEFAULT_GAP) -> list[float]:
    """Leg lengths [m] of robot i of r for `circuits` circuits, N, E, S, W per circuit, eqs. (1)-(2).

    Each length is the paper's step count F times the gap g.
    """
    return [steps * gap for c in range(1, circuits + 1) for steps in ddsa_leg_steps(r, i, c)]


def mdbsa_leg_steps(c: int, r: int = 1) -> tuple[int, int, int, int]:
    """(N, E, S, W) step counts of a region's single spiral on circuit c, eqs. (4)-(5).

    F^N = F^E = 1 (c = 1), (2c-3) r + 2 (c > 1);  F^S = F^W = 2 (c = 1), F^N + r (c > 1).
    Paper ambiguity: eqs. (4)-(5) keep the symbol r although the text derives them from
    eqs. (1)-(2) "when the number of robots is 1". We read r = 1 (one spiral per region, lines
    one gap apart: 1, 1, 2, 2, 3, 3, 4, 4, ...); r is kept as a parameter only so the equation
    can be checked as printed.
    """
    if c < 1 or r < 1:
        raise ValueError(f"need c >= 1 and r >= 1, got c={c}, r={r}")
    north = 1 if c == 1 else (2 * c - 3) * r + 2
    south = 2 if c == 1 else north + r
    return north, north, south, south


def mdbsa_legs(circuits: int, gap: float = DEFAULT_GAP, r: int = 1) -> list[float]:
    """Leg lengths [m] of a region's spiral for `circuits` circuits, eqs. (4)-(5)."""
    return [steps * gap for c in range(1, circuits + 1) for steps in mdbsa_leg_steps(c, r)]


# --------------------------------------------------------------------------------------------
# Paths
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class SpiralPath:
    """A polyline walked by arc length; immutable so a path can be shared between robots.

    Two robots may share one region's spiral (MDBSA Sec. IV): one walks it from the start
    (clockwise, outward), the other walks `reversed()` from the far end (counter-clockwise, inward).
    """

    waypoints: np.ndarray
    """(K, 2) polyline vertices [m, world frame], K >= 1."""
    cumulative: np.ndarray = field(init=False, repr=False)
    """(K,) arc length from the first waypoint to each waypoint [m]."""

    def __post_init__(self) -> None:
        pts = np.array(self.waypoints, dtype=float).reshape(-1, 2)
        if len(pts) == 0:
            raise ValueError("a path needs at least one waypoint")
        seg = np.linalg.norm(np.diff(pts, axis=0), axis=1)
        cum = np.concatenate([[0.0], np.cumsum(seg)])
        pts.setflags(write=False)
        cum.setflags(write=False)
        object.__setattr__(self, "waypoints", pts)
        object.__setattr__(self, "cumulative", cum)

    @property
    def length(self) -> float:
        """Total arc length [m]."""
        return float(self.cumulative[-1])

    @property
    def start(self) -> np.ndarray:
        """First waypoint [m, world frame]."""
        return self.waypoints[0]

    @property
    def end(self) -> np.ndarray:
        """Last waypoint [m, world frame]."""
        return self.waypoints[-1]

    def point_at(self, s: float) -> np.ndarray:
        """Point at arc length s [m] from the start; s is clamped to [0, length]."""
        s = min(max(float(s), 0.0), self.length)
        k = int(np.searchsorted(self.cumulative, s, side="right")) - 1
        k = min(max(k, 0), len(self.waypoints) - 2) if len(self.waypoints) > 1 else 0
        if len(self.waypoints) == 1:
            return self.waypoints[0].copy()
        seg_len = self.cumulative[k + 1] - self.cumulative[k]
        t = 0.0 if seg_len <= 0 else (s - self.cumulative[k]) / seg_len
        return self.waypoints[k] + t * (self.waypoints[k + 1] - self.waypoints[k])

    def next_waypoint_index(self, s: float) -> int:
        """Index of the first waypoint strictly beyond arc length s (len(waypoints) at the end)."""
        return int(np.searchsorted(self.cumulative, float(s) + _EPS, side="left"))

    def reversed(self) -> SpiralPath:
        """The same polyline walked from the far end; s' = length - s."""
        return SpiralPath(self.waypoints[::-1].copy())


def _exit_fraction(p: np.ndarray, q: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> float:
    """Largest t in [0, 1] with p + t (q - p) inside the box [lo, hi]; p must be inside."""
    t = 1.0
    d = q - p
    for ax in range(2):
        if d[ax] > 0 and q[ax] > hi[ax] + _EPS:
            t = min(t, (hi[ax] - p[ax]) / d[ax])
        elif d[ax] < 0 and q[ax] < lo[ax] - _EPS:
            t = min(t, (lo[ax] - p[ax]) / d[ax])
    return max(t, 0.0)


def _inside(p: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> bool:
    return bool(np.all(p >= lo - _EPS) and np.all(p <= hi + _EPS))


def _walk_truncated(start: np.ndarray, legs: list[tuple[int, float]], lo: np.ndarray,
                    hi: np.ndarray) -> np.ndarray:
    """Waypoints of legs (heading index, length [m]) from start, stopping where the path first
    leaves the box: the leg that crosses the boundary is cut there and the path ends."""
    pts = [start.copy()]
    p = start.copy()
    for heading, length in legs:
        if length <= 0:
            continue
        q = p + _HEADINGS[heading] * length
        if _inside(q, lo, hi):
            pts.append(q)
            p = q
            continue
        t = _exit_fraction(p, q, lo, hi)
        if t * length > _EPS:
            pts.append(p + t * (q - p))
        break
    return np.array(pts)


def ddsa_path(center: tuple[float, float] | np.ndarray, r: int, i: int, gap: float,
              half_extent: float, *, include_shared_stem: bool = False) -> np.ndarray:
    """(K, 2) waypoints [m, world frame] of robot i's (1..r) interlocking square spiral, eqs. (1)-(2).

    The spiral starts at `center` (the collection zone) and is clipped to the square
    center + [-half_extent, half_extent]^2 (pass the arena half-side minus a wall margin).

    Stem: read literally, every robot's first leg runs north from the center (i gaps long), so
    robot i's first leg re-walks the first legs of robots 1..i-1. By default the path starts at
    center + (0, (i-1) g), where robot i-1's first leg ends; the robot reaches it by driving
    out from the center (as the paper's "moves to its designated path"), and the r first legs
    then tile the line x = 0 with no leg shared. `include_shared_stem=True` gives the literal path.

    Clipping: the spiral is truncated where it first leaves the square (the crossing leg is cut
    at the boundary). Clamping legs onto the boundary instead would make several robots sweep
    the same wall strip (shared legs); truncation leaves at most a strip near the walls that the
    outermost legs do not reach (the interlocked rings are one gap apart, so it is narrow).
    If the arena is too small to hold even robot i's stem, a single (clamped) point is returned.
    """
    c0 = np.asarray(center, dtype=float)
    ext = float(half_extent)
    lo, hi = c0 - ext, c0 + ext
    # Enough circuits that the innermost ring of robot i is past the boundary: ring c has
    # half-width (c-2) r + i + ... >= (c-2) r, so (c-2) r > ext/gap + r suffices.
    circuits = int(np.ceil(ext / (gap * r))) + 3
    legs = [(k % 4, steps * gap)
            for c in range(1, circuits + 1)
            for k, steps in enumerate(ddsa_leg_steps(r, i, c))]
    start = c0.copy()
    if not include_shared_stem and i > 1:
        start = c0 + np.array([0.0, (i - 1) * gap])
        legs[0] = (0, gap)
    if not _inside(start, lo, hi):
        # Arena too small for robot i's ring: nothing left to search, a one-point path.
        return np.clip(start, lo, hi)[None, :]
    return _walk_truncated(start, legs, lo, hi)


def region_side(n_regions: int, arena_size: float) -> float:
    """Side length of one of the N_R equal square regions [m]: L / sqrt(N_R)."""
    return float(arena_size) / np.sqrt(n_regions)


def _overlaps_collinear(a0: np.ndarray, a1: np.ndarray, b0: np.ndarray, b1: np.ndarray) -> bool:
    """True if two axis-parallel segments share a piece of positive length."""
    for ax in range(2):
        other = 1 - ax
        if (abs(a0[other] - a1[other]) < _EPS and abs(b0[other] - b1[other]) < _EPS
                and abs(a0[other] - b0[other]) < _EPS):
            lo = max(min(a0[ax], a1[ax]), min(b0[ax], b1[ax]))
            hi = min(max(a0[ax], a1[ax]), max(b0[ax], b1[ax]))
            if hi - lo > 1e-7:
                return True
    return False


def mdbsa_path(region_center: tuple[float, float] | np.ndarray, region_side: float,
               gap: float = DEFAULT_GAP, *, margin: float = 0.0) -> np.ndarray:
    """(K, 2) waypoints [m, world frame] of the single spiral of one region, eqs. (4)-(5) with r = 1.

    The spiral starts at the region's center, runs N, E, S, W clockwise outward with lines one
    gap apart, and is clipped to the region square (shrunk by `margin` on every side).

    Clipping (the paper only says the path "fits within each region"): circuits whose waypoints
    stay inside are kept as they are; from the first circuit that pokes out, waypoints are
    clamped onto the square's boundary, so the last lines run along the region's edges and the
    detection discs reach into the corners; the path stops before the first clamped leg that
    would re-walk a line already walked (that would only add oversampling).
    """
    c0 = np.asarray(region_center, dtype=float)
    half = float(region_side) / 2.0 - float(margin)
    if half <= 0:
        raise ValueError("margin leaves no room in the region")
    lo, hi = c0 - half, c0 + half
    circuits = int(np.ceil(half / gap)) + 3
    pts = [c0.copy()]
    p_raw = c0.copy()
    for c in range(1, circuits + 1):
        for k, steps in enumerate(mdbsa_leg_steps(c, 1)):
            p_raw = p_raw + _HEADINGS[k] * steps * gap
            q = np.clip(p_raw, lo, hi)
            a = pts[-1]
            if np.linalg.norm(q - a) < _EPS:
                continue
            if any(_overlaps_collinear(a, q, pts[m], pts[m + 1]) for m in range(len(pts) - 1)):
                return np.array(pts)
            pts.append(q)
    return np.array(pts)


def segments_overlap_collinear(path_a: np.ndarray, path_b: np.ndarray) -> bool:
    """True if some leg of path_a and some leg of path_b share a piece of positive length."""
    for m in range(len(path_a) - 1):
        for n in range(len(path_b) - 1):
            if _overlaps_collinear(path_a[m], path_a[m + 1], path_b[n], path_b[n + 1]):
                return True
    return False
