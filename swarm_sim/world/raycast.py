"""Planar laser scans for the whole swarm at once.

The world is flat: every robot, wall and obstacle is a vertical prism that spans the scan plane,
so a scan is a 2-D problem. `cast_scan` solves it exactly for all rays of all robots in one
batch: rays against circles (the other robots, cylinder obstacles), against oriented boxes
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
its bearing once. The cost grows with the number of robot pairs closer than range_max
(`swarm_sim.world.pairs` finds them).

The ray tests are plain loops compiled with numba (`swarm_sim.world.jit`), in place of the ~60
numpy calls a tick of the batched version they replaced, whose fixed cost dominated at 112
robots. Measured on recorded poses of a CPFA run, the scan alone, alternated with that version
(median of 15 alternated rounds, thread CPU time): 112 robots 0.34 -> 0.16 ms (crowded start),
0.23 -> 0.10 ms (spread out); 1000 robots on 38 x 38 m (~85,000 pairs in reach) only
2.30 -> 2.22 and 2.09 -> 1.95 ms. At 1000 robots what remains is numpy's cos and sin of the
24,000 ray directions (~0.36 ms), the robot pairs (0.21 ms), their bearings (0.1 ms) and the
ray tests (~1.3 ms, about 7 ns per pair and direction: scalar code whose loads are scattered
over the swarm's rays; listing the rays to test first, sorting the pairs or splitting off the
wide windows measured no faster).

Bit for bit the ranges of the numpy version: the kernels do its IEEE operations in its order,
and the transcendental functions are numpy's, computed outside the kernels: the ray directions
(cos, sin; numpy's equal libm's in 2 million samples on this machine, but numpy may bring its
own SIMD versions elsewhere) and the boxes' rotations, and the bearings (numpy's vectorised
arctan2 differs from libm's in ~7 % of values and is ~15x faster; the bearings only choose which
rays are tested, within windows widened by _WINDOW_EPS rays). The tests compare the float64 nearest
hits (`nearest_hits`) with a numpy reference of the same arithmetic on every ray of every robot,
bit for bit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from swarm_sim.scenario import ScanConfig, Scenario
from swarm_sim.world.bullet import pybullet
from swarm_sim.world.jit import inline, kernel
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


def evenly_round(rays: int, fov: float) -> bool:
    """The rays are evenly spaced all the way round: a full circle, or a partial fov whose rays'
    spacing closes the circle (24 rays over 345 deg: the foot-bot's ring, 15 deg apart from
    -172.5 deg). The analytic scan then wraps its windows and tests a far robot on one ray."""
    if is_full_circle(fov):
        return True
    return rays > 1 and abs(fov / (rays - 1) * rays - TWO_PI) < 1e-9


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

@inline
def _max0(t: float) -> float:
    """np.maximum(t, 0.0): nan stays nan, -0.0 becomes 0.0 (numpy returns the second operand of
    a tie), so no range is ever -0.0."""
    return t if (t > 0.0) | (t != t) else 0.0


@inline
def _fmin(a: float, b: float) -> float:
    """np.fmin: the smaller of the two, ignoring a nan. (Which zero it gives for -0.0 vs 0.0
    does not matter: every result goes through `_max0` or a comparison.)"""
    return a if (a < b) | (b != b) else b


@inline
def _fmax(a: float, b: float) -> float:
    """np.fmax: the larger of the two, ignoring a nan."""
    return a if (a > b) | (b != b) else b


@inline
def _lower(best: np.ndarray, robot: int, k: int, t: float) -> None:
    """best[robot, k] = np.minimum(best[robot, k], t): the nearest hit so far (nan wins, as in
    numpy). A select, not a branch (see `_hit_circle`)."""
    b = best[robot, k]
    best[robot, k] = t if (t < b) | (t != t) else b


@kernel
def _walls(ox: np.ndarray, oy: np.ndarray, ux: np.ndarray, uy: np.ndarray, half_size: float) -> np.ndarray:
    """(N, rays) distances [m] at which the rays leave the arena: the wall faces |x| = half_size
    and |y| = half_size seen from inside (the square's exit distance)."""
    best = np.empty(ux.shape)
    for robot in range(ux.shape[0]):
        for k in range(ux.shape[1]):
            tx = (math.copysign(half_size, ux[robot, k]) - ox[robot]) / ux[robot, k]
            ty = (math.copysign(half_size, uy[robot, k]) - oy[robot]) / uy[robot, k]
            best[robot, k] = _max0(_fmin(tx, ty))
    return best


# The rays that can hit a shape: those whose angle lies within +-alpha of the shape's bearing,
# alpha a never-too-small half-angle of the shape's bounding circle. The windows only choose
# which rays the exact tests (`_hit_circle`, `_hit_box`) see, so how they are computed does not
# change a range, as long as they hold every ray that can hit.


@inline
def _half_angle(d2: float, r2: float) -> float:
    """A never-too-small window half-angle [rad] for a circle of squared radius r2 at squared
    distance d2 > r2 (the origin outside it).

    The exact half-angle is asin(r/d); tan(asin(x)) = x / sqrt(1 - x^2) bounds it from above,
    is tight for the small x of distant robots, and costs a sqrt instead of an arcsin. Above
    45 degrees it is clamped to pi/2, which bounds every asin.
    """
    x2 = min(r2 / max(d2, 1e-300), 0.5)
    if x2 >= 0.5:
        return math.pi / 2
    return math.sqrt(x2 / (1.0 - x2))


@inline
def _wrap_positive(angle: float) -> float:
    """The angle mapped to [0, 2 pi)."""
    out = angle - TWO_PI * math.floor(angle * (1.0 / TWO_PI))
    return 0.0 if out >= TWO_PI else out


@inline
def _window(rel: float, alpha: float, inside: bool, inc: float, full: bool, rays: np.ndarray) -> int:
    """Write the rays whose angle lies within +-alpha of `rel` (angle from ray 0 [rad]) to
    rays[:count], each once, and return count. `inside` (the origin is inside the shape's
    bounding circle): every ray."""
    n = len(rays)
    if inside:
        for k in range(n):
            rays[k] = k
        return n
    if full:
        # Ray k points k * inc from ray 0, all the way round: the window's first ray, then as
        # many as it holds (alpha <= pi/2, so at most n/2 + 1), wrapped round the circle.
        scale = 1.0 / inc
        lo = math.ceil((rel - alpha) * scale - _WINDOW_EPS)
        hi = math.floor((rel + alpha) * scale + _WINDOW_EPS)
        count = min(max(hi - lo + 1, 0), n)
        for m in range(count):
            rays[m] = (lo + m) % n
        return count
    # A partial fov covers angles [0, fov] from ray 0; a window may also match after a +-2 pi
    # shift (never twice the same ray: windows are at most pi wide). A single ray only needs
    # lo <= 0 <= hi, for which any positive inc will do.
    step = inc if inc > 0 else 1.0
    count = 0
    for shift in (-TWO_PI, 0.0, TWO_PI):
        lo = max(math.ceil((rel + shift - alpha) / step - _WINDOW_EPS), 0)
        hi = min(math.floor((rel + shift + alpha) / step + _WINDOW_EPS), n - 1)
        for k in range(lo, hi + 1):
            rays[count] = k
            count += 1
    return count


@inline
def _hit_circle(
    best: np.ndarray, ux: np.ndarray, uy: np.ndarray, robot: int, k: int,
    dx: float, dy: float, d2: float, r2: float, inside: bool,
) -> None:
    """Lower best[robot, k] by ray k's hit on a circle of squared radius r2 centred (dx, dy) from
    the robot, d2 = dx^2 + dy^2 (`inside`: the robot's centre is inside the circle). The exact
    test every circle ends in.

    Written without a branch on the hit: whether a ray near a robot's window edge hits is a coin
    toss for the CPU's branch predictor, and a mispredicted branch costs more than the whole test
    (1000 robots, ~85,000 pairs: 1.8 -> 0.7 ms a tick).
    """
    along = dx * ux[robot, k] + dy * uy[robot, k]
    disc = r2 - d2 + along * along  # r^2 - squared distance from the centre to the ray line
    hit = (disc >= 0.0) & ((along > 0.0) | inside)
    t = _max0(along - math.sqrt(max(disc, 0.0)))  # computed either way, then selected
    _lower(best, robot, k, t if hit else np.inf)


@kernel
def _lower_by_circle(
    best: np.ndarray, ux: np.ndarray, uy: np.ndarray, headings: np.ndarray, window: np.ndarray,
    robot: int, dx: float, dy: float, d2: float, r2: float, bearing: float, angle_min: float,
    inc: float, full: bool,
) -> None:
    """Lower the robot's ranges by its rays' hits on a circle of squared radius r2 centred
    (dx, dy) from it, at `bearing` [rad, world]: the exact test for the rays in its window."""
    inside = d2 <= r2
    alpha = 0.0 if inside else _half_angle(d2, r2)
    rel = _wrap_positive(bearing - headings[robot] - angle_min)
    for m in range(_window(rel, alpha, inside, inc, full, window)):
        _hit_circle(best, ux, uy, robot, window[m], dx, dy, d2, r2, inside)


@kernel
def _lower_by_robots(
    best: np.ndarray, ux: np.ndarray, uy: np.ndarray, headings: np.ndarray,
    i: np.ndarray, j: np.ndarray, dx: np.ndarray, dy: np.ndarray, d2: np.ndarray, bearing: np.ndarray,
    r2: float, angle_min: float, inc: float, full: bool,
) -> None:
    """Lower `best` by the robots' ray hits on each other: each unordered pair (i, j) once, both
    ways. (dx, dy) points from i to j, so -(dx, dy) from j to i, and the bearing from j is the
    one from i + pi.

    A full circle's rays are 2 pi / rays apart, and most pairs in reach are far enough apart that
    the window a robot subtends is narrower than that (with 24 rays: beyond ~0.65 m for a robot
    of radius 0.085 m). Then only the ray nearest to the bearing can lie in the window, and that
    ray alone is tested, whether it lies in the window or not (a ray that cannot hit changes
    nothing). The window is compared squared, so these pairs need no square root: its half-width
    in rays is tan(asin(r / d)) / inc, as in `_half_angle`, and tan^2(asin(x)) = r^2 / (d^2 - r^2).
    """
    rays = best.shape[1]
    window = np.empty(rays, np.intp)
    scale = 1.0 / inc
    for p in range(len(i)):
        a, b = i[p], j[p]
        # the squared half-width of the window [rays^2], widened (by >= _WINDOW_EPS rays while
        # below 1/2 ray)
        if full and d2[p] > r2 and r2 * scale * scale / (d2[p] - r2) + _WINDOW_EPS < 0.25:
            # the bearing's position among each robot's rays [in rays from its ray 0, unwrapped]
            pos = bearing[p] * scale
            _hit_nearest(best, ux, uy, a, pos - (headings[a] + angle_min) * scale, dx[p], dy[p], d2[p], r2)
            _hit_nearest(best, ux, uy, b, pos - (headings[b] + angle_min) * scale + 0.5 * rays,
                         -dx[p], -dy[p], d2[p], r2)
        else:
            _lower_by_circle(best, ux, uy, headings, window, a, dx[p], dy[p], d2[p], r2, bearing[p],
                             angle_min, inc, full)
            _lower_by_circle(best, ux, uy, headings, window, b, -dx[p], -dy[p], d2[p], r2,
                             bearing[p] + math.pi, angle_min, inc, full)


@inline
def _hit_nearest(
    best: np.ndarray, ux: np.ndarray, uy: np.ndarray, robot: int, pos: float,
    dx: float, dy: float, d2: float, r2: float,
) -> None:
    """The exact test for the robot's ray nearest to position `pos` [rays from ray 0, any turn]."""
    rays = best.shape[1]
    _hit_circle(best, ux, uy, robot, math.floor(pos + 0.5) % rays, dx, dy, d2, r2, False)


@kernel
def _lower_by_cylinders(
    best: np.ndarray, ux: np.ndarray, uy: np.ndarray, headings: np.ndarray, ox: np.ndarray,
    oy: np.ndarray, circles: np.ndarray, bearing: np.ndarray, range_max: float, angle_min: float,
    inc: float, full: bool,
) -> None:
    """Lower `best` by ray hits on the cylinder obstacles `circles` (C, 3: x, y, radius) within
    reach; bearing[robot, c] [rad] is the direction from the robot to the circle's centre."""
    window = np.empty(best.shape[1], np.intp)
    for robot in range(len(ox)):
        for c in range(len(circles)):
            dx = circles[c, 0] - ox[robot]
            dy = circles[c, 1] - oy[robot]
            d2 = dx * dx + dy * dy
            reach = range_max + circles[c, 2]
            if d2 < reach * reach:
                _lower_by_circle(best, ux, uy, headings, window, robot, dx, dy, d2,
                                 circles[c, 2] * circles[c, 2], bearing[robot, c], angle_min, inc, full)


@inline
def _hit_box(
    best: np.ndarray, ux: np.ndarray, uy: np.ndarray, robot: int, k: int,
    lx: float, ly: float, cos_b: float, sin_b: float, hx: float, hy: float,
) -> None:
    """Lower best[robot, k] by ray k's hit on a box of half sizes (hx, hy), the robot at (lx, ly)
    in the box's frame, the box turned by (cos_b, sin_b): the slab test in the box frame."""
    wx, wy = ux[robot, k], uy[robot, k]
    vx, vy = cos_b * wx + sin_b * wy, -sin_b * wx + cos_b * wy  # the ray in the box frame
    ax, bx = (-hx - lx) / vx, (hx - lx) / vx  # where the ray crosses x = -hx and x = hx
    ay, by = (-hy - ly) / vy, (hy - ly) / vy
    near = _fmax(_fmin(ax, bx), _fmin(ay, by))  # entry into both slabs
    far = _fmin(_fmax(ax, bx), _fmax(ay, by))  # exit from either
    if near <= far and far >= 0.0:
        _lower(best, robot, k, _max0(near))


@kernel
def _lower_by_boxes(
    best: np.ndarray, ux: np.ndarray, uy: np.ndarray, headings: np.ndarray, ox: np.ndarray,
    oy: np.ndarray, boxes: np.ndarray, bound: np.ndarray, cos_b: np.ndarray, sin_b: np.ndarray,
    bearing: np.ndarray, range_max: float, angle_min: float, inc: float, full: bool,
) -> None:
    """Lower `best` by ray hits on the box obstacles (B, 5: x, y, half x, half y, yaw) whose
    bounding circle (radius `bound`) is within reach; (cos_b, sin_b) of their yaws, bearing[robot, b]
    [rad] the direction from the robot to the box's centre."""
    window = np.empty(best.shape[1], np.intp)
    for robot in range(len(ox)):
        for b in range(len(boxes)):
            dx = boxes[b, 0] - ox[robot]
            dy = boxes[b, 1] - oy[robot]
            d2 = dx * dx + dy * dy
            reach = range_max + bound[b]
            if not d2 < reach * reach:
                continue
            r2 = bound[b] * bound[b]
            inside = d2 <= r2
            alpha = 0.0 if inside else _half_angle(d2, r2)
            rel = _wrap_positive(bearing[robot, b] - headings[robot] - angle_min)
            px, py = -dx, -dy  # the ray origin relative to the box centre
            lx, ly = cos_b[b] * px + sin_b[b] * py, -sin_b[b] * px + cos_b[b] * py
            for m in range(_window(rel, alpha, inside, inc, full, window)):
                _hit_box(best, ux, uy, robot, window[m], lx, ly, cos_b[b], sin_b[b], boxes[b, 2], boxes[b, 3])


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
    hits = nearest_hits(origins, headings, robot_radius, scene, rays, fov, range_max, pairs)
    return _finish(hits, float(range_min), float(range_max))


def nearest_hits(
    origins: np.ndarray,
    headings: np.ndarray,
    robot_radius: float,
    scene: StaticScene,
    rays: int,
    fov: float,
    range_max: float,
    pairs: RobotPairs | None = None,
) -> np.ndarray:
    """`cast_scan` before its float32 rounding and out-of-range markers: (N, rays) float64, the
    distance [m] to the nearest hit of every ray (the wall at the latest). The tests compare
    these bits: the float32 rounding would hide a change in the last bits."""
    origins = np.asarray(origins, dtype=float)
    headings = np.ascontiguousarray(headings, dtype=float)
    n = len(origins)
    angle_min, inc = scan_angles(rays, fov)
    full = evenly_round(rays, fov)
    range_max = float(range_max)
    ox, oy = origins[:, 0].copy(), origins[:, 1].copy()
    # Ray directions and bearings by numpy: its cos, sin and arctan2 differ from libm's in the
    # last bit now and then, and its arctan2 is ~15x faster than libm's (SIMD).
    angles = headings[:, None] + (angle_min + inc * np.arange(rays))[None, :]
    ux = np.cos(angles)
    uy = np.sin(angles)
    best = _walls(ox, oy, ux, uy, float(scene.half_size))

    if n > 1:
        reach = range_max + robot_radius
        if pairs is not None and pairs.reach != reach:
            raise ValueError(f"the robot pairs are kept for reach {pairs.reach}, the scan needs {reach}")
        i, j, dx, dy, d2 = pairs_in_reach(origins, reach) if pairs is None else pairs(origins)
        if len(i):
            r = float(robot_radius)
            _lower_by_robots(best, ux, uy, headings, i, j, dx, dy, d2, np.arctan2(dy, dx), r * r,
                             angle_min, inc, full)

    if len(scene.circles):
        c = scene.circles
        bearing = np.arctan2(c[None, :, 1] - oy[:, None], c[None, :, 0] - ox[:, None])
        _lower_by_cylinders(best, ux, uy, headings, ox, oy, c, bearing, range_max, angle_min, inc, full)

    if len(scene.boxes):
        b = scene.boxes
        bearing = np.arctan2(b[None, :, 1] - oy[:, None], b[None, :, 0] - ox[:, None])
        _lower_by_boxes(best, ux, uy, headings, ox, oy, b, np.hypot(b[:, 2], b[:, 3]), np.cos(b[:, 4]),
                        np.sin(b[:, 4]), bearing, range_max, angle_min, inc, full)
    return best


@kernel
def _finish(ranges: np.ndarray, range_min: float, range_max: float) -> np.ndarray:
    """(N, rays) float64 [m] rounded to float32, with the REP 117 out-of-range markers: inf at
    or beyond range_max, -inf below range_min (when > 0)."""
    out = np.empty(ranges.shape, np.float32)
    top, bottom = np.float32(range_max), np.float32(range_min)
    for robot in range(ranges.shape[0]):
        for k in range(ranges.shape[1]):
            v = np.float32(ranges[robot, k])
            if v >= top:
                v = np.float32(np.inf)
            elif range_min > 0.0 and v < bottom:
                v = np.float32(-np.inf)
            out[robot, k] = v
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
        hits = pybullet.rayTestBatch(
            ray_from[lo : lo + PYBULLET_BATCH].tolist(),
            ray_to[lo : lo + PYBULLET_BATCH].tolist(),
            numThreads=num_threads,
            physicsClientId=client,
        )
        fraction[lo : lo + len(hits)] = [hit[2] if hit[0] >= 0 else np.inf for hit in hits]
    ranges = start + fraction * (config.range_max - start)
    return _finish(ranges.reshape(n, config.rays), float(config.range_min), float(config.range_max))
