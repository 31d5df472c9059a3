"""The analytic batched scan: hand-computed cases, a brute-force reference, and pybullet."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from generic_robot import generic_scenario
from hypothesis import given, settings
from hypothesis import strategies as st

from swarm_msgs_py.types import Pose2D
from swarm_sim.registry import task_factory
from swarm_sim.scenario import ObstacleConfig, ScanConfig
from swarm_sim.world import World
from swarm_sim.world.raycast import StaticScene, cast_scan, cast_scan_pybullet, nearest_hits, scan_angles

R = 0.085  # robot radius [m]
OPEN = StaticScene(6.0, np.zeros((0, 3)), np.zeros((0, 5)))
FULL = 2 * math.pi


def scan(origins, headings, rays=4, fov=FULL, range_max=12.0, range_min=0.0, scene=OPEN):
    origins, headings = np.array(origins, float), np.array(headings, float)
    return cast_scan(origins, headings, R, scene, rays, fov, range_max, range_min)


# --------------------------------------------------------------------------- conventions


def test_scan_angles_match_the_laserscan_codec():
    from swarm_msgs_py.scan import scan_geometry

    for rays, fov in [(24, FULL), (4, FULL), (5, math.pi), (2, 1.0), (1, 1.0), (1, FULL)]:
        g = scan_geometry(ScanConfig(rays=rays, fov=fov))
        assert scan_angles(rays, fov) == (g.angle_min, g.angle_increment)
    assert scan_angles(4, FULL) == (-math.pi, math.pi / 2)
    assert scan_angles(3, math.pi) == (-math.pi / 2, math.pi / 2)


def test_ranges_are_float32_one_row_per_robot():
    out = scan([[0.0, 0.0], [1.0, 1.0]], [0.0, 0.0], rays=7)
    assert out.dtype == np.float32 and out.shape == (2, 7)


# --------------------------------------------------------------------------- hand-computed


def test_robot_facing_a_wall():
    # rays at -pi, -pi/2, 0, +pi/2 from the heading (+x); walls at |x|, |y| = 6
    out = scan([[4.0, 0.0]], [0.0])
    np.testing.assert_allclose(out[0], [10.0, 6.0, 2.0, 6.0], rtol=1e-6)


def test_heading_rotates_the_scan():
    out = scan([[0.0, 5.0]], [math.pi / 2])  # facing +y: ray 2 hits y = 6 after 1 m
    np.testing.assert_allclose(out[0], [11.0, 6.0, 1.0, 6.0], rtol=1e-6)


def test_beyond_range_max_is_inf_and_just_inside_is_not():
    out = scan([[4.0, 0.0]], [0.0], range_max=2.0)  # the wall is exactly range_max away
    assert np.all(np.isinf(out)) and np.all(out > 0)
    out = scan([[4.0, 0.0]], [0.0], range_max=2.001)
    assert out[0, 2] == pytest.approx(2.0) and np.isinf(out[0, [0, 1, 3]]).all()


def test_below_range_min_is_minus_inf():
    out = scan([[0.0, 0.0], [0.3, 0.0]], [0.0, 0.0], range_min=0.25)
    assert out[0, 2] == -np.inf  # the other robot's surface is 0.215 m away
    assert out[0, 0] == pytest.approx(6.0)


def test_robot_in_front_and_behind():
    out = scan([[0.0, 0.0], [1.0, 0.0]], [0.0, 0.0], range_max=3.0)
    assert out[0, 2] == pytest.approx(1.0 - R)  # robot 1 ahead of robot 0
    assert out[1, 0] == pytest.approx(1.0 - R)  # robot 0 behind robot 1 (ray at -pi)
    assert np.isinf(out[0, [0, 1, 3]]).all()


def test_own_body_is_not_seen():
    out = scan([[0.0, 0.0]], [0.3], rays=24, range_max=1.0)
    assert np.all(np.isinf(out))


def test_off_axis_hit_on_a_circle():
    # ray 2 (along +x) passes 0.05 m beside a robot at (1, 0.05): hit at 1 - sqrt(r^2 - 0.05^2)
    out = scan([[0.0, 0.0], [1.0, 0.05]], [0.0, 0.0], range_max=3.0)
    assert out[0, 2] == pytest.approx(1.0 - math.sqrt(R**2 - 0.05**2), abs=1e-6)
    out = scan([[0.0, 0.0], [1.0, 0.09]], [0.0, 0.0], range_max=3.0)
    assert np.isinf(out[0, 2])  # misses by 5 mm


def test_obstacles():
    cylinder = StaticScene(6.0, np.array([[2.0, 0.0, 0.3]]), np.zeros((0, 5)))
    assert scan([[0.0, 0.0]], [0.0], scene=cylinder)[0, 2] == pytest.approx(1.7)
    box = StaticScene(6.0, np.zeros((0, 3)), np.array([[2.0, 0.0, 0.5, 0.25, 0.0]]))
    assert scan([[0.0, 0.0]], [0.0], scene=box)[0, 2] == pytest.approx(1.5)
    assert scan([[2.0, 1.0]], [0.0], scene=box)[0, 1] == pytest.approx(0.75)  # ray at -pi/2
    diamond = StaticScene(6.0, np.zeros((0, 3)), np.array([[2.0, 0.0, 0.5, 0.5, math.pi / 4]]))
    assert scan([[0.0, 0.0]], [0.0], scene=diamond)[0, 2] == pytest.approx(2.0 - math.sqrt(0.5))


def test_partial_fov():
    # fov pi, 3 rays: -pi/2, 0, +pi/2; nothing behind is seen
    out = scan([[4.0, 0.0], [3.0, 0.0]], [0.0, 0.0], rays=3, fov=math.pi)
    np.testing.assert_allclose(out[0], [6.0, 2.0, 6.0], rtol=1e-6)  # robot 1 is behind
    np.testing.assert_allclose(out[1], [6.0, 1.0 - R, 6.0], rtol=1e-6)


# --------------------------------------------------------------------------- brute force


def _segments(scene: StaticScene, inflate: float) -> np.ndarray:
    h = scene.half_size - inflate
    segs = [(h, -h, h, h), (-h, -h, -h, h), (-h, h, h, h), (-h, -h, h, -h)]
    for x, y, hx, hy, yaw in scene.boxes:
        c, s = math.cos(yaw), math.sin(yaw)
        hx, hy = hx + inflate, hy + inflate
        signs = ((-1, -1), (1, -1), (1, 1), (-1, 1))
        corners = [(x + c * a * hx - s * b * hy, y + s * a * hx + c * b * hy) for a, b in signs]
        segs += [(*corners[k], *corners[(k + 1) % 4]) for k in range(4)]
    return np.array(segs)


def reference_scan(origins, headings, scene, rays, fov, range_max, inflate=0.0):
    """Every ray against every circle and every segment, one at a time, with every shape grown
    by `inflate` [m] (shrunk if negative)."""
    angle_min, inc = scan_angles(rays, fov)
    circles = [(x, y, r + inflate) for x, y, r in scene.circles]
    segs = _segments(scene, inflate)
    out = np.full((len(origins), rays), np.inf)
    for i, (ox, oy) in enumerate(origins):
        others = [(x, y, R + inflate) for k, (x, y) in enumerate(origins) if k != i]
        for k in range(rays):
            a = headings[i] + angle_min + k * inc
            ux, uy = math.cos(a), math.sin(a)
            best = math.inf
            for cx, cy, r in others + circles:
                along = (cx - ox) * ux + (cy - oy) * uy
                disc = r * r - ((cx - ox) ** 2 + (cy - oy) ** 2 - along * along)
                if disc >= 0 and along > 0:
                    best = min(best, along - math.sqrt(disc))
            for x0, y0, x1, y1 in segs:
                ex, ey = x1 - x0, y1 - y0
                den = ux * ey - uy * ex
                if abs(den) < 1e-15:
                    continue
                t = ((x0 - ox) * ey - (y0 - oy) * ex) / den
                s = ((x0 - ox) * uy - (y0 - oy) * ux) / den
                if t >= 0 and -1e-12 <= s <= 1 + 1e-12:
                    best = min(best, t)
            out[i, k] = best
    out[out >= range_max] = np.inf
    return out


def random_scene(rng: np.random.Generator, n: int, crowd: bool):
    obstacles = StaticScene(
        6.0,
        np.array([[-2.0, -1.5, 0.3], [3.5, -3.5, 0.2]]),
        np.array([[2.0, 1.0, 0.5, 0.2, 0.7], [-3.0, 3.0, 0.15, 1.0, -0.3]]),
    )
    keep_out = [(-2.0, -1.5, 0.45), (3.5, -3.5, 0.35), (2.0, 1.0, 0.7), (-3.0, 3.0, 1.2)]
    pts: list[np.ndarray] = []
    spread = 1.2 if crowd else 5.8
    while len(pts) < n:
        q = rng.uniform(-spread, spread, 2)
        if all(np.hypot(*(q - p)) > 2 * R + 0.01 for p in pts) and all(
            math.hypot(q[0] - x, q[1] - y) > r for x, y, r in keep_out
        ):
            pts.append(q)
    return np.array(pts), rng.uniform(-math.pi, math.pi, n), obstacles


@settings(max_examples=25, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    n=st.integers(1, 25),
    crowd=st.booleans(),
    rays=st.sampled_from([1, 2, 5, 24]),
    fov=st.sampled_from([FULL, math.pi, 4.0, 6.2]),
)
def test_batched_scan_equals_brute_force(seed, n, crowd, rays, fov):
    rng = np.random.default_rng(seed)
    origins, headings, scene = random_scene(rng, n, crowd)
    got = cast_scan(origins, headings, R, scene, rays, fov, 3.5)
    want = reference_scan(origins, headings, scene, rays, fov, 3.5)
    np.testing.assert_allclose(got, want.astype(np.float32), rtol=1e-6, atol=1e-6)


@settings(max_examples=15, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(2, 60), crowd=st.booleans(),
       range_max=st.sampled_from([0.3, 1.0, 3.5]))
def test_kd_tree_pairs_give_the_all_pairs_scan_bit_for_bit(seed, n, crowd, range_max):
    """Large swarms find robot pairs with a k-d tree, small ones test all pairs: same ranges."""
    import swarm_sim.world.pairs as pairs

    rng = np.random.default_rng(seed)
    origins, headings, scene = random_scene(rng, n, crowd)
    with pytest.MonkeyPatch.context() as m:
        m.setattr(pairs, "KD_TREE_FROM", 10**9)
        all_pairs = cast_scan(origins, headings, R, scene, 24, FULL, range_max)
        m.setattr(pairs, "KD_TREE_FROM", 2)
        tree = cast_scan(origins, headings, R, scene, 24, FULL, range_max)
    assert all_pairs.tobytes() == tree.tobytes()


def exact_reference_scan(origins, headings, scene, rays, fov, range_max, range_min=0.0):
    """`cast_scan`'s ranges from `exact_reference_hits`, rounded and marked in numpy."""
    out = exact_reference_hits(origins, headings, scene, rays, fov, range_max).astype(np.float32)
    out[out >= np.float32(range_max)] = np.inf
    if range_min > 0.0:
        out[out < np.float32(range_min)] = -np.inf
    return out


