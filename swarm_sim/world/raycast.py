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
tests only the few rays inside the angular window the circle subtends around its bearing (for
most robot pairs, only the ray nearest to the bearing), and each unordered robot pair computes
its bearing once; the nearest hit per ray is kept with ``np.minimum.at``. The cost grows with the
number of robot pairs closer than range_max (`swarm_sim.world.pairs` finds them).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from swarm_sim.scenario import ScanConfig, Scenario
from swarm_sim.world.pairs import RobotPairs, pairs_in_reach

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
    r2 = radius * radius if np.isscalar(radius) else (radius * radius)[pair]
    _hit_circles(best, ux, uy, i[pair] * rays + k, dx[pair], dy[pair], d2[pair], r2, inside[pair])


def _hit_circles(
    best: np.ndarray,
    ux: np.ndarray,
    uy: np.ndarray,
    flat: np.ndarray,
    dx: np.ndarray,
    dy: np.ndarray,
    d2: np.ndarray,
    r2: np.ndarray | float,
    inside: np.ndarray | bool,
) -> None:
    """Lower `best` at rays `flat` (robot * rays + ray) by their hits on circles of squared
    radius `r2` centred (dx, dy) from the ray's origin, d2 = dx^2 + dy^2 (`inside`: the origin is
    inside the circle). The exact test every path of the scan ends in."""
    along = dx * ux[flat] + dy * uy[flat]
    disc = r2 - d2 + along * along  # r^2 - squared distance from the centre to the ray line
    hit = (disc >= 0.0) & ((along > 0.0) | inside)
    t = along[hit] - np.sqrt(disc[hit])
    np.minimum.at(best, flat[hit], np.maximum(t, 0.0))


def _cast_robots(
    best: np.ndarray,
    ux: np.ndarray,
    uy: np.ndarray,
    i: np.ndarray,
    j: np.ndarray,
    dx: np.ndarray,
    dy: np.ndarray,
    d2: np.ndarray,
    radius: float,
    headings: np.ndarray,
    rays: int,
    angle_min: float,
    inc: float,
    full: bool,
) -> None:
    """Lower `best` by the robots' ray hits on each other: pairs (i, j) both ways, (dx, dy) from
    i to j (so -(dx, dy) from j to i, and the bearing from j is the one from i + pi).

    A full circle's rays are 2 pi / rays apart, and most pairs in reach are far enough apart that
    the window a robot subtends is narrower than that (with 24 rays: beyond ~0.65 m for a robot
    of radius 0.085 m). Then only the ray nearest to the bearing can lie in the window, and one
    rounding per pair and direction finds it: no ragged windows to expand (1000 robots on
    38 x 38 m, ~80,000 pairs in reach: scan 4.8 -> 3.1 ms a tick). The window is compared
    squared, so these pairs need no square root: its half-width in rays is tan(asin(r / d)) /
    inc, as in `_window_half_angles`, and tan^2(asin(x)) = r^2 / (d^2 - r^2). The wider windows
    (near pairs, a robot inside another, partial fields of view) go through `_ray_windows`. Both
    only choose which rays the exact test (`_hit_circles`) sees; their windows hold every ray
    that can hit.
    """
    bearing = np.arctan2(dy, dx)
    wide = np.arange(len(i))
    if full:
        scale = 1.0 / inc
        r2 = radius * radius
        with np.errstate(divide="ignore"):
            # squared half-width [rays^2], widened (by >= _WINDOW_EPS rays while below 1/2 ray)
            half2 = r2 * scale * scale / (d2 - r2) + _WINDOW_EPS
        narrow = (half2 > _WINDOW_EPS) & (half2 < 0.25)  # d2 <= r2: <= eps or inf
        wide = np.flatnonzero(~narrow)
        half2[wide] = -1.0  # they take the other path
        # The bearing's position among the rays [in rays from ray 0, unwrapped], i -> j, j -> i.
        offset = (headings + angle_min) * scale
        pos = np.empty((2, len(i)))
        bearing_rays = bearing * scale
        np.subtract(bearing_rays, offset.take(i), out=pos[0])
        np.subtract(bearing_rays, (offset - 0.5 * rays).take(j), out=pos[1])
        nearest = np.rint(pos)
        pos -= nearest
        pos *= pos
        q = np.flatnonzero(pos <= half2)
        back = np.searchsorted(q, len(i))  # q[back:] are the j -> i ones
        pair = q.copy()
        pair[back:] -= len(i)
        robot = np.concatenate([i.take(pair[:back]), j.take(pair[back:])])
        dx_q, dy_q = dx.take(pair), dy.take(pair)
        np.negative(dx_q[back:], out=dx_q[back:])  # (dx, dy) from robot j is -(dx, dy) from robot i
        np.negative(dy_q[back:], out=dy_q[back:])
        k = nearest.ravel().take(q).astype(np.intp) % rays
        _hit_circles(best, ux, uy, robot * rays + k, dx_q, dy_q, d2.take(pair), r2, False)
    if len(wide):
        i, j, dx, dy, d2, bearing = i[wide], j[wide], dx[wide], dy[wide], d2[wide], bearing[wide]
        _cast_circles(
            best, ux, uy, np.concatenate([i, j]), np.concatenate([dx, -dx]), np.concatenate([dy, -dy]),
            np.concatenate([d2, d2]), np.concatenate([bearing, bearing + math.pi]), radius, headings,
            rays, angle_min, inc, full,
        )


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
    pairs: RobotPairs | None = None,
) -> np.ndarray:
    """Ranges (N, rays) float32 [m] for robots at `origins` (N, 2) [m, world] with `headings`
    (N,) [rad]. Every robot is a circle of `robot_radius` seen by the others, not by itself.

    `pairs`: the swarm's `RobotPairs` with reach range_max + robot_radius, kept by the caller
    from tick to tick (default: the pairs are found from scratch)."""
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
        reach = range_max + robot_radius
        if pairs is not None and pairs.reach != reach:
            raise ValueError(f"the robot pairs are kept for reach {pairs.reach}, the scan needs {reach}")
        i, j, dx, dy, d2 = pairs_in_reach(origins, reach) if pairs is None else pairs(origins)
        if len(i):
            _cast_robots(best, ux, uy, i, j, dx, dy, d2, float(robot_radius), headings, rays, angle_min, inc, full)

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
