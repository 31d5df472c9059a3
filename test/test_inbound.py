"""What a node accepts from the bus (`swarm_sim.inbound`): robot ids, ticks, malformed bytes,
counting and rate-limited logging; the /diagnostics codec; the cores' refusals of dead robots."""

from __future__ import annotations

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from depot_manager.codec import DEPOT, RADIO
from depot_manager.protocol import DepotGrant, DepotReport, RadioReply, ReportKind
from depot_manager.server import DepotServer
from swarm_controllers.cpfa.messages import PheromoneMessage
from swarm_controllers.spiral.center import CenterServer
from swarm_controllers.spiral.protocol import ProgressReport
from swarm_msgs_py import diagnostics
from swarm_msgs_py.diagnostics import OK, encode_diagnostics
from swarm_msgs_py.types import NodeDownEvent
from swarm_sim.inbound import Inbound, Reason, Rejections, merged, robot_fields
from swarm_sim.scenario import load_scenario
from swarm_sim.world.tasks.foraging import ForagingSense

DT = 100_000_000
ROBOTS = ("robot_0", "robot_1")


def _inbound(now_ticks: int = 10) -> tuple[Inbound, list[str]]:
    logged: list[str] = []
    gate = Inbound(ROBOTS, DT, Rejections(), logged.append)
    gate.now_ns = gate.released_ns = now_ticks * DT
    return gate, logged


def test_robot_fields_are_found_by_annotation():
    assert robot_fields(RadioReply) == ("sender", "to")
    assert robot_fields(DepotGrant) == ("robot",)
    assert robot_fields(PheromoneMessage) == ()


def test_messages_naming_robots_of_no_run_are_dropped_and_counted():
    gate, logged = _inbound()
    ok = RadioReply(10 * DT, "robot_1", "robot_0", 0.0, 0.0, "entry_line_0", 3, False)
    forged = RadioReply(10 * DT, "robot_1", "robot_900", 0.0, 0.0, "entry_line_0", 3, False)
    assert gate.admit("/radio", ok) and not gate.admit("/radio", forged)
    assert gate.rejections.counts == {("/radio", "unknown robot"): 1}
    assert "RadioReply.to = 'robot_900'" in logged[0]


@given(st.integers(-5, 15))
def test_the_tick_window(offset):
    """Accepted: one tick late (released - dt) up to one tick ahead (now + dt)."""
    gate, _ = _inbound(now_ticks=10)
    m = DepotReport((10 + offset) * DT, "robot_0", ReportKind.AT, "l", 1)
    assert gate.admit("/depot/reports", m) == (-1 <= offset <= 1)
    if not -1 <= offset <= 1:
        assert gate.rejections.counts == {("/depot/reports", "wrong tick"): 1}


def test_malformed_bytes_are_counted_and_the_rest_of_the_batch_is_kept():
    gate, logged = _inbound()
    posted: list[object] = []
    bad = encode_diagnostics(0, [(OK, "DepotGrant", "", "robot_0", (("cell", "x"),))])
    assert gate.post_all("/depot/grants", DEPOT, bad, posted.append) == 0
    assert posted == [] and "malformed" in logged[0]
    (good,) = RADIO.encode(10 * DT, [RadioReply(10 * DT, "robot_1", "robot_0", 0.0, 0.0, "l", 1, False),
                                     RadioReply(10 * DT, "robot_1", "ghost", 0.0, 0.0, "l", 1, False)])
    assert gate.post_all("/radio", RADIO, good, posted.append) == 1 and posted[0].to == "robot_0"
    assert merged(gate.rejections) == {("/depot/grants", "malformed"): 1, ("/radio", "unknown robot"): 1}


def test_logging_is_rate_limited_per_kind():
    r = Rejections()
    logged = [n for n in range(1, 2001) if r.add("/radio", Reason.WRONG_TICK)]
    assert logged == [1, 10, 100, 1000]
    assert r.add("/radio", Reason.MALFORMED)  # another kind: logged at once
    assert r.total == 2001


def test_rejection_counts_round_trip_on_diagnostics():
    counts = {("/radio", "unknown robot"): 3, ("DepotReport", "refused"): 1}
    data = diagnostics.encode_rejections(5, "/robot_0/controller", counts)
    assert diagnostics.decode_rejections(data) == (5, {"/robot_0/controller": counts})


def test_node_down_events_round_trip():
    events = (NodeDownEvent("robot_3", 7 * DT, "robot", 3), NodeDownEvent("depot", 9 * DT, "server", 3))
    assert diagnostics.decode_events(diagnostics.encode_events(9 * DT, events)) == (9 * DT, events)


