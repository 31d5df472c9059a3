"""The proximity ring's collision detection (the papers' collision time)."""

import math

import numpy as np
from generic_robot import generic_scenario
from hypothesis import given, settings
from hypothesis import strategies as st

from swarm_sim.world.proximity import ProximityRing
from swarm_sim.world.raycast import scan_angles

SCENARIO = generic_scenario("queue_cpfa")
RING = ProximityRing(SCENARIO)
BODY = SCENARIO.robots.diameter / 2
RAYS = SCENARIO.sensors.scan.rays
START, INC = scan_angles(RAYS, SCENARIO.sensors.scan.fov)


def _scan(hits: dict[float, float]) -> np.ndarray:
    """One robot's scan with the ray nearest each bearing [deg] hitting at that gap beyond the body."""
    row = np.full(RAYS, np.inf)
    for bearing, gap in hits.items():
        k = round((math.radians(bearing) - START) / INC) % RAYS
        row[k] = BODY + gap
    return row[None, :]


def test_ahead_side_behind_and_out_of_range():
    assert RING.ahead(_scan({0.0: 0.05}))[0]
    assert RING.ahead(_scan({60.0: 0.09}))[0]
    assert not RING.ahead(_scan({90.0: 0.05}))[0]  # beside: the CPFA's +-80 deg leave it out
    assert not RING.ahead(_scan({180.0: 0.01}))[0]
    assert not RING.ahead(_scan({0.0: 0.15}))[0]  # beyond the foot-bot's 0.1 m
    assert not RING.ahead(_scan({}))[0]


def test_mean_vector_not_any_ray():
    # A near wall behind outweighs a faint reading ahead: the mean vector points back.
    assert not RING.ahead(_scan({0.0: 0.099, 165.0: 0.0, -165.0: 0.0}))[0]


@given(st.floats(-180, 180), st.floats(0.0, 0.1))
def test_one_reading_counts_iff_within_the_ahead_angle(bearing, gap):
    k = round((math.radians(bearing) - START) / INC) % RAYS
    angle = math.degrees(math.remainder(START + k * INC, 2 * math.pi))
    assert RING.ahead(_scan({bearing: gap}))[0] == (abs(angle) <= SCENARIO.sensors.proximity_ring.ahead + 1e-9)


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(1, 300), near=st.floats(0.0, 1.0))
def test_readings_are_those_of_the_whole_ring_formula(seed, n, near):
    """The readings, computed for the rays that hit only, give bit for bit the mean vector of
    exp(-gap) over every ray (0 where nothing is within range) that the ring's rule is stated in."""
    rng = np.random.default_rng(seed)
    ranges = rng.uniform(0.0, 0.4, (n, RAYS))
    ranges[rng.uniform(size=ranges.shape) > near] = np.inf
    ranges[rng.uniform(size=ranges.shape) < 0.02] = -np.inf
    ranges = ranges.astype(np.float32)
    d = ranges.astype(float) - BODY
    with np.errstate(invalid="ignore"):
        hit = d <= RING._range
        value = np.where(hit, np.exp(-np.maximum(d, 0.0)), 0.0)
    assert np.exp(-np.maximum(d[hit], 0.0)).tobytes() == value[hit].tobytes()  # what the ring relies on
    x, y = value @ RING._cos, value @ RING._sin
    norm = np.hypot(x, y)
    want = (norm > 0.0) & (x >= RING._cos_ahead * norm)
    assert np.array_equal(RING.ahead(ranges), want)
