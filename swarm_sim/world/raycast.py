"""Planar laser scans for the whole swarm at once.

The world is flat: every robot, wall and obstacle is a vertical prism that spans the scan plane,
so a scan is a 2-D problem. `cast_scan` solves it exactly in numpy for all rays of all robots in
one batch: rays against circles (the other robots, cylinder obstacles), against oriented boxes
(box obstacles: their four edge segments, tested with the slab method) and against the arena's
wall faces. `cast_scan_pybullet` asks pybullet's ``rayTestBatch`` the same question against the
collision shapes; it is slower and exists to cross-check the analytic backend. (pybullet's
convex ray cast stops within ~1 mm of a surface along its normal, so the two differ by up to
~1 mm there, more at grazing incidence.)

Conventions (shared with the LaserScan codec, `swarm_msgs_py.scan`): ray i points at
``heading + angle_min + i * angle_increment``; ranges are measured from the robot centre, the
robot's own body is not seen, values ``>= range_max`` become ``inf``, values ``< range_min``
become ``-inf`` (REP 117 "too close"), and ranges are float32.

Speed: instead of testing every ray against every circle, each (robot, circle) pair within reach
tests only the few rays inside the angular window the circle subtends around its bearing, and
each unordered robot pair computes its bearing once; the nearest hit per ray is kept with
``np.minimum.at``. The cost grows with the number of robot pairs closer than range_max.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from swarm_sim.scenario import ScanConfig, Scenario

TWO_PI = 2 * math.pi
_WINDOW_EPS = 1e-9
"""Angular windows are widened by this [in rays] so that rounding never drops a ray; the exact
intersection test decides."""
PYBULLET_START_OFFSET = 1e-4
"""pybullet rays start this far outside the robot's own body [m] so they cannot hit it."""
PYBULLET_BATCH = 8192
"""Rays per rayTestBatch call (pybullet caps a batch)."""


def is_full_circle(fov: float) -> bool:
    return fov >= TWO_PI - 1e-9


def scan_angles(rays: int, fov: float) -> tuple[float, float]:
    """(angle_min, angle_increment) [rad, relative to the heading], as the codec sends them.

    A full circle spaces the rays fov/rays apart so the first and last do not coincide; a partial
    fov puts rays on both edges (fov/(rays-1)); a single ray uses fov/rays.
    """
    if is_full_circle(fov) or rays == 1:
        return -fov / 2, fov / rays
    return -fov / 2, fov / (rays - 1)


@dataclass(frozen=True, eq=False)
class StaticScene:
    """What never moves, in the form the analytic scan wants [m, rad; world frame]."""

    half_size: float
    """The wall faces are the lines |x| = half_size and |y| = half_size (arena side / 2)."""
    circles: np.ndarray
    """(C, 3): x, y, radius of cylinder obstacles."""
    boxes: np.ndarray
    """(B, 5): x, y, half length along the box's x, half length along its y, yaw."""

    @classmethod
    def from_scenario(cls, scenario: Scenario) -> StaticScene:
        circles, boxes = [], []
        for o in scenario.obstacles:
            if o.shape == "cylinder":
                circles.append((o.center[0], o.center[1], o.size[0] / 2))
            else:
                boxes.append((o.center[0], o.center[1], o.size[0] / 2, o.size[1] / 2, o.yaw))
        return cls(
            scenario.arena.size / 2,
            np.array(circles, dtype=float).reshape(-1, 3),
            np.array(boxes, dtype=float).reshape(-1, 5),
        )


# --------------------------------------------------------------------------- analytic


KD_TREE_FROM = 200
"""Swarms of at least this many robots find their robot pairs within reach with a k-d tree;
smaller ones test all N (N - 1) / 2 pairs (cheaper than building a tree at ~100 robots; at 1000
robots all pairs cost ~8 ms a tick, the tree well under 1 ms)."""

_UPPER_PAIRS: dict[int, tuple[np.ndarray, np.ndarray]] = {}


def _upper_pairs(n: int) -> tuple[np.ndarray, np.ndarray]:
    """(i, j) for all i < j < n, cached per swarm size."""
    if n not in _UPPER_PAIRS:
        _UPPER_PAIRS[n] = np.triu_indices(n, 1)
    return _UPPER_PAIRS[n]


