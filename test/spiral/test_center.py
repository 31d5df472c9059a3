"""MDBSA center region assignment (paper Sec. IV): both cases, far-end sharing, idling, invariants."""

from __future__ import annotations

import numpy as np
import pytest
from generic_robot import generic_scenario
from hypothesis import given, settings
from hypothesis import strategies as st

from swarm_controllers.spiral.center import FORWARD, REVERSE, Assignment, RegionAssigner
from swarm_controllers.spiral.geometry import SpiralPath, mdbsa_path, region_centers, region_side
from swarm_controllers.spiral.regions import region_order
from swarm_msgs_py.types import robot_name
from swarm_sim.scenario import ScenarioError

ARENA = 8.0


def paths(n_regions: int, arena: float = ARENA) -> list[SpiralPath]:
    side = region_side(n_regions, arena)
    return [SpiralPath(mdbsa_path(c, side)) for c in region_centers(n_regions, arena)]


def robots(n: int) -> list[str]:
    return [robot_name(i) for i in range(n)]


def finish(ca: RegionAssigner, a: Assignment, t: float) -> None:
    """The robot walked its whole assignment up to its stop."""
    ca.report_progress(a.robot, a.region, a.stop_s, t)


def test_regions_have_real_paths():
    ps = paths(16)
    assert all(p.length > 1.0 for p in ps)
    assert np.allclose([p.length for p in ps], ps[0].length)


# ---------------------------------------------------------------- robots <= regions


def test_fewer_robots_first_assignment_by_id():
    ca = RegionAssigner(paths(16), robots(8))
    for k in reversed(range(8)):  # the order of asking does not matter
        a = ca.request(robot_name(k), 1.0)
        assert a is not None
        assert (a.region, a.direction, a.s0, a.shared) == (k, FORWARD, 0.0, False)
        assert a.stop_s == pytest.approx(ca.snapshot()[k].length)
    # one walker in each of regions 0..7, regions 8..15 unassigned
    snap = ca.snapshot()
    assert [len(r.walkers) for r in snap] == [1] * 8 + [0] * 8


NEAREST_FIRST_16 = (5, 6, 9, 10, 1, 2, 4, 7, 8, 11, 13, 14, 0, 3, 12, 15)
"""By hand, 16 regions of an 8 m arena (centres at +-1 and +-3 m, region id = 4 i + j with x from
i, y from j): the four at squared distance 2, then the eight at 10, then the corners at 18, each
ring in id order, as the authors' sort of (squared distance, row-major index) pairs gives."""


def test_the_authors_order_hands_out_the_regions_nearest_the_centre_first():
    scenario = generic_scenario("mdbsa_c", ["regions.order=nearest_first"])
    assert region_order(scenario) == NEAREST_FIRST_16
    assert region_order(generic_scenario("mdbsa_c", ["regions.order=row_major"])) == tuple(range(16))
    ca = RegionAssigner(paths(16), robots(8), order=NEAREST_FIRST_16)
    first = [ca.request(robot_name(k), 0.0) for k in range(8)]
    assert [a.region for a in first] == list(NEAREST_FIRST_16[:8])
    finish(ca, first[3], 10.0)  # robot_3 finishes region 10: the next fresh one in order is 8
    assert ca.request(robot_name(3), 10.0).region == 8


def test_an_unknown_order_is_refused_naming_the_key():
    with pytest.raises(ScenarioError, match="regions.order"):
        generic_scenario("mdbsa_c", ["regions.order=random"])
    with pytest.raises(ValueError, match="not a permutation"):
        RegionAssigner(paths(4), robots(2), order=(0, 1, 1, 2))


