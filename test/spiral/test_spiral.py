"""Spiral planning of DDSA and MDBSA: eqs. (1)-(5) of the MDBSA paper, clipping, coverage, sharing."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from swarm_controllers.spiral.geometry import (
    SpiralPath,
    ddsa_leg_steps,
    ddsa_legs,
    ddsa_path,
    mdbsa_leg_steps,
    mdbsa_legs,
    mdbsa_path,
    region_centers,
    region_side,
    segments_overlap_collinear,
)

GAP = 0.18
DETECTION_RADIUS = 0.13


# ---------------------------------------------------------------- leg lengths, eqs. (1)-(2)

# Hand-computed from eqs. (1)-(2): N = E = i (c=1), (2c-3) r + 2i (c>1); S = W = 2i (c=1), N + r.
DDSA_TABLE = [
    (1, 1, 1, (1, 1, 2, 2)),
    (1, 1, 2, (3, 3, 4, 4)),
    (1, 1, 3, (5, 5, 6, 6)),
    (5, 3, 1, (3, 3, 6, 6)),
    (5, 3, 2, (11, 11, 16, 16)),
    (5, 3, 3, (21, 21, 26, 26)),
    (8, 1, 2, (10, 10, 18, 18)),
    (8, 1, 4, (42, 42, 50, 50)),
    (4, 4, 1, (4, 4, 8, 8)),
    (4, 4, 2, (12, 12, 16, 16)),
]


@pytest.mark.parametrize(("r", "i", "c", "expected"), DDSA_TABLE)
def test_ddsa_leg_steps_match_eqs_1_2(r: int, i: int, c: int, expected: tuple[int, ...]) -> None:
    assert ddsa_leg_steps(r, i, c) == expected


def test_ddsa_legs_are_steps_times_gap_in_circuit_order() -> None:
    legs = ddsa_legs(5, 3, 3, GAP)
    steps = [3, 3, 6, 6, 11, 11, 16, 16, 21, 21, 26, 26]
    assert legs == pytest.approx([s * GAP for s in steps])


@pytest.mark.parametrize(("r", "i", "c"), [(3, 0, 1), (3, 4, 1), (0, 1, 1), (3, 1, 0)])
def test_ddsa_rejects_bad_ids(r: int, i: int, c: int) -> None:
    with pytest.raises(ValueError):
        ddsa_leg_steps(r, i, c)


# ---------------------------------------------------------------- leg lengths, eqs. (4)-(5)

MDBSA_TABLE = [
    (1, 1, (1, 1, 2, 2)),
    (2, 1, (3, 3, 4, 4)),
    (5, 1, (9, 9, 10, 10)),
    (2, 3, (5, 5, 8, 8)),  # the equation as printed, with r kept
    (3, 3, (11, 11, 14, 14)),
]


@pytest.mark.parametrize(("c", "r", "expected"), MDBSA_TABLE)
def test_mdbsa_leg_steps_match_eqs_4_5(c: int, r: int, expected: tuple[int, ...]) -> None:
    assert mdbsa_leg_steps(c, r) == expected


@given(c=st.integers(1, 40))
def test_mdbsa_equals_ddsa_with_one_robot(c: int) -> None:
    """The paper: eqs. (4)-(5) are eqs. (1)-(2) with a single robot."""
    assert mdbsa_leg_steps(c) == ddsa_leg_steps(1, 1, c)


def test_mdbsa_legs_in_metres() -> None:
    assert mdbsa_legs(2, GAP) == pytest.approx([GAP, GAP, 2 * GAP, 2 * GAP, 3 * GAP, 3 * GAP, 4 * GAP, 4 * GAP])


# ---------------------------------------------------------------- DDSA paths


def _seg_lengths_and_headings(path: np.ndarray) -> tuple[np.ndarray, list[tuple[int, int]]]:
    d = np.diff(path, axis=0)
    lengths = np.linalg.norm(d, axis=1)
    heads = [tuple(int(v) for v in np.sign(np.round(x, 9))) for x in d]
    return lengths, heads


@pytest.mark.parametrize(("r", "i"), [(1, 1), (3, 2), (5, 5), (8, 3)])
def test_ddsa_path_walks_the_equation_legs_clockwise(r: int, i: int) -> None:
    path = ddsa_path((0.3, -0.2), r, i, GAP, 100.0, include_shared_stem=True)
    lengths, heads = _seg_lengths_and_headings(path)
    legs = ddsa_legs(r, i, 6, GAP)
    assert np.allclose(path[0], (0.3, -0.2))
    assert lengths[:24] == pytest.approx(legs)
    assert heads[:4] == [(0, 1), (1, 0), (0, -1), (-1, 0)]  # N, E, S, W: clockwise


def test_ddsa_default_path_trims_the_shared_stem() -> None:
    full = ddsa_path((0, 0), 4, 3, GAP, 100.0, include_shared_stem=True)
    trimmed = ddsa_path((0, 0), 4, 3, GAP, 100.0)
    assert trimmed[0] == pytest.approx((0.0, 2 * GAP))
    assert np.allclose(trimmed[1:], full[1:])


@settings(max_examples=60, deadline=None)
@given(
    r=st.integers(1, 10),
    data=st.data(),
    half=st.floats(0.3, 5.0),
    cx=st.floats(-2.0, 2.0),
    cy=st.floats(-2.0, 2.0),
)
def test_ddsa_paths_stay_inside_the_arena(r: int, data: st.DataObject, half: float, cx: float, cy: float) -> None:
    i = data.draw(st.integers(1, r))
    path = ddsa_path((cx, cy), r, i, GAP, half)
    assert np.all(np.abs(path - (cx, cy)) <= half + 1e-9)
    assert len(path) >= 2 or half < i * GAP  # one point: no room left for robot i's ring


@settings(max_examples=25, deadline=None)
@given(r=st.integers(2, 9), half=st.floats(0.3, 4.0))
def test_interlocking_ddsa_spirals_never_share_a_leg(r: int, half: float) -> None:
    paths = [ddsa_path((0.0, 0.0), r, i, GAP, half) for i in range(1, r + 1)]
    for a, b in itertools.combinations(range(r), 2):
        assert not segments_overlap_collinear(paths[a], paths[b]), (r, a + 1, b + 1)


def test_literal_stems_would_share_a_leg() -> None:
    """Control: the untrimmed first legs all run north from the center, so the check can fail."""
    a = ddsa_path((0.0, 0.0), 3, 1, GAP, 2.0, include_shared_stem=True)
    b = ddsa_path((0.0, 0.0), 3, 2, GAP, 2.0, include_shared_stem=True)
    assert segments_overlap_collinear(a, b)


# ---------------------------------------------------------------- MDBSA regions, eq. (3)


def test_region_centers_eq_3() -> None:
    assert region_centers(4, 8.0) == pytest.approx(np.array([[2, 2], [2, -2], [-2, 2], [-2, -2]], dtype=float))
    c16 = region_centers(16, 8.0)
    assert c16[0] == pytest.approx((3.0, 3.0))
    assert c16[1] == pytest.approx((3.0, 1.0))  # column j varies fastest: y
    assert c16[4] == pytest.approx((1.0, 3.0))
    assert c16[15] == pytest.approx((-3.0, -3.0))
    assert region_centers(1, 8.0) == pytest.approx(np.zeros((1, 2)))


@pytest.mark.parametrize("n", [4, 16, 64, 256])
def test_regions_tile_the_arena(n: int) -> None:
    L = 8.0
    centers = region_centers(n, L)
    side = region_side(n, L)
    assert len(centers) == n
    assert len({(round(x, 9), round(y, 9)) for x, y in centers}) == n
    assert np.all(np.abs(centers) + side / 2 <= L / 2 + 1e-9)
    assert n * side**2 == pytest.approx(L * L)


@pytest.mark.parametrize("n", [2, 8, 12, 0])
def test_region_count_must_be_power_of_four(n: int) -> None:
    with pytest.raises(ValueError):
        region_centers(n, 8.0)


# ---------------------------------------------------------------- MDBSA paths


def test_mdbsa_path_follows_eqs_4_5_inside_the_region() -> None:
    path = mdbsa_path((1.0, -3.0), 2.0, GAP)
    lengths, heads = _seg_lengths_and_headings(path)
    assert np.allclose(path[0], (1.0, -3.0))
    assert lengths[:16] == pytest.approx(mdbsa_legs(4, GAP))
    assert heads[:4] == [(0, 1), (1, 0), (0, -1), (-1, 0)]


@settings(max_examples=60, deadline=None)
@given(
    side=st.floats(0.3, 4.0),
    gap=st.floats(0.05, 0.4),
    cx=st.floats(-4.0, 4.0),
    cy=st.floats(-4.0, 4.0),
)
def test_mdbsa_path_stays_in_its_region_and_never_rewalks_a_line(side: float, gap: float, cx: float, cy: float) -> None:
    path = mdbsa_path((cx, cy), side, gap)
    assert np.all(np.abs(path - (cx, cy)) <= side / 2 + 1e-9)
    for m, n in itertools.combinations(range(len(path) - 1), 2):
        assert not segments_overlap_collinear(path[m : m + 2], path[n : n + 2])


def uncovered_fraction(path: np.ndarray, center: np.ndarray, side: float, radius: float, step: float = 0.01) -> float:
    """Fraction of a grid of points (cell centers, `step` apart) in the region farther than
    `radius` from the path: the area the detection discs along the spiral miss."""
    h = side / 2
    xs = np.arange(-h + step / 2, h, step) + center[0]
    ys = np.arange(-h + step / 2, h, step) + center[1]
    gx, gy = np.meshgrid(xs, ys)
    pts = np.stack([gx.ravel(), gy.ravel()], axis=1)
    dist = np.full(len(pts), np.inf)
    for a, b in zip(path[:-1], path[1:]):
        ab = b - a
        t = np.clip(((pts - a) @ ab) / max(float(ab @ ab), 1e-12), 0.0, 1.0)
        dist = np.minimum(dist, np.linalg.norm(pts - (a + t[:, None] * ab), axis=1))
    return float(np.mean(dist > radius))


# Bound: adjacent spiral lines are one gap g = 0.18 m apart and the clipped last ring runs
# along the region's edges, so every point lies within g/2 = 0.09 m < 0.13 m of the path and
# the expected uncovered fraction is exactly 0. The 1e-3 slack only absorbs grid/float
# effects; a single missing wall strip would already cost >= 0.05 m / 1 m = 5 % of the
# smallest (64-region, 1 m) region, far above it.
UNCOVERED_BOUND = 1e-3


@pytest.mark.parametrize("n_regions", [4, 16, 64])
def test_detection_discs_cover_each_region(n_regions: int) -> None:
    L = 8.0
    side = region_side(n_regions, L)
    centers = region_centers(n_regions, L)
    first = mdbsa_path(centers[0], side, GAP)
    worst = uncovered_fraction(first, centers[0], side, DETECTION_RADIUS)
    assert worst <= UNCOVERED_BOUND
    # Every region's spiral is the same spiral translated, so the same coverage holds for all.
    for c in centers[1:]:
        assert np.allclose(mdbsa_path(c, side, GAP) - c, first - centers[0])


def test_coverage_check_detects_a_too_wide_gap() -> None:
    """Control: with g = 0.30 m > 2 x 0.13 m strips between lines go unseen."""
    c = np.zeros(2)
    assert uncovered_fraction(mdbsa_path(c, 2.0, 0.30), c, 2.0, DETECTION_RADIUS) > 0.05


# ---------------------------------------------------------------- SpiralPath


def test_spiral_path_length_and_ends() -> None:
    wps = mdbsa_path((0.0, 0.0), 2.0, GAP)
    sp = SpiralPath(wps)
    assert sp.length == pytest.approx(float(np.sum(np.linalg.norm(np.diff(wps, axis=0), axis=1))))
    assert sp.point_at(0.0) == pytest.approx(wps[0])
    assert sp.point_at(sp.length) == pytest.approx(wps[-1])
    assert sp.point_at(-5.0) == pytest.approx(wps[0])
    assert sp.point_at(sp.length + 5.0) == pytest.approx(wps[-1])
    assert sp.point_at(1.5 * GAP) == pytest.approx((0.5 * GAP, GAP))  # half-way along the first E leg
    with pytest.raises(ValueError):
        sp.waypoints[0, 0] = 1.0  # shared between robots: read-only


@settings(max_examples=50, deadline=None)
@given(frac=st.floats(0.0, 1.0))
def test_walking_from_either_end(frac: float) -> None:
    """Two robots on one region's spiral: one at s from the start, the other at s' from the end;
    they meet where s + s' = length."""
    sp = SpiralPath(mdbsa_path((1.0, 1.0), 2.0, GAP))
    rev = sp.reversed()
    assert rev.length == pytest.approx(sp.length)
    s = frac * sp.length
    assert rev.point_at(sp.length - s) == pytest.approx(sp.point_at(s), abs=1e-9)
    assert rev.start == pytest.approx(sp.end)
    assert rev.reversed().waypoints == pytest.approx(sp.waypoints)


def test_next_waypoint_index() -> None:
    sp = SpiralPath(np.array([[0.0, 0.0], [0.0, 1.0], [1.0, 1.0]]))
    assert sp.next_waypoint_index(0.0) == 1
    assert sp.next_waypoint_index(0.5) == 1
    assert sp.next_waypoint_index(1.0) == 2
    assert sp.next_waypoint_index(2.0) == 3