def exact_reference_hits(origins, headings, scene, rays, fov, range_max):
    """`nearest_hits`'s own arithmetic on every ray against every shape, in numpy, without its
    shortcuts (pairs in reach, angular windows, the nearest-ray path, the compiled loops): what
    it must equal bit for bit, in float64. A shape counts if its bounding circle is within reach,
    as in the scan."""
    angle_min, inc = scan_angles(rays, fov)
    angles = headings[:, None] + (angle_min + inc * np.arange(rays))[None, :]
    ux, uy = np.cos(angles), np.sin(angles)  # (n, rays)
    ox, oy = origins[:, 0], origins[:, 1]
    h = scene.half_size
    with np.errstate(divide="ignore", invalid="ignore"):
        best = np.maximum(np.fmin((np.copysign(h, ux) - ox[:, None]) / ux, (np.copysign(h, uy) - oy[:, None]) / uy), 0.0)

    def lower(t, valid):  # t, valid: (n, shapes, rays)
        nonlocal best
        best = np.minimum(best, np.where(valid, t, np.inf).min(axis=1, initial=np.inf))

    # circles: the other robots and the cylinders (x, y, radius)
    n = len(origins)
    c = np.concatenate([np.column_stack([ox, oy, np.full(n, R)]), scene.circles])
    dx, dy = c[None, :, 0] - ox[:, None], c[None, :, 1] - oy[:, None]
    d2 = dx * dx + dy * dy
    r2 = c[:, 2] * c[:, 2]
    reach = (range_max + c[:, 2]) ** 2
    counts = (d2 < reach) & ~np.eye(n, len(c), dtype=bool)
    along = dx[..., None] * ux[:, None, :] + dy[..., None] * uy[:, None, :]
    disc = r2[None, :, None] - d2[..., None] + along * along
    inside = (d2 <= r2)[..., None]
    hit = (disc >= 0.0) & ((along > 0.0) | inside) & counts[..., None]
    with np.errstate(invalid="ignore"):
        lower(np.maximum(along - np.sqrt(disc), 0.0), hit)

    # boxes (x, y, half x, half y, yaw): slab test in the box frame
    b = scene.boxes
    bound = np.hypot(b[:, 2], b[:, 3])
    dx, dy = b[None, :, 0] - ox[:, None], b[None, :, 1] - oy[:, None]
    counts = dx * dx + dy * dy < (range_max + bound) ** 2
    cos_b, sin_b = np.cos(b[:, 4])[None, :, None], np.sin(b[:, 4])[None, :, None]
    px, py = -dx[..., None], -dy[..., None]
    lx, ly = cos_b * px + sin_b * py, -sin_b * px + cos_b * py
    wx, wy = ux[:, None, :], uy[:, None, :]
    vx, vy = cos_b * wx + sin_b * wy, -sin_b * wx + cos_b * wy
    hx, hy = b[None, :, 2, None], b[None, :, 3, None]
    with np.errstate(divide="ignore", invalid="ignore"):
        ax, bx = (-hx - lx) / vx, (hx - lx) / vx
        ay, by = (-hy - ly) / vy, (hy - ly) / vy
    near = np.fmax(np.fmin(ax, bx), np.fmin(ay, by))
    far = np.fmin(np.fmax(ax, bx), np.fmax(ay, by))
    lower(np.maximum(near, 0.0), (near <= far) & (far >= 0.0) & counts[..., None])
    return best


