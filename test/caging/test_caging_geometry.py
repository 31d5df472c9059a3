"""The caging paper's geometry against hand-computed values: eqs. (1), (2), (5), Delta, the
landmark grid (Alg. 2) and the scenario checks that quote them."""

from __future__ import annotations

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from swarm_controllers.caging import geometry
from swarm_controllers.caging.landmarks import landmarks
from swarm_sim.scenario import ScenarioError, load_scenario

W, R, C, EPS = 0.13, 0.3, 0.01, 0.01
"""Khepera III width, the paper's object radius, c of Table 1, our epsilon."""


def test_eq1_rho_min_is_object_over_robot_mass_at_equal_accelerations():
    # M A / (m a) with A = a: 0.3 / 0.69 and 1.0 / 0.69
    assert geometry.rho_min(0.3, 0.69) == pytest.approx(0.434783, abs=1e-6)
    assert geometry.rho_min(1.0, 0.69) == pytest.approx(1.449275, abs=1e-6)
    assert geometry.rho_min(1.0, 0.5, acceleration_ratio=2.0) == pytest.approx(4.0)


def test_eq2_theta_min_by_hand():
    # half chord w/2 + eps/2 = 0.07 m, hypotenuse w/2 + r = 0.365 m:
    # tan(theta/2) = 0.07 / sqrt(0.365^2 - 0.07^2) = 0.07 / 0.358225 = 0.195408
    # theta = 2 atan(0.195408) = 0.385953 rad = 22.1135 deg, so 360 / 22.1135 = 16.28: 16 robots
    theta = geometry.theta_min(W, R, EPS)
    assert theta == pytest.approx(0.385953, abs=1e-6)
    assert math.degrees(theta) == pytest.approx(22.1135, abs=1e-4)
    assert geometry.max_robots(W, R, EPS) == 16
    assert geometry.max_robots(W, 0.45, EPS) == 23  # a larger object holds more robots


def test_eq5_cage_positions_by_hand():
    # (r + w) + c = 0.44 m, at i phi = 2 x 45 deg = 90 deg around (1, 2)
    x, y = geometry.cage_position((1.0, 2.0), 2, 8, R, W, C)
    assert (x, y) == pytest.approx((1.0, 2.44))
    x, y = geometry.cage_position((0.0, 0.0), 1, 6, R, W, C)  # 60 deg
    assert (x, y) == pytest.approx((0.22, 0.44 * math.sqrt(3) / 2))
    assert geometry.cage_angle(8) == pytest.approx(math.pi / 4)
    assert geometry.approach_distance(R, W, 0.6) == pytest.approx(0.965)  # Delta = r + w/2 + 0.6


@given(st.floats(-3, 3), st.floats(-3, 3), st.floats(-math.pi, math.pi))
def test_cage_route_stays_on_the_ring_and_ends_at_the_slot_angle(x, y, slot):
    center = (0.2, -0.1)
    if math.hypot(x - center[0], y - center[1]) < 1e-6:
        return
    ring = geometry.travel_radius(R, W, C)
    route = geometry.cage_route((x, y), center, slot, ring)
    angles = [math.atan2(py - center[1], px - center[0]) for px, py in route]
    assert all(math.hypot(px - center[0], py - center[1]) == pytest.approx(ring) for px, py in route)
    assert math.remainder(angles[-1] - slot, 2 * math.pi) == pytest.approx(0, abs=1e-9)
    assert math.remainder(angles[0] - math.atan2(y - center[1], x - center[0]), 2 * math.pi) == pytest.approx(0, abs=1e-9)
    steps = [abs(math.remainder(b - a, 2 * math.pi)) for a, b in zip(angles, angles[1:])]
    assert all(s <= geometry.MAX_ARC + 1e-9 for s in steps)
    # it passes placed robots (at the cage radius) and the object with room to spare
    assert ring - geometry.cage_radius(R, W, C) > W


def test_landmark_counts_and_neighbourhoods():
    """The paper reports 255 landmarks for step 0.5 m and 72 for 1 m (sec. 5): our 8 x 7 m grid
    gives 17 x 15 and 9 x 8; the full 10 x 10 m arena would give 21 x 21 and 11 x 11."""
    fine = landmarks(load_scenario("caging"))
    coarse = landmarks(load_scenario("caging", ["transport.landmarks.step=1.0"]))
    assert (len(fine), len(coarse)) == (255, 72)
    full = landmarks(load_scenario("caging", ["transport.landmarks.extent=[10.0, 10.0]", "arena.size=12"]))
    assert len(full) == 441
    assert fine.points[:, 0].min() == -4.0 and fine.points[:, 1].max() == 3.5
    corner, inner = fine.neighbours[0], fine.neighbours[17 + 1]
    assert len(corner) == 3 and len(inner) == 8
    for i, eta in enumerate(fine.neighbours):
        for j in eta:
            step = math.dist(fine.points[i], fine.points[j])
            assert step == pytest.approx(0.5) or step == pytest.approx(0.5 * math.sqrt(2))
            assert i in fine.neighbours[j]


@pytest.mark.parametrize(("overrides", "message"), [
    (["robots.count=17"], r"17 robots do not fit around the object: phi = 360/17 = 21.18 deg < theta_min = 22.11 deg"),
    (["robots.count=1", "transport.object.mass=1.0"], r"eq. \(1\) needs rho_min = M A / \(m a\) = 1.0 x 1 / 0.69 = 1.449"),
    (["transport.landmarks.extent=[9.0, 7.0]"], r"transport.landmarks.extent: a cage around an edge landmark"),
    (["sensors.position_range=0.3"], r"sensors.position_range: 0.3 m is less than 0.565 m"),
    (["controller.caging.call_timeout=0"], r"controller.caging.call_timeout: must be positive"),
])
def test_impossible_caging_scenarios_are_refused_with_the_numbers(overrides, message):
    with pytest.raises(ScenarioError, match=message):
        load_scenario("caging", overrides)


def test_the_paper_swarms_are_accepted():
    for count, radius, mass in ((6, 0.3, 0.3), (7, 0.3, 0.3), (8, 0.3, 0.3), (8, 0.4, 0.7), (8, 0.45, 1.0)):
        load_scenario("caging", [f"robots.count={count}", f"transport.object.radius={radius}",
                                 f"transport.object.mass={mass}"])