def _robot_pairs_in_reach(origins: np.ndarray, reach: float) -> tuple[np.ndarray, ...]:
    """(i, j, dx, dy, d2) of the robot pairs i < j strictly closer than `reach` [m], with
    (dx, dy) = origin j - origin i [m] and d2 its squared length.

    Both ways give the same set (the tree's candidates are filtered with the same exact
    ``d2 < reach^2`` test the all-pairs way uses), in different orders; the scan keeps the
    nearest hit per ray with ``np.minimum.at``, which does not depend on the order, so the ranges
    are bit for bit the same either way.
    """
    n = len(origins)
    if n >= KD_TREE_FROM:
        from scipy.spatial import cKDTree

        pairs = cKDTree(origins).query_pairs(reach * (1 + 1e-9), output_type="ndarray")
        i, j = pairs[:, 0], pairs[:, 1]  # scipy gives i < j
    else:
        i, j = _upper_pairs(n)
    dx = origins[j, 0] - origins[i, 0]
    dy = origins[j, 1] - origins[i, 1]
    d2 = dx * dx + dy * dy
    near = np.flatnonzero(d2 < reach * reach)
    return i[near], j[near], dx[near], dy[near], d2[near]


def _expand(lo: np.ndarray, count: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For windows (lo, count): (window index, ray index) of every ray in every window."""
    total = int(count.sum())
    owner = np.repeat(np.arange(len(count)), count)
    starts = np.cumsum(count) - count
    k = np.arange(total) + (lo - starts)[owner]
    return owner, k


def _wrap_positive(angle: np.ndarray) -> np.ndarray:
    """Angles mapped to [0, 2 pi) (np.mod is several times slower for floats)."""
    out = angle - TWO_PI * np.floor(angle * (1.0 / TWO_PI))
    out[out >= TWO_PI] = 0.0
    return out


def _ray_windows(
    rel: np.ndarray, alpha: np.ndarray, everything: np.ndarray, rays: int, inc: float, full_circle: bool
) -> tuple[np.ndarray, np.ndarray]:
    """Rays whose angle lies within +-alpha of `rel` (angle from ray 0 [rad]).

    Returns (pair index, ray index) arrays. Pairs flagged `everything` (the origin is inside the
    shape's bounding circle) get every ray.
    """
    rel = _wrap_positive(rel)
    if full_circle:
        # alpha <= pi/2, so a window never holds more than rays/2 + 1 rays (no wrap-around twice)
        scale = 1.0 / inc
        lo = np.ceil((rel - alpha) * scale - _WINDOW_EPS).astype(np.int64)
        count = np.floor((rel + alpha) * scale + _WINDOW_EPS).astype(np.int64) - lo + 1
        if everything.any():
            lo[everything] = 0
            count[everything] = rays
        some = np.flatnonzero(count)  # most distant pairs fall between two rays
        owner, k = _expand(lo[some], np.minimum(count[some], rays))
        k[k < 0] += rays
        k[k >= rays] -= rays
        return some[owner], k
    # A partial fov covers angles [0, fov] from ray 0; a window may also match after a +-2 pi
    # shift. A single ray only needs lo <= 0 <= hi, for which any positive inc will do.
    inc = inc if inc > 0 else 1.0
    owners, ks = [], []
    for shift in (-TWO_PI, 0.0, TWO_PI):
        lo = np.maximum(np.ceil((rel + shift - alpha) / inc - _WINDOW_EPS), 0).astype(np.int64)
        hi = np.minimum(np.floor((rel + shift + alpha) / inc + _WINDOW_EPS), rays - 1).astype(np.int64)
        if shift == 0.0:
            lo[everything] = 0
            hi[everything] = rays - 1
        else:
            hi[everything] = -1
        owner, k = _expand(lo, np.maximum(hi - lo + 1, 0))
        owners.append(owner)
        ks.append(k)
    return np.concatenate(owners), np.concatenate(ks)


def _window_half_angles(d2: np.ndarray, radius: np.ndarray | float) -> tuple[np.ndarray, np.ndarray]:
    """A never-too-small window half-angle for a circle of `radius` at squared distance `d2`,
    and whether the origin is inside the circle.

    The exact half-angle is asin(r/d); tan(asin(x)) = x / sqrt(1 - x^2) bounds it from above,
    is tight for the small x of distant robots, and costs a sqrt instead of an arcsin.
    """
    r2 = radius * radius
    inside = d2 <= r2
    x2 = np.minimum(r2 / np.maximum(d2, 1e-300), 0.5)  # above 45 degrees: clamp to pi/2 below
    alpha = np.sqrt(x2 / (1.0 - x2))
    alpha[x2 >= 0.5] = math.pi / 2
    return alpha, inside


def _pairs_in_reach(
    ox: np.ndarray, oy: np.ndarray, cx: np.ndarray, cy: np.ndarray, reach: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(robot, shape, dx, dy, d2) for every static shape whose bounding circle a ray can reach."""
    dx = cx[None, :] - ox[:, None]
    dy = cy[None, :] - oy[:, None]
    d2 = dx * dx + dy * dy
    i, j = np.nonzero(d2 < (reach * reach)[None, :])
    return i, j, dx[i, j], dy[i, j], d2[i, j]


def _cast_circles(
    best: np.ndarray,
    ux: np.ndarray,
    uy: np.ndarray,
    i: np.ndarray,
    dx: np.ndarray,
    dy: np.ndarray,
    d2: np.ndarray,
    bearing: np.ndarray,
    radius: np.ndarray | float,
    headings: np.ndarray,
    rays: int,
    angle_min: float,
    inc: float,
    full: bool,
) -> None:
    """Lower `best` (flat, N * rays) by robot i's ray hits on circles centred (dx, dy) from it."""
    alpha, inside = _window_half_angles(d2, radius)
    pair, k = _ray_windows(bearing - headings[i] - angle_min, alpha, inside, rays, inc, full)
    if len(pair) == 0:
        return
    flat = i[pair] * rays + k
    along = dx[pair] * ux[flat] + dy[pair] * uy[flat]
    r2 = radius * radius if np.isscalar(radius) else (radius * radius)[pair]
    disc = r2 - d2[pair] + along * along  # r^2 - squared distance from the centre to the ray line
    hit = (disc >= 0.0) & ((along > 0.0) | inside[pair])
    t = along[hit] - np.sqrt(disc[hit])
    np.minimum.at(best, flat[hit], np.maximum(t, 0.0))


def _cast_boxes(
    best: np.ndarray,
    ux: np.ndarray,
    uy: np.ndarray,
    ox: np.ndarray,
    oy: np.ndarray,
    boxes: np.ndarray,
    headings: np.ndarray,
    range_max: float,
    rays: int,
    angle_min: float,
    inc: float,
    full: bool,
) -> None:
    """Lower `best` by ray hits on oriented boxes: slab test in the box frame for the rays inside
    the window of the box's bounding circle."""
    bound = np.hypot(boxes[:, 2], boxes[:, 3])
    i, j, dx, dy, d2 = _pairs_in_reach(ox, oy, boxes[:, 0], boxes[:, 1], range_max + bound)
    if len(i) == 0:
        return
    alpha, inside = _window_half_angles(d2, bound[j])
    pair, k = _ray_windows(np.arctan2(dy, dx) - headings[i] - angle_min, alpha, inside, rays, inc, full)
    flat = i[pair] * rays + k
    jb = j[pair]
    cos_b, sin_b = np.cos(boxes[jb, 4]), np.sin(boxes[jb, 4])
    px, py = -dx[pair], -dy[pair]  # the ray origin relative to the box centre
    lx, ly = cos_b * px + sin_b * py, -sin_b * px + cos_b * py
    wx, wy = ux[flat], uy[flat]
    vx, vy = cos_b * wx + sin_b * wy, -sin_b * wx + cos_b * wy
    hx, hy = boxes[jb, 2], boxes[jb, 3]
    with np.errstate(divide="ignore", invalid="ignore"):
        ax, bx = (-hx - lx) / vx, (hx - lx) / vx
        ay, by = (-hy - ly) / vy, (hy - ly) / vy
    near = np.fmax(np.fmin(ax, bx), np.fmin(ay, by))
    far = np.fmin(np.fmax(ax, bx), np.fmax(ay, by))
    hit = (near <= far) & (far >= 0.0)
    np.minimum.at(best, flat[hit], np.maximum(near[hit], 0.0))


def cast_scan(
    origins: np.ndarray,
    headings: np.ndarray,
    robot_radius: float,
    scene: StaticScene,
    rays: int,
    fov: float,
    range_max: float,
    range_min: float = 0.0,
) -> np.ndarray:
    """Ranges (N, rays) float32 [m] for robots at `origins` (N, 2) [m, world] with `headings`
    (N,) [rad]. Every robot is a circle of `robot_radius` seen by the others, not by itself."""
    origins = np.asarray(origins, dtype=float)
    headings = np.asarray(headings, dtype=float)
    n = len(origins)
    angle_min, inc = scan_angles(rays, fov)
    full = is_full_circle(fov)
    ox, oy = origins[:, 0], origins[:, 1]
    angles = headings[:, None] + (angle_min + inc * np.arange(rays))[None, :]
    ux = np.cos(angles)
    uy = np.sin(angles)

    # Wall faces |x| = h, |y| = h seen from inside: the exit distance of the square.
    h = scene.half_size
    with np.errstate(divide="ignore", invalid="ignore"):
        tx = (np.copysign(h, ux) - ox[:, None]) / ux
        ty = (np.copysign(h, uy) - oy[:, None]) / uy
    best = np.maximum(np.fmin(tx, ty), 0.0).ravel()
    ux = ux.ravel()
    uy = uy.ravel()

    # Other robots: each unordered pair once (the bearing from j to i is the one from i to j + pi).
    if n > 1:
        i, j, dx, dy, d2 = _robot_pairs_in_reach(origins, range_max + robot_radius)
        if len(i):
            bearing = np.arctan2(dy, dx)
            _cast_circles(
                best, ux, uy, np.concatenate([i, j]), np.concatenate([dx, -dx]),
                np.concatenate([dy, -dy]), np.concatenate([d2, d2]),
                np.concatenate([bearing, bearing + math.pi]), float(robot_radius), headings,
                rays, angle_min, inc, full,
            )

    if len(scene.circles):
        c = scene.circles
        i, j, dx, dy, d2 = _pairs_in_reach(ox, oy, c[:, 0], c[:, 1], range_max + c[:, 2])
        if len(i):
            _cast_circles(
                best, ux, uy, i, dx, dy, d2, np.arctan2(dy, dx), c[j, 2], headings,
                rays, angle_min, inc, full,
            )

    if len(scene.boxes):
        _cast_boxes(best, ux, uy, ox, oy, scene.boxes, headings, range_max, rays, angle_min, inc, full)

    return _finish(best.reshape(n, rays), range_min, range_max)


def _finish(ranges: np.ndarray, range_min: float, range_max: float) -> np.ndarray:
    """Round to float32 and apply the REP 117 out-of-range markers."""
    out = ranges.astype(np.float32)
    out[out >= np.float32(range_max)] = np.inf
    if range_min > 0.0:
        out[out < np.float32(range_min)] = -np.inf
    return out


# --------------------------------------------------------------------------- pybullet


def cast_scan_pybullet(
    client: int,
    origins: np.ndarray,
    headings: np.ndarray,
    z: float,
    robot_radius: float,
    config: ScanConfig,
    num_threads: int = 1,
) -> np.ndarray:
    """Same as `cast_scan`, by pybullet ``rayTestBatch`` against the collision shapes at height z.

    Rays start PYBULLET_START_OFFSET outside the robot's own cylinder (so they cannot hit it) and
    the offset is added back to the range. `num_threads` is rayTestBatch's numThreads.
    """
    import pybullet as p

    origins = np.asarray(origins, dtype=float)
    n = len(origins)
    angle_min, inc = scan_angles(config.rays, config.fov)
    offsets = angle_min + inc * np.arange(config.rays)
    angles = np.asarray(headings, dtype=float)[:, None] + offsets[None, :]
    u = np.stack([np.cos(angles), np.sin(angles)], axis=-1).reshape(-1, 2)
    o = np.repeat(origins, config.rays, axis=0)
    start = robot_radius + PYBULLET_START_OFFSET
    zs = np.full((len(u), 1), float(z))
    ray_from = np.hstack([o + start * u, zs])
    ray_to = np.hstack([o + config.range_max * u, zs])
    fraction = np.empty(len(u))
    for lo in range(0, len(u), PYBULLET_BATCH):
        hits = p.rayTestBatch(
            ray_from[lo : lo + PYBULLET_BATCH].tolist(),
            ray_to[lo : lo + PYBULLET_BATCH].tolist(),
            numThreads=num_threads,
            physicsClientId=client,
        )
        fraction[lo : lo + len(hits)] = [hit[2] if hit[0] >= 0 else np.inf for hit in hits]
    ranges = start + fraction * (config.range_max - start)
    return _finish(ranges.reshape(n, config.rays), config.range_min, config.range_max)