def test_a_dead_robot_leaves_the_depot_and_its_reports_are_refused():
    server = DepotServer(load_scenario("queue_qmt", ["robots.count=4"]))
    s = 10**9
    server.step(s, [DepotReport(0, "robot_1", ReportKind.JOIN, "entry_line_0", 0)])
    server.step(2 * s, [])
    assert server.admission.robots_inside == ("robot_1",)
    assert "robot_1" in {o for *_, o in server.admission.snapshot().occupied}
    server.robot_lost("robot_1", 3 * s)
    assert server.admission.robots_inside == () and server.admission.snapshot().occupied == ()
    out = server.step(3 * s, [DepotReport(2 * s, "robot_1", ReportKind.JOIN, "entry_line_0", 0)])
    assert out == () and server.rejections.counts == {("DepotReport", "declared dead"): 1}
    # the freed slot 0 is free for another robot
    server.step(4 * s, [DepotReport(3 * s, "robot_2", ReportKind.JOIN, "entry_line_0", 0)])
    assert server.admission.robots_inside == ("robot_2",)


def test_a_dead_robots_region_goes_to_another_robot():
    scenario = load_scenario("mdbsa_d", ["robots.count=2", "regions.count=4"])
    server = CenterServer(scenario)
    assert server.assigner.current("robot_0").region == 0
    server.robot_lost("robot_0", 10**9)
    assert server.assigner.current("robot_0") is None
    # robot_1 finishes its region 1 and asks: it gets an unassigned region; region 0 is one again
    (a,) = server.step(10**9, [ProgressReport(0, "robot_1", 0.0, 0.0, -1, 0.0, True)])
    assert a.region == 1  # its initial walk
    length = server.assigner.remaining(1)
    (a,) = server.step(2 * 10**9, [ProgressReport(10**9, "robot_1", 0.0, 0.0, 1, length, True)])
    assert a.region == 0  # the dead robot's region, unassigned again (lowest id of the longest)
    out = server.step(3 * 10**9, [ProgressReport(2 * 10**9, "robot_0", 0.0, 0.0, -1, 0.0, True)])
    assert out == () and ("ProgressReport", "declared dead") in server.rejections.counts


def test_core_counts_are_merged_with_the_nodes():
    node, core = Rejections(), Rejections()
    node.add("/radio", Reason.MALFORMED)
    core.add("RadioReply", Reason.REFUSED)
    core.add("RadioReply", Reason.REFUSED)
    assert merged(node, core, None) == {("/radio", "malformed"): 1, ("RadioReply", "refused"): 2}
    assert np.sum(list(merged(node, core).values())) == 3


# --------------------------------------------------------------------------- the guard (issue 25)

def _guarded(scenario_overrides=("robots.count=2",)):
    from swarm_sim.inbound import Bounds

    scenario = load_scenario("queue_qmt", scenario_overrides)
    logged: list[str] = []
    gate = Inbound(scenario.robot_names, scenario.dt_ns, Rejections(), logged.append, Bounds.of(scenario))
    gate.now_ns = gate.released_ns = 10 * scenario.dt_ns
    return gate, scenario, logged


def test_the_guard_refuses_big_messages_unread_and_survives_any_decoder_failure():
    gate, _, _ = _guarded()
    read: list[bytes] = []

    def decoder(data):
        read.append(data)
        raise OverflowError("1e308 squared")  # not a ValueError: the guard still holds

    assert gate.decode("/x", decoder, bytes(100), max_bytes=10) is None and read == []
    assert gate.decode("/x", decoder, bytes(5), max_bytes=10) is None and len(read) == 1
    assert gate.decode("/x", lambda d: ("ok", d), b"ab", max_bytes=10) == ("ok", b"ab")
    assert gate.rejections.counts == {("/x", "too big"): 1, ("/x", "malformed"): 1}


def test_a_19_mb_array_of_grants_is_refused_by_size_before_it_is_decoded():
    gate, scenario, _ = _guarded()
    grants = [DepotGrant(0, "robot_999", "entry_line_0", k) for k in range(20_000)]
    (data,) = DEPOT.encode(0, grants)
    assert len(data) > gate.bounds.message_bytes
    assert gate.post_all("/depot/grants", DEPOT, data, lambda m: None) == 0
    assert gate.rejections.counts == {("/depot/grants", "too big"): 1}


def test_coordinates_beyond_the_arena_are_refused_before_any_core_computes_with_them():
    gate, scenario, logged = _guarded()
    edge = scenario.arena.size / 2 + scenario.arena.wall_thickness
    ok = RadioReply(10 * DT, "robot_1", "robot_0", edge, -edge, "l", 1, False)
    far = RadioReply(10 * DT, "robot_1", "robot_0", 1e6, 0.0, "l", 1, False)
    assert gate.admit("/radio", ok) and not gate.admit("/radio", far)
    assert gate.rejections.counts == {("/radio", "out of bounds"): 1} and "RadioReply.x" in logged[0]