def test_fewer_robots_finishers_take_unassigned_then_share_longest_from_far_end():
    ps = paths(4)
    ca = RegionAssigner(ps, robots(3))
    a = {k: ca.request(robot_name(k), 0.0) for k in range(3)}
    assert [a[k].region for k in range(3)] == [0, 1, 2]
    # robot_1 finishes region 1: it gets the unassigned region 3
    finish(ca, a[1], 10.0)
    assert ca.finished(1)
    b = ca.request(robot_name(1), 10.0)
    assert (b.region, b.direction, b.s0, b.shared) == (3, FORWARD, 0.0, False)
    # robot_0 has walked 5 m of region 0, robot_2 2 m of region 2; robot_1 finishes region 3:
    # no unassigned region, so it shares the longest remaining one (region 2) from the far end.
    ca.report_progress(robot_name(0), 0, 5.0, 11.0)
    ca.report_progress(robot_name(2), 2, 2.0, 11.0)
    finish(ca, b, 12.0)
    c = ca.request(robot_name(1), 12.0)
    L = ps[2].length
    assert (c.region, c.direction, c.shared) == (2, REVERSE, True)
    assert c.s0 == pytest.approx(L)  # starts at the far end of the spiral
    assert c.stop_s == pytest.approx(2.0)  # at the latest where the partner had got to
    assert np.allclose(ps[2].point_at(c.s0), ps[2].end)


def test_tie_on_remaining_goes_to_lowest_region_id():
    ca = RegionAssigner(paths(4), robots(4))
    a = [ca.request(r, 0.0) for r in robots(4)]
    finish(ca, a[3], 1.0)
    b = ca.request(robot_name(3), 1.0)  # regions 0, 1, 2 all untouched: lowest id
    assert (b.region, b.direction) == (0, REVERSE)


def test_two_walkers_meet_and_finish_the_region():
    ps = paths(4)
    L = ps[0].length
    ca = RegionAssigner(ps, robots(2))
    ca.request(robot_name(0), 0)
    a1 = ca.request(robot_name(1), 0)
    finish(ca, a1, 5.0)
    ca.request(robot_name(1), 5.0)  # region 2, unassigned
    finish(ca, ca.current(robot_name(1)), 6.0)
    ca.request(robot_name(1), 6.0)  # region 3
    finish(ca, ca.current(robot_name(1)), 7.0)
    ca.report_progress(robot_name(0), 0, 3.0, 7.0)
    b = ca.request(robot_name(1), 7.0)
    assert (b.region, b.direction, b.s0) == (0, REVERSE, pytest.approx(L))
    # both walk on; the stop the center tells each is the other's frontier
    assert ca.report_progress(robot_name(1), 0, L - 4.0, 8.0) == pytest.approx(3.0)
    assert ca.report_progress(robot_name(0), 0, 6.0, 8.0) == pytest.approx(L - 4.0)
    assert ca.remaining(0) == pytest.approx(L - 10.0)
    st0 = ca.snapshot()[0]
    assert st0.covered == ((0.0, 6.0), (pytest.approx(L - 4.0), pytest.approx(L)))
    assert st0.walkers == ((robot_name(0), FORWARD), (robot_name(1), REVERSE))
    # they meet at m; robot_1 comes back first and says so: the region is finished at once
    m = 9.0
    ca.report_progress(robot_name(1), 0, m, 9.0, done=True)
    assert ca.finished(0)
    assert ca.snapshot()[0].covered == ((0.0, pytest.approx(L)),)
    # every region finished: both robots go idle
    assert ca.request(robot_name(1), 9.0) is None
    ca.report_progress(robot_name(0), 0, m, 10.0, done=True)
    assert ca.request(robot_name(0), 10.0) is None
    assert all(r.finished and not r.walkers for r in ca.snapshot())


def test_walkers_meeting_without_done_flag_still_finish_when_both_report():
    ps = paths(4)
    ca = RegionAssigner(ps, robots(5))  # robot_4 shares region 0 from the far end
    a = {r: ca.request(r, 0) for r in robots(5)}
    assert (a[robot_name(4)].region, a[robot_name(4)].direction) == (0, REVERSE)
    ca.report_progress(robot_name(0), 0, 7.0, 1.0)
    assert not ca.finished(0)
    ca.report_progress(robot_name(4), 0, 7.0, 1.0)
    assert ca.finished(0)


# ---------------------------------------------------------------- robots > regions


@pytest.mark.parametrize("n_robots", [5, 8, 11])
def test_more_robots_one_then_second_per_region_then_idle(n_robots):
    ps = paths(4)
    ca = RegionAssigner(ps, robots(n_robots))
    got = {r: ca.request(r, 0.0) for r in robots(n_robots)}
    for k in range(n_robots):
        a = got[robot_name(k)]
        if k < 4:
            assert (a.region, a.direction, a.s0) == (k, FORWARD, 0.0)
        elif k < 8:
            assert (a.region, a.direction, a.shared) == (k - 4, REVERSE, True)
            assert a.s0 == pytest.approx(ps[k - 4].length)
            assert a.stop_s == 0.0
        else:
            assert a is None  # at most two per region
    counts = [len(r.walkers) for r in ca.snapshot()]
    assert counts == [1 + (k + 4 < n_robots) for k in range(4)]