def crowded_scene(rng: np.random.Generator, n: int, spread: float):
    """Robots anywhere in a square of side 2 spread, overlapping ones and exact copies included:
    every kind of robot pair (far, near, touching, one inside the other, coincident)."""
    origins = rng.uniform(-spread, spread, (n, 2))
    copies = rng.integers(0, n, n // 4)
    origins[rng.integers(0, n, n // 4)] = origins[copies]
    return origins, rng.uniform(-math.pi, math.pi, n)


@settings(max_examples=40, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    n=st.integers(2, 40),
    spread=st.sampled_from([0.2, 1.0, 3.0, 5.8]),
    rays=st.sampled_from([1, 3, 8, 24, 36]),
    fov=st.sampled_from([FULL, math.pi, 6.2]),
    range_max=st.sampled_from([0.14, 1.0, 3.5]),
    scene=st.sampled_from(["open", "obstacles"]),
)
def test_scan_is_its_own_arithmetic_on_every_ray_bit_for_bit(seed, n, spread, rays, fov, range_max, scene):
    """The windows and the nearest-ray path only choose which rays the exact test sees: never
    one that would hit less, so the ranges are bit for bit those of testing every ray."""
    rng = np.random.default_rng(seed)
    origins, headings = crowded_scene(rng, n, spread)
    static = OPEN if scene == "open" else random_scene(rng, 1, False)[2]
    hits = nearest_hits(origins, headings, R, static, rays, fov, range_max)
    assert hits.tobytes() == exact_reference_hits(origins, headings, static, rays, fov, range_max).tobytes()
    got = cast_scan(origins, headings, R, static, rays, fov, range_max, 0.05)
    want = exact_reference_scan(origins, headings, static, rays, fov, range_max, 0.05)
    assert got.tobytes() == want.tobytes()


@settings(max_examples=30, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    rays=st.sampled_from([4, 24, 36]),
    fov=st.sampled_from([FULL, math.pi, 6.2]),
    distance=st.sampled_from([0.2, 0.5, 1.0, 3.0, 3.58, "one ray"]),
)
def test_rays_grazing_a_robot_are_their_own_arithmetic_bit_for_bit(seed, rays, fov, distance):
    """Robots placed where the windows' edges are: each ray of robot 0 aimed at another robot's
    centre, or grazing its edge (tangent, or a hair inside or outside), or passing exactly between
    two rays, at distances around the nearest-ray path's limit and at the edge of reach."""
    rng = np.random.default_rng(seed)
    angle_min, inc = scan_angles(rays, fov)
    if distance == "one ray":  # a robot a ray apart from the bearing is hit just closer than this
        distance = R / math.sin(inc / 2) * rng.choice([0.999, 1.0, 1.001, 1.04])
    heading = rng.uniform(-math.pi, math.pi)
    angles = heading + angle_min + inc * rng.integers(0, rays, 12)
    tangent = math.asin(R / distance)
    offsets = rng.choice([0.0, tangent, -tangent, 0.5 * inc, tangent * (1 + 1e-12), tangent * (1 - 1e-12)],
                         12)
    d = distance * rng.choice([1.0, 1.0 + 1e-15, 1.0 - 1e-15], 12)
    others = np.column_stack([d * np.cos(angles + offsets), d * np.sin(angles + offsets)])
    origins = np.vstack([[[0.0, 0.0]], others])
    headings = np.concatenate([[heading], rng.uniform(-math.pi, math.pi, 12)])
    hits = nearest_hits(origins, headings, R, OPEN, rays, fov, 3.5)
    assert hits.tobytes() == exact_reference_hits(origins, headings, OPEN, rays, fov, 3.5).tobytes()


def test_the_exact_reference_agrees_with_the_brute_force_one():
    """The bit-for-bit reference above is itself right (against the scalar brute force)."""
    rng = np.random.default_rng(5)
    origins, headings, scene = random_scene(rng, 20, crowd=True)
    want = reference_scan(origins, headings, scene, 24, FULL, 3.5)
    got = exact_reference_scan(origins, headings, scene, 24, FULL, 3.5)
    np.testing.assert_allclose(got, want.astype(np.float32), rtol=1e-6, atol=1e-6)


# --------------------------------------------------------------------------- pybullet


def _world_with(scene: StaticScene, n: int, rays: int, backend: str = "analytic") -> World:
    cylinders = [ObstacleConfig("cylinder", (x, y), (2 * r, 2 * r)) for x, y, r in scene.circles]
    boxes = [ObstacleConfig("box", (x, y), (2 * hx, 2 * hy), yaw) for x, y, hx, hy, yaw in scene.boxes]
    obstacles = (*cylinders, *boxes)
    s = generic_scenario("cpfa", robots__count=n, sensors__scan__rays=rays, sensors__scan__backend=backend)
    s = dataclasses.replace(s, obstacles=obstacles)
    return World(s, task_factory(s))


BULLET_TOLERANCE = 2e-3
"""pybullet's convex ray cast (GJK) stops within ~1 mm of a surface, its shapes carry a 1 mm
collision margin: its hit lies between those of the scene grown and shrunk by this [m]."""


@pytest.mark.parametrize("seed", range(4))
def test_pybullet_backend_agrees_with_the_analytic_one(seed):
    """Within 1e-3 m on nearly every ray; the rest (grazing rays, where pybullet's ~1 mm surface
    tolerance moves the hit a long way along the ray) must be explained by that tolerance."""
    rng = np.random.default_rng(seed)
    origins, headings, scene = random_scene(rng, 30, crowd=seed % 2 == 1)
    world = _world_with(scene, 30, 36)
    try:
        world.teleport({r: Pose2D(*origins[i], headings[i]) for i, r in enumerate(world.robots)})
        pos = np.array([[q.x, q.y] for q in world.true_poses().values()])
        yaw = np.array([q.yaw for q in world.true_poses().values()])
        sc = world.scenario.sensors.scan
        static = StaticScene.from_scenario(world.scenario)
        analytic = cast_scan(pos, yaw, R, static, sc.rays, sc.fov, sc.range_max)
        bullet = cast_scan_pybullet(world.client, pos, yaw, world.scenario.robots.height / 2, R, sc)
    finally:
        world.close()
    finite = np.isfinite(analytic)
    assert finite.sum() > 0.3 * analytic.size
    same = (np.isinf(analytic) & np.isinf(bullet)) | (
        finite & (np.abs(np.where(finite, analytic, 0) - np.where(finite, bullet, 0)) <= 1e-3)
    )
    assert same.mean() > 0.9
    grown = reference_scan(pos, yaw, scene, sc.rays, sc.fov, sc.range_max, inflate=BULLET_TOLERANCE)
    shrunk = reference_scan(pos, yaw, scene, sc.rays, sc.fov, sc.range_max, inflate=-BULLET_TOLERANCE)
    assert np.all(bullet >= grown - 1e-5)
    assert np.all(bullet <= shrunk + 1e-5)
    assert np.all((grown <= analytic) & (analytic <= shrunk))


def test_world_observations_use_the_configured_backend():
    """The world's own tick-0 scans with either backend (same seed, so the same start)."""
    out, poses = {}, None
    for backend in ("analytic", "pybullet"):
        s = generic_scenario("cpfa", robots__count=9, sensors__scan__backend=backend)
        with World(s, task_factory(s)) as w:
            out[backend] = np.stack([o.ranges for o in w.reset().values()])
            poses = list(w.true_poses().values())
    pos = np.array([[q.x, q.y] for q in poses])
    yaw = np.array([q.yaw for q in poses])
    sc = s.sensors.scan
    want = reference_scan(pos, yaw, OPEN, sc.rays, sc.fov, sc.range_max)
    np.testing.assert_allclose(out["analytic"], want.astype(np.float32), rtol=1e-6, atol=1e-6)
    bullet = out["pybullet"]
    assert not np.array_equal(bullet, out["analytic"])  # really the other backend
    grown = reference_scan(pos, yaw, OPEN, sc.rays, sc.fov, sc.range_max, BULLET_TOLERANCE)
    shrunk = reference_scan(pos, yaw, OPEN, sc.rays, sc.fov, sc.range_max, -BULLET_TOLERANCE)
    assert np.all(bullet >= grown - 1e-5) and np.all(bullet <= shrunk + 1e-5)


def test_pybullet_threads_do_not_change_the_scan():
    s = generic_scenario("cpfa", robots__count=16, sensors__scan__backend="pybullet")
    one, two = World(s, task_factory(s), scan_threads=1), World(s, task_factory(s), scan_threads=2)
    try:
        a, b = one.reset(), two.reset()
        assert all(np.array_equal(a[r].ranges, b[r].ranges) for r in one.robots)
    finally:
        one.close()
        two.close()
