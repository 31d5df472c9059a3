"""MDBSA (Lu & Luna 2023, Sec. IV): the region spirals, the center server over messages, the
behaviour on synthetic observations, a kinematic swarm with the real center, and short pybullet
runs of MDBSA-D (robots stay in their regions, deliveries land at region centers) and MDBSA-C
(deliveries land in the depot)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from generic_robot import generic_scenario
from hypothesis import given, settings
from hypothesis import strategies as st

from depot_manager.protocol import DepotReport, ReportKind
from swarm_controllers.cpfa.messages import PheromoneMessage
from swarm_controllers.spiral.center import (
    FORWARD,
    REVERSE,
    CenterServer,
    region_bounds,
    region_paths,
    region_spiral,
)
from swarm_controllers.spiral.config import SpiralConfig
from swarm_controllers.spiral.geometry import (
    mdbsa_path,
    region_centers,
    region_side,
    segments_overlap_collinear,
)
from swarm_controllers.spiral.mdbsa import ASK_MARGIN, ASK_RETRY, DEPOT_POINT_HIT, DEPOT_POINT, MdbsaBehaviour, MdbsaState
from swarm_controllers.spiral.protocol import CENTER, ProgressReport, RegionAssignment, WalkProgress
from swarm_controllers.spiral.regions import RegionConfig
from swarm_msgs_py.types import DropEvent, Observation, Pose2D, robot_name
from swarm_sim.messaging import Router
from swarm_sim.protocol import ROBOTS
from swarm_sim.registry import make_behaviour
from swarm_sim.scenario import ScenarioError, load_scenario
from swarm_sim.sites import drop_zones
from swarm_sim.world.tasks.foraging import ForagingSense

ROW_MAJOR = ["regions.order=row_major"]
"""The hand-worked cases below number regions by id (the authors' nearest-first order: test_center)."""
C = generic_scenario("mdbsa_c", ROW_MAJOR)
D = generic_scenario("mdbsa_d", ROW_MAJOR)
DT, DT_NS = C.sim.dt, C.dt_ns
CLEAR = np.full(C.sensors.scan.rays, np.inf, dtype=np.float32)
SMALL = generic_scenario(  # 2.4 m arena, 4 regions of 1.2 m: spirals of ~8 m, walked in ~1 min
    # the lane bounds below are worked out for a lane target one gap ahead
    "mdbsa_c", ["regions.count=4", "controller.spiral.waypoint_gaps=1"], robots__count=3, arena__size=2.4,
    resources__clusters=1, resources__count=16,
)


def dist_to_polyline(p: np.ndarray, pts: np.ndarray) -> np.ndarray:
    """Distance [m] from each point of p (N, 2) to the polyline pts (K, 2)."""
    best = np.full(len(p), np.inf)
    for a, b in zip(pts[:-1], pts[1:]):
        d = b - a
        t = np.clip((p - a) @ d / max(float(d @ d), 1e-12), 0.0, 1.0)
        best = np.minimum(best, np.linalg.norm(a + t[:, None] * d - p, axis=1))
    return best


# ---------------------------------------------------------------- scenarios


def test_scenarios_are_experiment_1_with_16_regions():
    ddsa = generic_scenario("ddsa")
    for s, name in ((C, "mdbsa_c"), (D, "mdbsa_d")):
        assert s.controller.behaviour == name
        assert RegionConfig.of(s).count == 16
        # the same world; the robots may differ in the collision turn only (DDSA's authors turn away)
        robots = dataclasses.replace(s.robots, stop_turn_go=ddsa.robots.stop_turn_go)
        assert (s.arena, robots, s.resources, s.sim) == (ddsa.arena, ddsa.robots, ddsa.resources, ddsa.sim)
        assert dataclasses.replace(s.robots.stop_turn_go, collision_turn="x") == \
            dataclasses.replace(ddsa.robots.stop_turn_go, collision_turn="x")
    assert C.depot.delivery == "depot"
    assert [z.name for z in drop_zones(C)] == ["depot"]
    # MDBSA-D: the region centers are the drop zones and the depot disc is not one, so a
    # carrier crossing the depot keeps its load.
    assert D.depot.delivery == "region_centers"
    zones = drop_zones(D)
    assert [z.name for z in zones] == [f"region_{i}" for i in range(16)]
    np.testing.assert_allclose([z.center for z in zones], region_centers(16, 8.0))
    assert all(z.radius == RegionConfig.of(D).center_radius for z in zones)


def test_a_scenario_with_the_wrong_drop_zones_is_refused():
    with pytest.raises(ScenarioError, match="depot.delivery: mdbsa_d delivers to region_centers"):
        generic_scenario("mdbsa_d", ["depot.delivery=depot"])
    with pytest.raises(ScenarioError, match="depot.delivery: mdbsa_c delivers to depot"):
        generic_scenario("mdbsa_c", ["depot.delivery=region_centers"])
    with pytest.raises(ValueError, match="robot_8"):
        MdbsaBehaviour(C, "robot_8", None)
    assert not MdbsaBehaviour(C, "robot_0", None).distributed and MdbsaBehaviour(D, "robot_0", None).distributed
    assert isinstance(make_behaviour(D, "robot_0", np.random.default_rng(0)), MdbsaBehaviour)


# ---------------------------------------------------------------- region spirals


@settings(max_examples=60, deadline=None)
@given(side=st.floats(0.6, 4.0), margin=st.floats(0.0, 0.25),
       cx=st.floats(-3.0, 3.0), cy=st.floats(-3.0, 3.0))
def test_region_spiral_in_a_centred_box_is_mdbsa_path(side, margin, cx, cy):
    half = side / 2 - margin
    c = np.array([cx, cy])
    np.testing.assert_allclose(region_spiral(c, c - half, c + half, 0.18),
                               mdbsa_path(c, side, 0.18, margin=margin), atol=1e-12)


@pytest.mark.parametrize("regions", [4, 16, 64])
def test_region_paths_stay_in_their_boxes_and_cover_the_resource_area(regions):
    s = generic_scenario("mdbsa_d", [f"regions.count={regions}"])
    paths = region_paths(s)
    bounds = region_bounds(s)
    side = region_side(regions, s.arena.size)
    wall = s.arena.size / 2 - SpiralConfig.of(s).arena_margin
    for p, (lo, hi), c in zip(paths, bounds, region_centers(regions, s.arena.size)):
        np.testing.assert_allclose(p.start, c)  # eq. (3): the spiral starts at the region center
        assert np.all(p.waypoints >= lo - 1e-9) and np.all(p.waypoints <= hi + 1e-9)
        assert np.all(np.abs(p.waypoints - c) <= side / 2 - SpiralConfig.of(s).gap / 2 + 1e-9)
        assert np.all(np.abs(p.waypoints) <= wall + 1e-9)
    # No line is walked by two regions (neighbouring outer lines are a gap apart).
    for i in range(len(paths)):
        for j in range(i + 1, len(paths)):
            assert not segments_overlap_collinear(paths[i].waypoints, paths[j].waypoints)
    # Every place a resource may lie is within detection range of some spiral.
    h = s.arena.size / 2 - s.resources.margin
    g = np.linspace(-h, h, 90)
    pts = np.stack(np.meshgrid(g, g), axis=-1).reshape(-1, 2)
    d = np.min([dist_to_polyline(pts, p.waypoints) for p in paths], axis=0)
    assert d.max() <= s.sensors.resource_detection_radius + 1e-9


def test_server_and_behaviours_use_the_same_spirals():
    server = CenterServer(D)
    b = MdbsaBehaviour(D, "robot_3", None)
    assert len(server.paths) == len(b.paths) == 16
    for p, q in zip(server.paths, b.paths):
        np.testing.assert_array_equal(p.waypoints, q.waypoints)


# ---------------------------------------------------------------- the center server


def report(robot, k=0, *, x=0.3, y=0.0, region=-1, s=0.0, done=True):
    return ProgressReport(stamp_ns=k * DT_NS, robot=robot, x=x, y=y, region=region, s=s, done=done)


def test_server_hands_out_the_initial_regions_sorted_by_robot():
    server = CenterServer(C)
    out = server.step(DT_NS, [report(robot_name(k)) for k in (7, 3, 0, 5, 1, 6, 2, 4)])
    assert [m.robot for m in out] == [robot_name(k) for k in range(8)]
    for k, m in enumerate(out):
        assert isinstance(m, RegionAssignment) and m.CHANNEL == ROBOTS
        assert (m.stamp_ns, m.region, m.direction, m.s0, m.shared) == (DT_NS, k, FORWARD, 0.0, False)
        assert m.stop_s == pytest.approx(server.paths[k].length)
    assert [len(r.walkers) for r in server.snapshot()] == [1] * 8 + [0] * 8
    assert server.ignored == 0


def test_server_ignores_reports_from_out_of_range_and_other_messages():
    server = CenterServer(C)
    r = SpiralConfig.of(C).center_range
    far = report("robot_0", x=r + 0.01)
    unknown = report("robot_99")
    bad_region = report("robot_1", region=16, s=1.0, done=False)
    others = [PheromoneMessage(0, 1.0, 1.0), DepotReport(0, "robot_2", ReportKind.JOIN)]
    assert server.step(DT_NS, [far, unknown, bad_region, *others]) == ()
    assert server.ignored == 3
    edge = report("robot_0", x=r * math.cos(1.0), y=r * math.sin(1.0) - 1e-9)
    (m,) = server.step(2 * DT_NS, [edge])
    assert (m.robot, m.region) == ("robot_0", 0)
    assert server.ignored == 3


def test_server_idles_robots_beyond_two_per_region_and_again_when_they_ask():
    one = generic_scenario("mdbsa_c", ["regions.count=1"], robots__count=3)
    server = CenterServer(one)
    out = server.step(DT_NS, [report(robot_name(k)) for k in range(3)])
    length = server.paths[0].length
    assert [(m.region, m.direction, m.s0, m.stop_s, m.shared) for m in out] == [
        (0, FORWARD, 0.0, length, False), (0, REVERSE, length, 0.0, True),
        (-1, 0, 0.0, 0.0, False)]
    (again,) = server.step(2 * DT_NS, [report("robot_2", 1)])
    assert again.region == -1


def test_server_shares_the_partners_frontier_and_reassigns_when_done():
    s4 = generic_scenario("mdbsa_c", ["regions.count=4"], robots__count=5)
    server = CenterServer(s4)
    first = server.step(DT_NS, [report(robot_name(k)) for k in range(5)])
    assert [(m.region, m.direction) for m in first] == [
        (0, FORWARD), (1, FORWARD), (2, FORWARD), (3, FORWARD), (0, REVERSE)]
    length = server.paths[0].length
    # The reverse walker passes the center: nothing new for it (robot_0 has not reported).
    assert server.step(2 * DT_NS, [report("robot_4", 1, region=0, s=length - 3.0, done=False)]) == ()
    # The forward walker passes: its stop moves to the partner's frontier.
    (upd,) = server.step(3 * DT_NS, [report("robot_0", 2, region=0, s=2.0, done=False)])
    assert (upd.robot, upd.region, upd.direction, upd.shared) == ("robot_0", 0, FORWARD, True)
    assert (upd.s0, upd.stop_s) == (2.0, pytest.approx(length - 3.0))
    # Told once: the same stop is not repeated.
    assert server.step(4 * DT_NS, [report("robot_0", 3, region=0, s=2.5, done=False)]) == ()
    # robot_0 walked to its stop: region 0 is finished; no region is free, so it shares the
    # longest single-walker region (1: ties go to the lowest id) from the far end.
    (new,) = server.step(5 * DT_NS, [report("robot_0", 4, region=0, s=length - 3.0, done=True)])
    assert server.snapshot()[0].finished
    assert (new.region, new.direction, new.shared) == (1, REVERSE, True)
    assert (new.s0, new.stop_s) == (pytest.approx(server.paths[1].length), 0.0)


def test_server_answers_a_robot_once_per_tick_and_is_deterministic():
    def run() -> list[tuple[RegionAssignment, ...]]:
        server = CenterServer(C)
        outs = [server.step(DT_NS, [report("robot_0"), report("robot_1")])]
        outs.append(server.step(2 * DT_NS, [report("robot_0", 1, region=0, s=5.0, done=False),
                                            report("robot_0", 1, region=0, s=6.0, done=True)]))
        return outs

    a, b = run(), run()
    assert a == b
    # One answer (to the done report): the longest unassigned region, regions 0-7 being
    # allocated to robots 0-7 from the start.
    lengths = [p.length for p in CenterServer(C).paths]
    longest = max(range(8, 16), key=lambda i: (lengths[i], -i))
    assert [(m.robot, m.region) for m in a[1]] == [("robot_0", longest)]


# ---------------------------------------------------------------- the behaviour, alone


def reports(c):
    """What a command says to the center (its peer messages left out)."""
    return tuple(m for m in c.messages if isinstance(m, ProgressReport))


def obs(robot, k, x, y, yaw=0.0, messages=(), carrying=False, resources=(), ranges=CLEAR):
    return Observation(robot, k * DT_NS, Pose2D(x, y, yaw), 0.0, 0.0, ranges, ForagingSense(resources, carrying),
                       tuple(messages))


class Unicycle:
    """Integrates commands exactly; the world's stand-in (no collisions, no resources)."""

    def __init__(self, b, x, y, yaw=0.0):
        self.b, self.x, self.y, self.yaw, self.k = b, x, y, yaw, 0

    def step(self, messages=(), ranges=CLEAR):
        c = self.b.step(obs(self.b.robot, self.k, self.x, self.y, self.yaw, messages, ranges=ranges))
        self.yaw = math.remainder(self.yaw + c.angular * DT, 2 * math.pi)
        self.x += c.linear * math.cos(self.yaw) * DT
        self.y += c.linear * math.sin(self.yaw) * DT
        self.k += 1
        return c


def test_asks_at_once_when_in_range_and_again_only_after_the_retry_time():
    b = MdbsaBehaviour(C, "robot_1", None)
    c = b.step(obs("robot_1", 0, 0.0, -0.4))
    assert (c.linear, c.angular) == (0.0, 0.0) and b.state is MdbsaState.WAITING
    assert c.messages == (ProgressReport(0, "robot_1", 0.0, -0.4, -1, 0.0, True),)
    retry = round(ASK_RETRY / DT)
    for k in range(1, retry):
        assert b.step(obs("robot_1", k, 0.0, -0.4)).messages == ()
    again = b.step(obs("robot_1", retry, 0.0, -0.4)).messages
    assert len(again) == 1 and again[0].done and again[0].region == -1


def test_drives_into_range_before_asking():
    b = MdbsaBehaviour(C, "robot_0", None)
    u = Unicycle(b, 1.5, 0.4, math.pi)
    for _ in range(300):
        c = u.step()
        if reports(c):
            break
    assert b.state is MdbsaState.WAITING
    (m,) = reports(c)
    assert math.hypot(m.x, m.y) <= SpiralConfig.of(C).center_range - ASK_MARGIN + 1e-9
    assert math.hypot(m.x, m.y) > SpiralConfig.of(C).center_range - ASK_MARGIN - 0.05


def test_idle_robots_stop_at_a_region_center_for_good_and_keep_avoiding_in_place():
    """The authors' idle robot drives to its (last) region's center, stops within
    RegionRadius and never asks again; it keeps avoiding every tick (issue 11)."""
    b = MdbsaBehaviour(C, "robot_2", None)
    u = Unicycle(b, 0.4, 0.0, 0.0)
    u.step()
    mine = RegionAssignment(DT_NS, "robot_2", -1, 0, 0.0, 0.0, False)
    other = RegionAssignment(DT_NS, "robot_3", 5, FORWARD, 0.0, 20.0, False)
    c = u.step(messages=[other, mine])
    assert b.state is MdbsaState.IDLE and b.region == -1 and c.messages == ()
    assert b.status().extra == (("region", "-1"),)
    centers = [p.start for p in region_paths(C)]
    spot = min(centers, key=lambda c: math.hypot(c[0] - 0.4, c[1]))  # never walked: the nearest
    for _ in range(600):
        c = u.step()
        assert c.messages == ()
    assert b.state is MdbsaState.IDLE
    assert math.hypot(u.x - spot[0], u.y - spot[1]) <= RegionConfig.of(C).center_radius
    assert math.hypot(u.x, u.y) > SpiralConfig.of(C).center_range
    events = b.obstacle_avoidance_events
    c = u.step(ranges=np.full_like(CLEAR, 0.1))
    assert c.linear == 0.0 and c.angular != 0.0 and b.obstacle_avoidance_events == events + 1
    assert (u.step().linear, u.step().angular) == (0.0, 0.0)


def test_a_waiting_robot_keeps_avoiding_in_place():
    b = MdbsaBehaviour(C, "robot_1", None)
    b.step(obs("robot_1", 0, 0.0, -0.4))
    assert b.state is MdbsaState.WAITING
    c = b.step(obs("robot_1", 1, 0.0, -0.4, ranges=np.full_like(CLEAR, 0.1)))
    assert c.linear == 0.0 and c.angular != 0.0 and b.obstacle_avoidance_events == 1
    assert b.state is MdbsaState.WAITING


def test_a_waiting_robot_takes_only_an_answer_stamped_after_its_ask():
    """An MDBSA-C robot may ask right after a pass report whose update is still in flight;
    that update (stamped no later than the ask) must not be taken for the answer."""
    b = MdbsaBehaviour(C, "robot_0", None)
    b.step(obs("robot_0", 3, 0.3, 0.0))  # asks, stamped tick 3
    stale = RegionAssignment(3 * DT_NS, "robot_0", 4, FORWARD, 2.0, 9.0, False)
    b.step(obs("robot_0", 4, 0.3, 0.0, messages=[stale]))
    assert b.state is MdbsaState.WAITING and b.region == -1
    answer = RegionAssignment(4 * DT_NS, "robot_0", 6, FORWARD, 0.0, 20.0, False)
    b.step(obs("robot_0", 5, 0.3, 0.0, messages=[answer]))
    assert b.state is MdbsaState.TRAVELING and b.region == 6


def test_reverse_walk_starts_at_the_far_end_and_reports_arc_length_from_the_start():
    b = MdbsaBehaviour(SMALL, "robot_0", None)
    path = b.paths[2]
    stop = 0.4 * path.length
    u = Unicycle(b, 0.0, 0.0)
    u.step()
    a = RegionAssignment(DT_NS, "robot_0", 2, REVERSE, path.length, stop, True)
    u.step([a])
    assert b.state is MdbsaState.TRAVELING and (b.region, b.direction) == (2, REVERSE)
    while b.state is MdbsaState.TRAVELING:
        u.step()
    assert math.hypot(u.x - path.end[0], u.y - path.end[1]) < 0.05
    s_seen, worst = [], 0.0
    while b.state is MdbsaState.SEARCHING:
        c = u.step()
        s_seen.append(b.progress)
        worst = max(worst, float(dist_to_polyline(np.array([[u.x, u.y]]), path.waypoints)[0]))
    assert np.all(np.diff(s_seen) <= 1e-12)  # s counts from the spiral's start: it decreases
    assert b.progress == pytest.approx(stop)
    assert worst < 0.03
    assert math.hypot(u.x - path.point_at(stop)[0], u.y - path.point_at(stop)[1]) < 0.06
    # The walk is over: back into the center's range, report it done there.
    for _ in range(600):
        if reports(c):
            break
        assert b.state is MdbsaState.TO_CENTER
        c = u.step()
    (m,) = reports(c)
    assert (m.region, m.s, m.done) == (2, pytest.approx(stop), True)
    st_ = b.status()
    assert st_.state == "WAITING" and ("region", "2") in st_.extra and ("direction", "-1") in st_.extra


def _walk_to_its_end(b, u, region):
    """Assign `region` forward, up to its point farthest from the centre, and drive until the walk
    is over; the report after it."""
    path = b.paths[region]
    stop = max(np.linspace(0.0, path.length, 200), key=lambda s: math.hypot(*path.point_at(s)))
    assert math.hypot(*path.point_at(stop)) > SpiralConfig.of(SMALL).center_range + 0.2
    u.step()
    u.step([RegionAssignment(DT_NS, b.robot, region, FORWARD, 0.0, float(stop), False)])
    for _ in range(3000):
        c = u.step()
        if reports(c):
            return reports(c)
    raise AssertionError("the walk never ended")


def _seg_distance(p, a, b):
    a, b, p = np.asarray(a, float), np.asarray(b, float), np.asarray(p, float)
    t = np.clip(np.dot(p - a, b - a) / np.dot(b - a, b - a), 0.0, 1.0)
    return float(np.hypot(*(a + t * (b - a) - p)))


@pytest.mark.parametrize("mode", ["center_range", "depot"])
def test_with_next_walk_at_depot_a_new_walk_starts_by_way_of_the_authors_point(mode):
    """The MDBSA authors' robot, its point list empty, takes its next walk at once but first drives
    to within 0.1 m of (0.1, 0.1) (``SetTarget(CVector2(0.1, 0.1))``, then ``TargetHit``). Ours
    asks in the center's range either way; with ``depot`` it then goes by way of that point."""
    s = generic_scenario("mdbsa_c", ["regions.count=4", f"controller.spiral.next_walk_at={mode}"], robots__count=3,
                         arena__size=2.4, resources__clusters=1, resources__count=16)
    assert SpiralConfig.of(s).next_walk_at == mode
    b = MdbsaBehaviour(s, "robot_0", None)
    u = Unicycle(b, 0.3, 0.0)
    (m,) = _walk_to_its_end(b, u, 1)
    assert m.done and m.region == 1 and b.state is MdbsaState.WAITING
    rng = SpiralConfig.of(s).center_range
    assert rng - ASK_MARGIN - 0.05 < math.hypot(m.x, m.y) <= rng
    nxt = 3
    straight = _seg_distance(DEPOT_POINT, (m.x, m.y), b.paths[nxt].start)
    assert straight > DEPOT_POINT_HIT + 0.2  # the straight way misses the nest point
    u.step([RegionAssignment(u.k * DT_NS, "robot_0", nxt, FORWARD, 0.0, b.paths[nxt].length, False)])
    nearest = math.inf
    for _ in range(600):
        if b.state is not MdbsaState.TRAVELING:
            break
        u.step()
        nearest = min(nearest, math.hypot(u.x - DEPOT_POINT[0], u.y - DEPOT_POINT[1]))
    assert b.state is MdbsaState.SEARCHING and b.region == nxt
    if mode == "depot":
        assert nearest <= DEPOT_POINT_HIT
    else:
        assert nearest > straight - 0.05


def test_with_next_walk_at_depot_an_idle_robot_does_not_visit_the_depot():
    s = generic_scenario("mdbsa_c", ["regions.count=4", "controller.spiral.next_walk_at=depot"], robots__count=3,
                         arena__size=2.4, resources__clusters=1, resources__count=16)
    b = MdbsaBehaviour(s, "robot_0", None)
    u = Unicycle(b, 0.3, 0.0)
    _walk_to_its_end(b, u, 1)
    u.step([RegionAssignment(u.k * DT_NS, "robot_0", -1, 0, 0.0, 0.0, False)])
    assert b.state is MdbsaState.IDLE
    nearest = math.inf
    for _ in range(300):
        u.step()
        nearest = min(nearest, math.hypot(u.x - DEPOT_POINT[0], u.y - DEPOT_POINT[1]))
    assert nearest > DEPOT_POINT_HIT + 0.2


@pytest.mark.parametrize("gaps", [1, 3])
def test_waypoint_gaps_sets_how_far_apart_the_foot_bots_stops_are(gaps):
    """On the foot-bot (stop-turn-go, blind legs) the lane target ``waypoint_gaps`` gaps ahead
    makes one stop per ``waypoint_gaps * gap`` of a straight leg (the authors' MDBSA: 3 gaps)."""
    s = load_scenario("mdbsa_c", [*ROW_MAJOR, "regions.count=4", f"controller.spiral.waypoint_gaps={gaps}"],
                      robots__count=3, arena__size=4.0, resources__clusters=1, resources__count=16)
    b = MdbsaBehaviour(s, "robot_0", None)
    path = b.paths[1]
    u = Unicycle(b, *path.start)
    u.step()
    u.step([RegionAssignment(DT_NS, "robot_0", 1, FORWARD, 0.0, path.length, False)])
    stops, moving, start = 0, False, None
    while b.state is not MdbsaState.SEARCHING:
        u.step()
    long_leg = max(range(1, len(path.waypoints)), key=lambda k: path.cumulative[k] - path.cumulative[k - 1])
    a, e = path.cumulative[long_leg - 1], path.cumulative[long_leg]
    for _ in range(6000):
        c = u.step()
        if b.progress >= e - 1e-6 or b.state is not MdbsaState.SEARCHING:
            break
        if b.progress > a + 1e-6:
            start = start if start is not None else b.progress
            full = c.linear > 0.999 * s.robots.max_linear_speed  # a stop inside a tick slows its mean twist
            if full and not moving:
                stops += 1
            moving = full
    step = gaps * SpiralConfig.of(s).gap
    assert e - a > 2 * step  # the leg is long enough to tell
    assert stops == pytest.approx(math.ceil((e - start) / step), abs=1)


def test_an_update_from_the_center_moves_the_stop_toward_the_robot_only():
    b = MdbsaBehaviour(SMALL, "robot_0", None)
    L = b.paths[1].length
    b.step(obs("robot_0", 0, 0.0, 0.0))
    b.step(obs("robot_0", 2, 0.0, 0.0, messages=[RegionAssignment(DT_NS, "robot_0", 1, FORWARD, 0.0, L, False)]))
    assert b.stop == pytest.approx(L)
    b.step(obs("robot_0", 3, 0.0, 0.0, messages=[RegionAssignment(2 * DT_NS, "robot_0", 1, FORWARD, 0.0, L - 2.0, True)]))
    assert b.stop == pytest.approx(L - 2.0)
    b.step(obs("robot_0", 4, 0.0, 0.0, messages=[RegionAssignment(3 * DT_NS, "robot_0", 1, FORWARD, 0.0, L - 1.0, True)]))
    assert b.stop == pytest.approx(L - 2.0)  # a stale (larger) stop never extends the walk


# ---------------------------------------------------------------- a kinematic swarm with the center


def kinematic_run(s, seconds):
    """Unicycles (no physics, no resources) + the real CenterServer, messages routed as the
    batch runner does: robots at tick k see what was stamped before k, the server runs after
    the robots."""
    server = CenterServer(s)
    robots = s.robot_names
    bs = {r: MdbsaBehaviour(s, r, None) for r in robots}
    side = math.ceil(math.sqrt(len(robots)))
    pitch = s.robots.start_spacing
    pose = {r: [(i % side - (side - 1) / 2) * pitch, (i // side - (side - 1) / 2) * pitch, 0.0]
            for i, r in enumerate(robots)}
    router, log = Router(), []
    for k in range(round(seconds / DT)):
        t_ns = k * s.dt_ns
        inbox = router.take_before(ROBOTS, t_ns)
        for r, b in bs.items():
            x, y, yaw = pose[r]
            c = b.step(Observation(r, t_ns, Pose2D(x, y, yaw), 0.0, 0.0, CLEAR, ForagingSense((), False), inbox))
            for m in c.messages:
                router.post(m)
            yaw = math.remainder(yaw + c.angular * DT, 2 * math.pi)
            pose[r] = [x + c.linear * math.cos(yaw) * DT, y + c.linear * math.sin(yaw) * DT, yaw]
            log.append((k, r, b.state, b.region, b.direction, b.progress))
        for m in server.step(t_ns, router.take_before(CENTER, t_ns)):
            router.post(m)
    return bs, server, pose, log


def test_kinematic_swarm_finishes_every_region_sharing_paths_then_idles():
    bs, server, pose, log = kinematic_run(SMALL, 240.0)
    snap = server.snapshot()
    assert all(r.finished for r in snap) and all(not r.walkers for r in snap)
    assert server.ignored == 0
    assert all(b.state is MdbsaState.IDLE for b in bs.values())
    # Idle for good at the center of the region each walked last (the authors' IDLE).
    last = {r: region for _, r, state, region, _, _ in log if state is MdbsaState.SEARCHING}
    for r, (x, y, _) in pose.items():
        cx, cy = server.paths[last[r]].start
        assert math.hypot(x - cx, y - cy) <= RegionConfig.of(SMALL).center_radius
    walks = {(r, region, d) for _, r, state, region, d, _ in log
             if state is MdbsaState.SEARCHING}
    assert {region for _, region, _ in walks} == {0, 1, 2, 3}
    assert any(d == REVERSE for _, _, d in walks), "no path was shared from its far end"
    # At any tick at most two robots search a region, in opposite directions.
    per_tick: dict[tuple[int, int], list[int]] = {}
    for k, r, state, region, d, _ in log:
        if state is MdbsaState.SEARCHING:
            per_tick.setdefault((k, region), []).append(d)
    assert all(len(ds) <= 2 and len(set(ds)) == len(ds) for ds in per_tick.values())


@pytest.mark.parametrize("radio", [True, False])
def test_the_two_walkers_of_a_region_stop_where_they_meet(radio):
    """Sec. IV / Fig. 5: the walkers of a shared region talk (`WalkProgress` every waypoint spacing)
    and stop where they meet: together they cover the spiral, overlapping by about that spacing.
    Without the radio each walks on to the stop the center last sent it (much more overlap)."""
    s = generic_scenario("mdbsa_d", [*ROW_MAJOR, "regions.count=4", f"controller.spiral.partner_radio={radio}"],
                         robots__count=8, arena__size=2.4, resources__clusters=1, resources__count=16)
    bs, server, _, log = kinematic_run(s, 150.0)
    reach: dict[tuple[str, int, int], float] = {}
    for _, r, _, region, d, progress in log:
        if region >= 0:
            reach[(r, region, d)] = progress
    overlaps = []
    for region in range(4):
        fwd = [p for (r, g, d), p in reach.items() if g == region and d == FORWARD]
        rev = [p for (r, g, d), p in reach.items() if g == region and d == REVERSE]
        assert len(fwd) == 1 and len(rev) == 1  # 8 robots, 4 regions: two walkers each from tick 0
        overlaps.append(fwd[0] - rev[0])  # forward covered [0, fwd], reverse [rev, L]
    legs = np.diff(server.paths[0].cumulative)
    assert min(overlaps) >= -1e-6  # never a gap
    step = SpiralConfig.of(s).waypoint_gaps * SpiralConfig.of(s).gap
    if radio:
        assert max(overlaps) <= step  # about the waypoint spacing
    else:
        assert max(overlaps) > 2 * legs.max()


def test_a_walker_takes_only_its_partners_progress_and_only_toward_itself():
    b = MdbsaBehaviour(SMALL, "robot_0", None)
    L = b.paths[1].length
    b.step(obs("robot_0", 0, 0.0, 0.0))
    b.step(obs("robot_0", 2, 0.0, 0.0, messages=[RegionAssignment(DT_NS, "robot_0", 1, FORWARD, 0.0, L, False)]))
    ignored = [WalkProgress(DT_NS, "robot_1", 2, REVERSE, 3.0),      # another region
               WalkProgress(DT_NS, "robot_1", 1, FORWARD, 3.0),      # the same direction
               WalkProgress(DT_NS, "robot_0", 1, REVERSE, 3.0),      # its own
               WalkProgress(DT_NS, "robot_1", 1, REVERSE, math.nan)]
    b.step(obs("robot_0", 3, 0.0, 0.0, messages=ignored))
    assert b.stop == pytest.approx(L)
    b.step(obs("robot_0", 4, 0.0, 0.0, messages=[WalkProgress(3 * DT_NS, "robot_1", 1, REVERSE, L - 2.0)]))
    assert b.stop == pytest.approx(L - 2.0)
    b.step(obs("robot_0", 5, 0.0, 0.0, messages=[WalkProgress(4 * DT_NS, "robot_1", 1, REVERSE, L - 1.0)]))
    assert b.stop == pytest.approx(L - 2.0)  # an older frontier never extends the walk


# ---------------------------------------------------------------- pybullet runs


def _recorded_batch(monkeypatch, s):
    import swarm_sim.batch as batch

    built: dict[str, MdbsaBehaviour] = {}
    log: dict[str, list[tuple[int, str, int, bool, float, float]]] = {}
    servers = []

    def recording(scenario, robot, rng):
        b = make_behaviour(scenario, robot, rng)
        built[robot] = b
        log[robot] = []
        step = b.step
        searched: set[int] = set()

        def logged(o: Observation):
            c = step(o)
            if b.state is MdbsaState.SEARCHING:
                searched.add(id(b._walk))
            walking = b._walk is not None and not b._walk.over and id(b._walk) in searched
            log[robot].append((o.stamp_ns, b.state.name, b.region, walking, o.pose.x, o.pose.y))
            return c

        b.step = logged
        return b

    def make_servers(scenario):
        made = batch_make_servers(scenario)
        servers.append(made[CENTER])
        return made

    batch_make_servers = batch.make_servers
    monkeypatch.setattr(batch, "make_behaviour", recording)
    monkeypatch.setattr(batch, "make_servers", make_servers)
    return batch.run_batch(s), built, log, servers[0]


def test_mdbsa_d_robots_stay_in_their_regions_and_deliver_to_their_region_centers(monkeypatch):
    """8 robots, 4 regions, 180 s: robots 0-3 walk regions 0-3 from the center, robots 4-7 the
    same regions from the far end. Tolerance: while a robot works its walk (searching, carrying
    a find to the region center, resuming) it stays within its region's square + 0.3 m."""
    s = generic_scenario("mdbsa_d", ["regions.count=4", "sim.duration=180"])
    run, built, log, server = _recorded_batch(monkeypatch, s)
    assert server.ignored == 0
    centers, half = region_centers(4, s.arena.size), region_side(4, s.arena.size) / 2
    for k in range(8):
        rows = log[robot_name(k)]
        assert {(region) for _, state, region, *_ in rows if state == "SEARCHING"} == {k % 4}
        assert built[robot_name(k)].direction == (FORWARD if k < 4 else REVERSE)
        worked = [(region, x, y) for _, state, region, walking, x, y in rows
                  if walking and state in ("SEARCHING", "DELIVERING", "RESUMING")]
        assert len(worked) > 300
        for region, x, y in worked:
            cx, cy = centers[region]
            assert max(abs(x - cx), abs(y - cy)) <= half + 0.3, (k, region, x, y)
    drops = run.trace.drops
    assert len(drops) >= 10
    region_at = {(r, stamp): region for r, rows in log.items() for stamp, _, region, *_ in rows}
    for e in drops:
        assert isinstance(e, DropEvent)
        assert e.zone == f"region_{region_at[(e.robot, e.stamp_ns - DT_NS)]}"


def test_mdbsa_c_delivers_to_the_depot_and_reports_in_range(monkeypatch):
    s = dataclasses.replace(C, sim=dataclasses.replace(C.sim, duration=120.0))
    run, built, log, server = _recorded_batch(monkeypatch, s)
    assert len(run.trace.drops) >= 3
    assert {e.zone for e in run.trace.drops} == {"depot"}
    assert server.ignored == 0
    assert sorted(b.region for b in built.values()) == list(range(8))