def test_more_robots_finishers_share_longest_single_walker_region_else_idle():
    ps = paths(4)
    L = ps[0].length
    ca = RegionAssigner(ps, robots(6))  # regions 0, 1 get two walkers; regions 2, 3 one
    for r in robots(6):
        ca.request(r, 0.0)
    # robots 0 and 4 meet in region 0 at s = 8
    ca.report_progress(robot_name(0), 0, 8.0, 5.0, done=True)
    ca.report_progress(robot_name(4), 0, 8.0, 5.0, done=True)
    assert ca.finished(0)
    ca.report_progress(robot_name(2), 2, 3.0, 5.0)
    b = ca.request(robot_name(0), 6.0)  # region 3 has the longest remaining path
    assert (b.region, b.direction, b.shared) == (3, REVERSE, True)
    assert b.s0 == pytest.approx(L)
    c = ca.request(robot_name(4), 6.0)  # region 2 is the only one with one walker left
    assert (c.region, c.direction, c.s0, c.stop_s) == (2, REVERSE, pytest.approx(L), 3.0)
    # robots 1 and 5 meet in region 1: every open region has two walkers now, so idle
    ca.report_progress(robot_name(1), 1, 6.0, 7.0, done=True)
    assert ca.request(robot_name(1), 7.0) is None
    assert [len(r.walkers) for r in ca.snapshot()] == [0, 1, 2, 2]  # robot_5 not back yet
    assert ca.request(robot_name(5), 8.0) is None
    assert [len(r.walkers) for r in ca.snapshot()] == [0, 0, 2, 2]


def test_request_is_not_rewarded_with_own_abandoned_slot_twice():
    """A robot that gives up frees its slot; the next asker (itself or an idle one) gets it."""
    ps = paths(4)
    ca = RegionAssigner(ps, robots(9))
    for r in robots(9):
        ca.request(r, 0.0)
    L = ps[2].length
    ca.report_progress(robot_name(6), 2, L - 1.0, 2.0)
    b = ca.request(robot_name(8), 2.0)  # idle robot_8 asks while robot_6 still holds region 2
    assert b is None
    c = ca.request(robot_name(6), 3.0)  # robot_6 ends its walk early: re-offered the freed slot
    assert (c.region, c.direction, c.s0) == (2, REVERSE, pytest.approx(L - 1.0))
    assert ca.request(robot_name(8), 3.0) is None


# ---------------------------------------------------------------- invariants, determinism


def _run(n_regions: int, n_robots: int, ops: list[tuple[int, int, float, bool]]):
    """Replay random requests and progress reports; yields (assigner, this step's result)."""
    ca = RegionAssigner(paths(n_regions), robots(n_robots))
    asked: set[str] = set()
    for step, (kind, k, frac, done) in enumerate(ops):
        r = robot_name(k % n_robots)
        t = float(step + 1)
        result = None
        if kind == 0:
            asked.add(r)
            result = ca.request(r, t)
        elif r in asked and (a := ca.current(r)) is not None:
            # walk a fraction of the way from s0 to the current stop
            s = a.s0 + frac * (ca.stop_for(r) - a.s0)
            result = ca.report_progress(r, a.region, s, t, done=done)
        yield ca, result


ops_strategy = st.lists(
    st.tuples(st.integers(0, 1), st.integers(0, 40), st.floats(0.0, 1.0), st.booleans()),
    max_size=80)