def test_observations_are_checked_for_their_tick_and_their_numbers():
    from swarm_msgs_py.types import Pose2D

    gate, scenario, _ = _guarded()
    dt, b = scenario.dt_ns, gate.bounds
    as_is = lambda d: d  # noqa: E731 - the guard's decoder: the "bytes" are the decoded tuple here

    def guard(where, kind):
        got = []
        check = gate.sense_guard(where, as_is, kind, got.append)
        return lambda d: (check(d), got.pop() if got else None)[1]

    odom = guard("/r/odom", "odometry")
    assert odom((dt, Pose2D(1.0, -1.0, 3.0), 0.1, -1.0))
    for stamp, x, v, w in ((dt, float("nan"), 0.0, 0.0), (dt, 1e308, 0.0, 0.0), (dt, 0.0, b.speed * 1.01, 0.0),
                           (dt, 0.0, 0.0, -b.turn_rate * 1.01)):
        assert odom((stamp, Pose2D(x, 0.0, 0.0), v, w)) is None
    for stamp in (dt + 1, -dt, b.end_ns + dt):
        assert odom((stamp, Pose2D(0.0, 0.0, 0.0), 0.0, 0.0)) is None
    ranges = guard("/r/scan", "scan")
    rays = b.rays
    assert ranges((dt, np.array([np.inf, -np.inf, 0.5] + [1.0] * (rays - 3), np.float32)))
    assert ranges((dt, np.array([np.nan] + [1.0] * (rays - 1), np.float32))) is None
    assert ranges((dt, np.array([-0.5] + [1.0] * (rays - 1), np.float32))) is None
    assert ranges((dt, np.ones(rays + 1, np.float32))) is None
    seen = guard("/r/sense", "value")
    assert seen((dt, ForagingSense(((1.0, 2.0), (-2.0, 0.5)), True)))
    assert seen((dt, ForagingSense(((1.0, 2.0), (float("inf"), 0.5)), False))) is None
    assert seen((dt, ForagingSense(((1e9, 2.0),), False))) is None
    assert gate.rejections.counts == {("/r/odom", "out of bounds"): 4, ("/r/odom", "wrong tick"): 3,
                                      ("/r/scan", "out of bounds"): 3, ("/r/sense", "out of bounds"): 2}


def test_the_sense_guard_decodes_and_checks_in_one_call():
    from swarm_msgs_py import odometry, scan
    from swarm_msgs_py.types import Pose2D
    from swarm_sim.world.tasks.foraging_sensing import SENSING

    gate, scenario, _ = _guarded()
    dt, sc = scenario.dt_ns, scenario.sensors.scan
    got, refusals = [], []

    def guard(where, decode, kind="value"):
        return gate.sense_guard(where, decode, kind, got.append, lambda: refusals.append(where))

    odom = guard("/r/odom", odometry.decode_odometry, "odometry")
    ranges = guard("/r/scan", scan.decode_scan, "scan")
    seen = guard("/r/sense", SENSING.decode)
    odom(odometry.encode_odometry("robot_0", dt, Pose2D(1.0, 2.0, 0.5), 0.1, 0.0))
    assert got.pop()[0] == dt
    odom(odometry.encode_odometry("robot_0", dt, Pose2D(1e308, 2.0, 0.5), 0.1, 0.0))
    odom(odometry.encode_odometry("robot_0", dt + 1, Pose2D(1.0, 2.0, 0.5), 0.1, 0.0))
    odom(b"\x00\x01\x00\x00")
    odom(bytes(gate.bounds.sense_bytes + 1))
    good = np.full(sc.rays, np.inf, np.float32)
    good[0] = -np.inf
    ranges(scan.encode_scan("robot_0", dt, good, sc))
    assert got.pop()[0] == dt
    good[1] = np.nan
    ranges(scan.encode_scan("robot_0", dt, good, sc))
    seen(SENSING.encode(dt, ForagingSense(((1.0, 1.0),), True)))
    assert got.pop() == (dt, ForagingSense(((1.0, 1.0),), True)) and got == []
    seen(SENSING.encode(dt, ForagingSense(((1.0, float("nan")),), False)))
    seen(SENSING.encode(dt, ForagingSense((), True))[:-3])
    assert got == []
    assert refusals == ["/r/odom"] * 4 + ["/r/scan"] + ["/r/sense"] * 2
    assert gate.rejections.counts == {("/r/odom", "out of bounds"): 1, ("/r/odom", "wrong tick"): 1,
                                      ("/r/odom", "malformed"): 1, ("/r/odom", "too big"): 1,
                                      ("/r/scan", "out of bounds"): 1, ("/r/sense", "out of bounds"): 1,
                                      ("/r/sense", "malformed"): 1}
