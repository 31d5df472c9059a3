"""Resource placement: counts, validity, cluster geometry, determinism, impossible layouts."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from swarm_sim.scenario import ArenaConfig, DepotConfig, ResourceConfig, ScenarioError
from swarm_sim.sites import drop_zones, zones_clear_of_resources
from swarm_sim.world.resources import place_one, place_resources, powerlaw_pile_sizes, powerlaw_tiers

ARENA = ArenaConfig(size=12.0)
DEPOT = DepotConfig(center=(0.0, 0.0), radius=0.5)


def rng(seed: int = 0) -> np.random.Generator:
    return np.random.default_rng(seed)


def assert_valid(
    xy: np.ndarray, cfg: ResourceConfig, arena: ArenaConfig = ARENA, depot: DepotConfig = DEPOT
) -> None:
    half = arena.size / 2 - cfg.margin
    assert np.all(np.abs(xy) <= half + 1e-9), "outside the arena margin"
    d = np.hypot(xy[:, 0] - depot.center[0], xy[:, 1] - depot.center[1])
    assert np.all(d >= depot.radius + cfg.min_depot_clearance - 1e-9), "too close to the depot"


def test_clustered_default_is_five_disjoint_8x8_grids():
    cfg = ResourceConfig()
    xy = place_resources(cfg, ARENA, DEPOT, rng())
    assert xy.shape == (320, 2)
    assert_valid(xy, cfg)
    clusters = xy.reshape(5, 64, 2)
    boxes = []
    for c in clusters:
        # an 8 x 8 grid of pitch 0.1 m: 8 distinct x and 8 distinct y values, 0.1 m apart
        for axis in (0, 1):
            values = np.unique(np.round(c[:, axis], 9))
            assert len(values) == 8
            np.testing.assert_allclose(np.diff(values), 0.1, atol=1e-9)
        boxes.append((c.min(axis=0), c.max(axis=0)))
    for a in range(5):
        for b in range(a + 1, 5):
            (lo_a, hi_a), (lo_b, hi_b) = boxes[a], boxes[b]
            gap = np.maximum(lo_b - hi_a, lo_a - hi_b)  # per-axis separation
            assert gap.max() >= 0.1 - 1e-9, f"clusters {a} and {b} overlap"


def test_placement_is_deterministic_per_rng():
    cfg = ResourceConfig()
    a = place_resources(cfg, ARENA, DEPOT, rng(7))
    b = place_resources(cfg, ARENA, DEPOT, rng(7))
    c = place_resources(cfg, ARENA, DEPOT, rng(8))
    assert np.array_equal(a, b)
    assert not np.array_equal(a, c)


def test_uniform():
    cfg = ResourceConfig(distribution="uniform", count=500)
    xy = place_resources(cfg, ARENA, DEPOT, rng())
    assert xy.shape == (500, 2)
    assert_valid(xy, cfg)
    assert len(np.unique(xy, axis=0)) == 500
    # spread over the whole arena, not bunched in one corner
    assert xy[:, 0].min() < -4 and xy[:, 0].max() > 4 and xy[:, 1].min() < -4 and xy[:, 1].max() > 4


def test_powerlaw_piles():
    assert powerlaw_pile_sizes(4) == [64] + [16] * 4 + [4] * 16 + [1] * 64
    cfg = ResourceConfig(distribution="powerlaw", count=320, powerlaw_levels=4)
    xy = place_resources(cfg, ARENA, DEPOT, rng(3))
    assert xy.shape == (320, 2)
    assert_valid(xy, cfg)
    big = xy[:64]
    assert np.ptp(big[:, 0]) == pytest.approx(0.7) and np.ptp(big[:, 1]) == pytest.approx(0.7)
    for k in range(4):
        pile = xy[64 + 16 * k : 64 + 16 * (k + 1)]
        assert np.ptp(pile[:, 0]) == pytest.approx(0.3) and np.ptp(pile[:, 1]) == pytest.approx(0.3)


def test_powerlaw_tiers_split_the_count_as_the_authors_loop_functions():
    """DSA_loop_functions::PowerLawFoodDistribution (MARSLab-UTRGV DDSA/MDBSA, luki-dev)."""
    def shares(n):
        return [sum(t) for t in powerlaw_tiers(n)]
    assert shares(160) == [40] * 4 and shares(200) == [50] * 4 and shares(100) == [25] * 4
    assert shares(150) == [36, 38, 38, 38] and shares(250) == [61, 63, 63, 63]
    assert shares(300) == [60] * 5  # 4^3 (1 + 3) = 256 < 300: a fifth tier, 16 x 16 piles first
    assert powerlaw_tiers(256) == [[64], [16] * 4, [4] * 16, [1] * 64]  # = Hecker & Moses, 4 levels
    assert powerlaw_tiers(160) == [[40], [16, 16, 8], [4] * 10, [1] * 40]
    assert powerlaw_tiers(1) == [[], [1]] and powerlaw_tiers(0) == []


@given(st.integers(1, 1300))
def test_powerlaw_tiers_hold_exactly_the_count_in_piles_that_fit(count):
    tiers = powerlaw_tiers(count)
    assert sum(map(sum, tiers)) == count
    for h, tier in enumerate(tiers):
        side = 2 ** (len(tiers) - 1 - h)
        assert len(tier) <= 4**h and all(0 < n <= side * side for n in tier)


def test_powerlaw_tiers_layout_fills_piles_row_by_row_at_the_pitch():
    cfg = ResourceConfig(distribution="powerlaw_tiers", count=160, spacing=0.15, min_depot_clearance=0.05)
    depot = DepotConfig(center=(0.0, 0.0), radius=0.18)
    xy = place_resources(cfg, ArenaConfig(size=8.0), depot, rng(2), drop_zones_of(depot))
    assert xy.shape == (160, 2)
    big = xy[:40]  # the 8 x 8 pile cut to 40: five full rows of eight
    assert np.ptp(big[:, 0]) == pytest.approx(7 * 0.15) and np.ptp(big[:, 1]) == pytest.approx(4 * 0.15)
    third = xy[72:80]  # the third 4 x 4 pile cut to 8: two rows of four
    assert np.ptp(third[:, 0]) == pytest.approx(3 * 0.15) and np.ptp(third[:, 1]) == pytest.approx(0.15)
    d = np.hypot(*xy.T)
    assert d.min() >= 0.18 + 0.05 - 1e-9  # min_depot_clearance decides, not the zone's spacing
    gaps = np.hypot(*(xy[:, None] - xy[None]).transpose(2, 0, 1)) + np.eye(len(xy))
    assert gaps.min() >= 0.15 - 1e-9


def test_the_depot_drop_zone_keeps_only_min_depot_clearance():
    """The depot's own zone is not widened by `spacing` on top of its clearance (the authors
    keep food NestRadius + FoodRadius from the nest centre: 0.05 m clear of it)."""
    cfg = ResourceConfig(distribution="uniform", count=2000, spacing=0.15, min_depot_clearance=0.05)
    depot = DepotConfig(center=(0.0, 0.0), radius=0.18)
    d = np.hypot(*place_resources(cfg, ArenaConfig(size=8.0), depot, rng(0), drop_zones_of(depot)).T)
    assert 0.23 - 1e-9 <= d.min() < 0.18 + 0.15


def drop_zones_of(depot: DepotConfig):
    from swarm_sim.scenario import DropZoneConfig
    return (DropZoneConfig("depot", depot.center, depot.radius, 0.0, "depot"),)


def test_powerlaw_needs_enough_resources():
    cfg = ResourceConfig(distribution="powerlaw", count=100, powerlaw_levels=4)
    with pytest.raises(ScenarioError, match="resources.count"):
        place_resources(cfg, ARENA, DEPOT, rng())
    small = ResourceConfig(distribution="powerlaw", count=12, powerlaw_levels=2)  # piles 4, 1, 1, 1, 1
    assert len(place_resources(small, ARENA, DEPOT, rng())) == 12


def test_clusters_that_cannot_fit_raise_naming_the_key():
    cfg = ResourceConfig(clusters=5, cluster_side=8, count=320, min_depot_clearance=1.0)
    with pytest.raises(ScenarioError, match="resources.clusters"):
        place_resources(cfg, ArenaConfig(size=4.0), DEPOT, rng())


def test_no_room_outside_the_depot_raises_naming_the_key():
    cfg = ResourceConfig(distribution="uniform", count=10, min_depot_clearance=10.0)
    with pytest.raises(ScenarioError, match="resources.min_depot_clearance"):
        place_resources(cfg, ARENA, DEPOT, rng())


def test_place_one_is_valid_and_keeps_away_from_ground_resources():
    cfg = ResourceConfig()
    ground = place_resources(cfg, ARENA, DEPOT, rng())
    g = rng(5)
    for _ in range(50):
        q = place_one(cfg, ARENA, DEPOT, g, ground)
        assert q.shape == (2,)
        assert_valid(q[None, :], cfg)
        assert np.min(np.hypot(*(ground - q).T)) >= cfg.spacing


@settings(max_examples=40, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    distribution=st.sampled_from(["clustered", "uniform", "powerlaw", "powerlaw_tiers"]),
    clusters=st.integers(1, 6),
    side=st.integers(1, 6),
    depot_x=st.floats(-3.0, 3.0),
    clearance=st.floats(0.0, 1.5),
)
def test_every_layout_is_valid(seed, distribution, clusters, side, depot_x, clearance):
    cfg = ResourceConfig(
        distribution=distribution,
        count=clusters * side**2 if distribution == "clustered" else 100,
        clusters=clusters,
        cluster_side=side,
        powerlaw_levels=3,
        min_depot_clearance=clearance,
    )
    depot = DepotConfig(center=(depot_x, 0.5), radius=0.5)
    xy = place_resources(cfg, ARENA, depot, rng(seed))
    assert xy.shape == (cfg.count, 2)
    assert_valid(xy, cfg, ARENA, depot)
    if distribution == "clustered" and side > 1:
        # every resource's nearest neighbour is one pitch away (grids, none merged or stacked)
        d = np.hypot(*(xy[:, None, :] - xy[None, :, :]).transpose(2, 0, 1))
        np.fill_diagonal(d, math.inf)
        np.testing.assert_allclose(d.min(axis=1), cfg.spacing, atol=1e-9)


@pytest.mark.parametrize("seed", range(6))
def test_the_spiral_algorithms_share_one_layout_per_seed_and_docks_stay_clear(seed):
    """The authors keep food off the nest only, so DDSA, MDBSA-C and MDBSA-D (whose region
    centres are drop zones, of a delivery kind that lets resources lie inside them) get the same
    resources for a seed, 64 regions included; a queue dock is still kept one spacing clear (a
    resource in it would be delivered at pick-up)."""
    from swarm_sim.scenario import load_scenario

    layouts = []
    for name in ("ddsa", "mdbsa_c", "mdbsa_d"):
        s = load_scenario(name, ["regions.count=64"], seed=seed)
        layouts.append(place_resources(s.resources, s.arena, s.depot, np.random.default_rng(seed),
                                       zones_clear_of_resources(s)))
    assert np.array_equal(layouts[0], layouts[1]) and np.array_equal(layouts[0], layouts[2])
    assert len(drop_zones(s)) == 64 and zones_clear_of_resources(s) == ()
    s = load_scenario("queue_qse", seed=seed)
    zones = zones_clear_of_resources(s)
    assert zones == drop_zones(s) and len(zones) == 4
    xy = place_resources(s.resources, s.arena, s.depot, np.random.default_rng(seed), zones)
    for z in zones:
        d = np.hypot(xy[:, 0] - z.center[0], xy[:, 1] - z.center[1])
        assert d.min() >= z.radius + s.resources.spacing - 1e-9, z.name