@settings(max_examples=150, deadline=None)
@given(n_regions=st.sampled_from([1, 4, 16]), n_robots=st.integers(1, 40), ops=ops_strategy)
def test_invariants_over_random_sequences(n_regions, n_robots, ops):
    prev_remaining = None
    for ca, result in _run(n_regions, n_robots, ops):
        snap = ca.snapshot()
        seen = set()
        for reg in snap:
            assert len(reg.walkers) <= 2
            dirs = [d for _, d in reg.walkers]
            assert len(set(dirs)) == len(dirs)  # two walkers walk opposite ways
            assert 0.0 <= reg.remaining <= reg.length + 1e-9
            for w, d in reg.walkers:
                assert w not in seen  # one region per robot
                seen.add(w)
                assert (ca.current(w).region, ca.current(w).direction) == (reg.region, d)
        assert seen == {r for r in ca.robots if ca.current(r) is not None}
        remaining = [reg.remaining for reg in snap]
        if prev_remaining is not None:  # coverage only grows
            assert all(b <= a + 1e-9 for a, b in zip(prev_remaining, remaining))
        prev_remaining = remaining
        if isinstance(result, Assignment) and result.t > 0:  # a new walk, not an initial one
            # never into a finished region, and it starts at the frontier of its end
            assert (result.stop_s - result.s0) * result.direction > 1e-6
            reg = snap[result.region]
            cov = reg.covered
            fwd = cov[0][1] if cov and cov[0][0] == 0.0 else 0.0
            rev = cov[-1][0] if cov and cov[-1][1] == reg.length else reg.length
            assert result.s0 == pytest.approx(fwd if result.direction == FORWARD else rev)
        if n_robots <= n_regions and isinstance(result, Assignment) and result.t == 0:
            assert result.region == int(result.robot.split("_")[1])


@settings(max_examples=30, deadline=None)
@given(n_robots=st.integers(1, 20), ops=ops_strategy)
def test_deterministic(n_robots, ops):
    def final(ops):
        results = [(res, ca.snapshot()) for ca, res in _run(4, n_robots, ops)]
        return results
    first, second = final(ops), final(ops)
    assert first == second


def test_idle_robots_beyond_twice_the_regions():
    ca = RegionAssigner(paths(4), robots(12))
    got = [ca.request(r, 0.0) for r in robots(12)]
    assert all(a is None for a in got[8:])
    assert all(len(r.walkers) == 2 for r in ca.snapshot())


def test_idle_until_a_path_is_free():
    ca = RegionAssigner(paths(1), robots(3))
    a = [ca.request(r, 0.0) for r in robots(3)]
    assert a[2] is None and ca.request(robot_name(2), 1.0) is None
    # robot_1 (reverse) leaves early; idle robot_2 may now take its place from robot_1's frontier
    L = ca.snapshot()[0].length
    ca.report_progress(robot_name(1), 0, L - 2.0, 2.0)
    ca.request(robot_name(1), 2.0)  # robot_1 itself re-asks first and is re-assigned the slot
    assert ca.current(robot_name(1)).s0 == pytest.approx(L - 2.0)
    assert ca.request(robot_name(2), 3.0) is None
    ca.report_progress(robot_name(0), 0, 1.0, 4.0)
    ca.report_progress(robot_name(1), 0, 1.0, 4.0, done=True)
    assert ca.finished(0)
    assert ca.request(robot_name(0), 5.0) is None
    assert ca.request(robot_name(2), 5.0) is None


def test_rejects_bad_input():
    with pytest.raises(ValueError):
        RegionAssigner([], robots(2))
    with pytest.raises(ValueError):
        RegionAssigner(paths(4), ["robot_0", "robot_0"])
    ca = RegionAssigner(paths(4), robots(2))
    with pytest.raises(ValueError):
        ca.request("robot_9", 0.0)
    with pytest.raises(ValueError):
        ca.report_progress(robot_name(0), 7, 1.0, 0.0)
    assert ca.report_progress(robot_name(0), 3, 1.0, 0.0) is None  # never walked region 3
    assert ca.remaining(3) == pytest.approx(ca.snapshot()[3].length)


def test_stale_reports_never_shrink_coverage():
    ps = paths(4)
    L = ps[0].length
    ca = RegionAssigner(ps, robots(5))  # robot_4 walks region 0 from the far end
    ca.report_progress(robot_name(4), 0, L - 6.0, 1.0)
    ca.report_progress(robot_name(4), 0, L - 2.0, 2.0)  # an older position, delivered late
    ca.report_progress(robot_name(0), 0, 5.0, 1.0)
    ca.report_progress(robot_name(0), 0, 1.0, 2.0)
    assert ca.snapshot()[0].covered == ((0.0, 5.0), (pytest.approx(L - 6.0), pytest.approx(L)))
    assert ca.remaining(0) == pytest.approx(L - 11.0)
