"""Queue strategies end to end in process (batch runner): robots forage with the CPFA, queue
under the depot manager's grants and unload at docks only; non-carriers stay out of the
perimeter; graph-free, so these are fast."""

from __future__ import annotations

import math
from unittest import mock

import numpy as np
import pytest
from generic_robot import generic_scenario
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from depot_manager.config import DockingConfig, QueueConfig
from depot_manager.protocol import DepotGrant, RadioQuery, RadioReply, Refusal
from swarm_controllers.avoidance import ray_angles
from swarm_controllers.cpfa.behaviour import CpfaState
from swarm_controllers.queue.behaviour import (
    BRAKE_CONE,
    BRAKE_RANGE,
    KEEP_OUT_BAND,
    Phase,
    QueueBehaviour,
    _segment_hits_disc,
)
from swarm_msgs_py.types import NS_PER_S, Observation, Pose2D
from swarm_sim.analysis.metrics import summarize
from swarm_sim.batch import run_batch
from swarm_sim.world.tasks.foraging import ForagingSense

ROBOTS = 16
DURATION = 150.0
pytestmark = pytest.mark.xdist_group("queueing")  # one worker makes the module's runs (`run`) for all


@pytest.fixture(scope="module", params=[(name, model) for name in ("queue_qse", "queue_qst", "queue_qme", "queue_qmt")
                                         for model in ("footbot_cpfa", "generic")], ids="-".join)
def run(request):
    """Each queue scenario on the authors' foot-bot (as shipped) and on the generic robot; the
    foot-bot's stop-turn-go legs deliver later (150 s: 1, 1 and 6 resources for Q_ST, Q_ME and
    Q_MT), so it runs twice as long."""
    name, model = request.param
    duration = DURATION if model == "generic" else 2 * DURATION
    scenario = generic_scenario(name, [f"robots.model={model}", f"robots.count={ROBOTS}", f"sim.duration={duration}"])
    return scenario, run_batch(scenario, record_poses=True)


def test_deliveries_happen_at_docks_only(run):
    scenario, result = run
    summary = summarize(result.trace)
    # Entry-point joining walks the whole entry line (Q_SE's spiral is ~40 m long), so only
    # tail joining is sure to deliver several in a short run.
    expected = {"queue_qse": 0, "queue_qme": 1}.get(scenario.name, 3)
    assert summary["resources_delivered"] >= expected, summary
    assert summary["deliveries_outside_docks"] == 0
    assert all(d.zone.startswith("dock_") for d in result.trace.drops)
    for d in summary["dropoff_times_s"]:
        assert 0.0 <= d < scenario.sim.duration  # perimeter entry to dock arrival (before T_unload)


def test_only_carriers_enter_the_perimeter(run):
    """Inside the perimeter (less a robot radius) a robot is carrying, or is leaving after its
    drop, or is still leaving the start grid (robots start around the depot)."""
    scenario, result = run
    poses, trace = result.poses, result.trace
    dt = scenario.sim.dt
    R = DockingConfig.of(scenario).perimeter_radius - scenario.robots.diameter / 2
    r = np.hypot(poses[..., 0], poses[..., 1])
    for i, robot in enumerate(trace.robots):
        picks = sorted(p.stamp_ns / NS_PER_S for p in trace.pickups if p.robot == robot)
        drops = sorted(d.stamp_ns / NS_PER_S for d in trace.drops if d.robot == robot)
        left_start = np.flatnonzero(r[:, i] > R)
        if len(left_start) == 0:
            continue
        for k in range(left_start[0], len(r)):
            if r[k, i] >= R:
                continue
            t = k * dt
            carrying = any(p <= t for p in picks) and sum(p <= t for p in picks) > sum(d <= t for d in drops)
            leaving = any(0 <= t - d <= 60.0 for d in drops)  # exit line to the perimeter
            assert carrying or leaving, f"{robot} inside the perimeter at t={t:.1f} s, not carrying"


def test_queue_lengths_are_recorded(run):
    scenario, result = run
    lines = 1 if QueueConfig.of(scenario).wrapping == "single" else DockingConfig.of(scenario).docks
    assert result.trace.series["queue_lengths"], "the depot server recorded no queue lengths"
    assert all(len(q) == lines for _, q in result.trace.series["queue_lengths"])


def test_tail_joining_talks_over_the_radio_and_entry_joining_does_not():
    from depot_manager.protocol import RadioQuery

    for name, expect in (("queue_qmt", True), ("queue_qme", False)):
        scenario = generic_scenario(name, [f"robots.count={ROBOTS}", "sim.duration=120"])
        seen = []
        import swarm_sim.batch as batch

        original = batch.Router.post

        def post(self, message, seen=seen, original=original):
            if isinstance(message, RadioQuery):
                seen.append(message)
            original(self, message)

        batch.Router.post = post
        try:
            run_batch(scenario)
        finally:
            batch.Router.post = original
        assert bool(seen) == expect, name


def test_a_non_carrier_is_steered_out_of_the_perimeter():
    scenario = generic_scenario("queue_qmt", ["robots.count=1"])
    b = QueueBehaviour(scenario, "robot_0", np.random.default_rng(0))
    from swarm_msgs_py.types import Observation, Pose2D

    ranges = np.full(scenario.sensors.scan.rays, np.inf, dtype=np.float32)
    obs = Observation("robot_0", 0, Pose2D(1.0, 0.0, math.pi), 0.0, 0.0, ranges, ForagingSense((), False))
    cmd = b.step(obs)  # facing the depot: turn round (outward) before driving
    assert b.phase is Phase.FORAGING
    assert abs(cmd.angular) > 0.5 and cmd.linear < 0.05


def test_segment_disc_intersection():
    assert _segment_hits_disc((-3, 0), (3, 0), (0, 0), 1.0)
    assert not _segment_hits_disc((-3, 2), (3, 2), (0, 0), 1.0)
    assert not _segment_hits_disc((2, 0), (5, 0), (0, 0), 1.0)
    assert KEEP_OUT_BAND > 0


def test_perimeter_delay_covers_the_drop_off(run):
    """The paper's time delay (entering to leaving the perimeter) contains the drop-off time."""
    _, result = run
    summary = summarize(result.trace)
    if summary["perimeter_delay_mean_s"] is not None:
        assert summary["perimeter_delay_mean_s"] > 0
        assert summary["dropoff_time_mean_s"] is not None


def test_replies_and_grants_naming_slots_that_do_not_exist_are_dropped():
    from depot_manager.protocol import DepotGrant, RadioReply
    from swarm_sim.registry import make_behaviour

    s = generic_scenario("queue_qmt", ["robots.count=2"])
    b = make_behaviour(s, "robot_0", np.random.default_rng(0))
    b._phase = Phase.SEEKING
    ranges = np.full(24, np.inf, dtype=np.float32)
    bad = (RadioReply(0, "robot_1", "robot_0", 1.0, 0.0, "entry_line_0", 10**9, False),
           RadioReply(0, "robot_1", "robot_0", 1.0, 0.0, "nowhere", 1, False),
           DepotGrant(0, "robot_0", "entry_line_0", 10**6))
    obs = Observation("robot_0", 10**8, Pose2D(1.0, 0.0, 0.0), 0.0, 0.0, ranges, ForagingSense((), True), bad)
    b._handle(obs, [])  # the message handling alone, in the phase that listens to replies
    assert b.rejections.counts == {("RadioReply", "refused"): 2, ("DepotGrant", "refused"): 1}
    b.step(obs)  # and a whole step with them does not fail


def test_the_depot_manager_ignores_reports_from_robots_that_do_not_exist():
    from depot_manager.protocol import DepotReport, ReportKind
    from depot_manager.server import DepotServer

    server = DepotServer(generic_scenario("queue_qmt", ["robots.count=4"]))
    out = server.step(10**9, [DepotReport(0, f"robot_{900 + k}", ReportKind.JOIN, "entry_line_0", k) for k in range(4)])
    assert out == () and server.admission.robots_inside == ()
    assert server.rejections.counts == {("DepotReport", "unknown robot"): 4}


def test_dropoff_time_stops_at_the_dock_before_t_unload():
    from swarm_controllers.queue.perimeter import PROBE, Crossings, dock_arrival_s, dropoff_times
    from swarm_msgs_py.types import DropEvent
    from swarm_sim.analysis.metrics import RunTrace

    s = generic_scenario("queue_qmt")
    drop = DropEvent("robot_0", 100 * NS_PER_S, 3, "dock_0", 0.585, 0.0)
    trace = RunTrace("queue_qmt", 0, ("robot_0",), 120.0, 1.0, 320, "batch", drops=[drop], config=s,
                     probes={PROBE: Crossings(entries={"robot_0": [10.0, 40.0]})})
    # the foraging task drops on the first tick the carrier has been inside for T_unload
    assert dock_arrival_s(trace, drop) == pytest.approx(100.0 - DockingConfig.of(s).unload_time)
    assert dropoff_times(trace) == [pytest.approx(100.0 - DockingConfig.of(s).unload_time - 40.0)]


class _Everyone:
    def __contains__(self, robot: object) -> bool:
        return True


_ROBOTS = ("robot_0", "robot_1", "robot_2")
_LINES = ("entry_line_0", "entry_line_1", "nowhere")
_near_x, _near_y = st.floats(0.4, 1.6), st.floats(-0.6, 0.6)  # about the robot at (1, 0): in radio range or not
_queue_messages = st.lists(st.one_of(
    st.builds(DepotGrant, st.just(0), st.sampled_from(_ROBOTS), st.sampled_from(_LINES), st.integers(-1, 4),
              st.booleans(), st.sampled_from(list(Refusal))),
    st.builds(RadioQuery, st.just(0), st.sampled_from(_ROBOTS), _near_x, _near_y),
    st.builds(RadioReply, st.just(0), st.sampled_from(_ROBOTS), st.sampled_from(_ROBOTS), _near_x, _near_y,
              st.sampled_from(("", *_LINES)), st.integers(-1, 4), st.booleans()),
), max_size=6).map(tuple)


def _handled(phase, messages, join, line, cell, *, read_all: bool):
    """Command and state of robot_0 at (1, 0) after a step with `messages` (or, read_all, after
    the reference: every message read)."""
    s = generic_scenario("queue_qmt", ["robots.count=3"])
    b = QueueBehaviour(s, "robot_0", np.random.default_rng(0))
    b._phase, b._join, b._line, b._cell = phase, join, line, cell
    ranges = np.full(24, np.inf, dtype=np.float32)
    obs = Observation("robot_0", 10**9, Pose2D(1.0, 0.0, 0.0), 0.0, 0.0, ranges, ForagingSense((), True), messages)
    if read_all:
        with mock.patch("swarm_controllers.queue.behaviour._granted", lambda _messages: _Everyone()):
            command = b.step(obs)
    else:
        command = b.step(obs)
    names = ("_phase", "_join", "_line", "_cell", "_grant", "_last", "_retry_at", "_yield_until", "_goal")
    return command, [getattr(b, n) for n in names], b.rejections.counts, b._rng.bit_generator.state


_INBOX = (
    RadioQuery(0, "robot_1", 1.1, 0.0),
    RadioReply(0, "robot_1", "robot_0", 1.1, 0.1, "entry_line_0", 3, True),
    DepotGrant(0, "robot_2", "entry_line_0", 2),
)


@pytest.mark.parametrize("phase", list(Phase))
@pytest.mark.parametrize("grant", [None, DepotGrant(0, "robot_0", "entry_line_0", 2),
                                   DepotGrant(0, "robot_0", "entry_line_0", -1, reason=Refusal.NOT_BEHIND_TAIL)])
def test_message_handling_skips_only_what_cannot_matter(phase, grant):
    """A step does not read the messages of a robot neither queued nor seeking that no grant is
    for; reading every message instead (the reference) gives the same command, state and
    replies, in every phase, with a grant for the robot before the others or none."""
    inbox = _INBOX if grant is None else (grant, *_INBOX)
    args = (phase, inbox, ("entry_line_0", 3), "entry_line_0", 1)
    assert _handled(*args, read_all=False) == _handled(*args, read_all=True)


@settings(max_examples=300)
@given(st.sampled_from(list(Phase)), _queue_messages,
       st.one_of(st.none(), st.tuples(st.sampled_from(_LINES[:2]), st.integers(0, 4))),
       st.sampled_from(("", *_LINES[:2])), st.integers(-1, 3))
def test_message_handling_skips_only_what_cannot_matter_for_any_inbox(phase, messages, join, line, cell):
    assume(line or phase is not Phase.QUEUED)  # a queued robot is on a line
    args = (phase, messages, join, line, cell)
    assert _handled(*args, read_all=False) == _handled(*args, read_all=True)


@pytest.mark.parametrize("name", ["queue_qse", "queue_qmt"])
def test_the_slots_looked_up_every_tick_are_the_managers_cells(name):
    b = QueueBehaviour(generic_scenario(name), "robot_0", np.random.default_rng(0))
    assert b._slots.keys() == b._cells.keys()
    for line, cells in b._cells.items():
        assert b._slots[line] == [(float(x), float(y)) for x, y in cells]
        assert all(type(v) is float for xy in b._slots[line] for v in xy)


def _queued_robot() -> tuple[QueueBehaviour, Pose2D]:
    """robot_0 queued at slot 1 of entry_line_0, granted slot 3, facing slot 2 from 5 cm short
    of it: it drives on unless it brakes."""
    b = QueueBehaviour(generic_scenario("queue_qmt"), "robot_0", np.random.default_rng(0))
    b._phase, b._line, b._cell, b._grant = Phase.QUEUED, "entry_line_0", 1, ("entry_line_0", 3)
    (x1, y1), (x2, y2) = b._slots["entry_line_0"][1:3]
    yaw = math.atan2(y2 - y1, x2 - x1)
    return b, Pose2D(x2 - 0.05 * math.cos(yaw), y2 - 0.05 * math.sin(yaw), yaw)


@settings(max_examples=200)
@given(st.lists(st.floats(0.0, 0.25, width=32) | st.just(float(np.float32(BRAKE_RANGE))) | st.just(math.inf), min_size=24,
                max_size=24))
def test_a_queued_robot_brakes_as_the_float32_scan_compares(ranges):
    """The braking cone's rays, read as Python floats, brake exactly when the float32 rays
    compared with BRAKE_RANGE did (numpy compares a float32 with a Python float in float32)."""
    b, pose = _queued_robot()
    scan = np.asarray(ranges, dtype=np.float32)
    cone = [i for i, a in enumerate(ray_angles(generic_scenario("queue_qmt").sensors.scan)) if abs(a) <= BRAKE_CONE]
    brakes = bool(min(scan[i] for i in cone) < BRAKE_RANGE)  # the reference: numpy's comparison
    command = b.step(Observation("robot_0", 10**9, pose, 0.0, 0.0, scan, ForagingSense((), True)))
    assert (command.linear == 0.0) == brakes


def test_a_ray_at_the_float32_brake_range_does_not_brake_and_one_below_does():
    b, pose = _queued_robot()
    scan = np.full(24, np.inf, dtype=np.float32)
    scan[12] = np.float32(BRAKE_RANGE)  # 0.0799999982 < 0.08 as float64, equal as float32
    assert b.step(Observation("robot_0", 10**9, pose, 0.0, 0.0, scan, ForagingSense((), True))).linear > 0.0
    scan[12] = np.nextafter(np.float32(BRAKE_RANGE), np.float32(0.0))
    assert b.step(Observation("robot_0", 2 * 10**9, pose, 0.0, 0.0, scan, ForagingSense((), True))).linear == 0.0


@pytest.mark.parametrize("patience", [3.0, 100000.0])
def test_a_queued_robot_braked_past_its_patience_swerves_and_one_with_the_authors_rule_stands(patience):
    """``controller.queue.brake_patience``: blocked right in front, a queued robot stands; once braked
    that long it swerves round the block (our deadlock breaker), and with a patience beyond the run
    (the queue authors' robots on their path: ``Stop()`` only) it stands for good."""
    from swarm_sim.scenario import ScenarioError

    b = QueueBehaviour(generic_scenario("queue_qmt", [f"controller.queue.brake_patience={patience}"]), "robot_0",
                       np.random.default_rng(0))
    b._phase, b._line, b._cell, b._grant = Phase.QUEUED, "entry_line_0", 1, ("entry_line_0", 3)
    _, pose = _queued_robot()
    scan = np.full(24, np.inf, dtype=np.float32)
    scan[12] = 0.05  # a robot right in front of it
    twists = [(c.linear, c.angular) for c in
              (b.step(Observation("robot_0", k * 10**8, pose, 0.0, 0.0, scan, ForagingSense((), True)))
               for k in range(1, 101))]  # 10 s
    braked = twists[0]  # standing, turned toward its slot
    assert braked[0] == 0.0 and set(twists[:29]) == {braked}  # its first 3 s either way
    assert (set(twists[29:]) != {braked}) == (patience < 10.0)
    with pytest.raises(ScenarioError, match="controller.queue.brake_patience"):
        generic_scenario("queue_qmt", ["controller.queue.brake_patience=0"])


def test_the_slot_pitch_key_spaces_the_lines_cells_and_is_checked():
    """``controller.queue.slot_pitch`` (the paper gives none; default the lane spacing): the cells
    along every line lie one pitch apart; one below the robot's diameter is refused by name."""
    from swarm_sim.scenario import ScenarioError

    for pitch in (None, 0.3):
        s = generic_scenario("queue_qst", [] if pitch is None else [f"controller.queue.slot_pitch={pitch}"])
        b = QueueBehaviour(s, "robot_0", np.random.default_rng(0))
        for line in b._entry_lines:
            gaps = np.linalg.norm(np.diff(np.asarray(b._slots[line]), axis=0), axis=1)
            np.testing.assert_allclose(gaps[:-1], pitch or 0.2, atol=1e-6)  # the last one ends where the line does
    with pytest.raises(ScenarioError, match="slot_pitch"):
        generic_scenario("queue_qst", ["controller.queue.slot_pitch=0.1"])


def test_a_robot_that_lost_its_resource_on_the_way_reports_unloaded_at_its_dock():
    """A carrier that stood T_unload in a dock's zone on the way lost its resource there: at its own
    dock it says unloaded at once (the manager refuses an unload anywhere but the dock, and the
    dock would wait for it forever); one that drops on the way reports nothing there."""
    from depot_manager.protocol import DepotReport, ReportKind

    b = QueueBehaviour(generic_scenario("queue_qmt"), "robot_0", np.random.default_rng(0))
    (dock_line, dock_cell), = [d for d in b._docks if d[0] == "entry_line_0"]
    b._phase, b._line, b._cell, b._grant = Phase.QUEUED, dock_line, dock_cell - 2, (dock_line, dock_cell)
    b._carrying = True
    x, y = b._slots[dock_line][dock_cell - 2]
    dropped = b.step(Observation("robot_0", 10**9, Pose2D(x, y, 0.0), 0.0, 0.0, np.full(24, np.inf, np.float32),
                                 ForagingSense((), False)))
    assert not [m for m in dropped.messages if isinstance(m, DepotReport) and m.kind is ReportKind.UNLOADED]
    b._cell = dock_cell - 1
    x, y = b._slots[dock_line][dock_cell]
    at = b.step(Observation("robot_0", 2 * 10**9, Pose2D(x, y, 0.0), 0.0, 0.0, np.full(24, np.inf, np.float32),
                            ForagingSense((), False)))
    kinds = [(m.kind, m.line, m.cell) for m in at.messages if isinstance(m, DepotReport)]
    assert kinds == [(ReportKind.AT, dock_line, dock_cell), (ReportKind.UNLOADED, dock_line, dock_cell)]


@pytest.mark.parametrize("timeout", [3.0, 120.0])
def test_a_tail_seeker_falls_back_to_entry_joining_after_seek_timeout(timeout):
    """``controller.queue.seek_timeout`` (our addition; the paper's searcher has no give-up): a
    carrier that has not joined by then heads for an entry point instead."""
    from swarm_sim.registry import make_behaviour
    from swarm_sim.scenario import ScenarioError

    s = generic_scenario("queue_qst", ["robots.count=2", f"controller.queue.seek_timeout={timeout}"])
    assert QueueConfig.of(s).seek_timeout == timeout
    b = make_behaviour(s, "robot_0", np.random.default_rng(0))
    ranges = np.full(s.sensors.scan.rays, np.inf, dtype=np.float32)
    x = DockingConfig.of(s).perimeter_radius - 0.1  # inside the perimeter, carrying: it starts seeking
    phases = []
    for k in range(40):  # 4 s, standing where it is (nobody answers)
        b.step(Observation("robot_0", k * s.dt_ns, Pose2D(x, 0.0, math.pi), 0.0, 0.0, ranges, ForagingSense((), True)))
        phases.append(b._phase)
    assert phases[0] is Phase.SEEKING
    assert (phases[-1] is Phase.TO_ENTRY) == (timeout < 4.0)
    with pytest.raises(ScenarioError, match="controller.queue.seek_timeout"):
        generic_scenario("queue_qst", ["controller.queue.seek_timeout=0"])


def test_innermost_boarding_asks_for_the_innermost_arcs_nearest_cell_and_never_radios():
    """``controller.queue.boarding=innermost`` (the queue authors' Q_ST): a carrier heads straight
    in and asks to join the innermost arc at its nearest cell; with ``radio`` it queries first."""
    from depot_manager.protocol import DepotReport, ReportKind
    from swarm_sim.registry import make_behaviour

    for boarding in ("innermost", "radio"):
        s = generic_scenario("queue_qst", ["robots.count=2", f"controller.queue.boarding={boarding}"])
        b = make_behaviour(s, "robot_0", np.random.default_rng(0))
        near = np.full(s.sensors.scan.rays, 0.3, dtype=np.float32)  # something within radio range
        sent = []
        x = b._layout.inner_radius + b._lane  # at the inner region's boundary, carrying
        for k in range(20):
            sent += b.step(Observation("robot_0", k * s.dt_ns, Pose2D(x, 0.0, math.pi), 0.0, 0.0, near,
                                       ForagingSense((), True))).messages
        joins = [m for m in sent if isinstance(m, DepotReport) and m.kind is ReportKind.JOIN]
        queries = [m for m in sent if isinstance(m, RadioQuery)]
        if boarding == "radio":
            assert queries
            continue
        assert not queries and joins
        cells = b._cells[joins[0].line]
        r = np.hypot(*cells.T)
        assert math.hypot(*cells[joins[0].cell]) < r.min() + b._lane / 2  # on the innermost arc
        assert math.hypot(cells[joins[0].cell][0] - x, cells[joins[0].cell][1]) < 0.25  # the nearest


def test_queued_motion_continuous_drives_the_lines_only_with_the_generic_steering():
    """``controller.queue.queued_motion`` (a diagnostic): on the foot-bot the queue's lines take the
    generic robot's continuous drive, foraging keeps the model's stop-turn-go."""
    from swarm_controllers.motion import ContinuousDrive
    from swarm_controllers.robots.stop_turn_go import StopTurnGo
    from swarm_sim.registry import make_behaviour

    for motion, line_drive in (("model", StopTurnGo), ("continuous", ContinuousDrive)):
        s = generic_scenario("queue_qst", ["robots.count=2", "robots.model=footbot_cpfa",
                                           f"controller.queue.queued_motion={motion}"])
        b = make_behaviour(s, "robot_0", np.random.default_rng(0))
        assert isinstance(b._drive, StopTurnGo) and isinstance(b._line_drive, line_drive)
        # a continuous drive turns and goes at once; stop-turn-go first stands for its plan
        lin, ang = b._line_to_point(0.0, 0.0, 0.0, 1.0, 0.3)
        assert (lin > 0 and ang > 0) == (motion == "continuous")


@pytest.mark.parametrize("leg", ["centre", "rim"])
def test_a_foot_bot_carriers_return_leg_ends_where_return_leg_says(leg):
    """``controller.queue.return_leg``: a foot-bot's legs run blind, so a carrier's return leg aimed
    at the depot centre (``centre``) carries it on past the inner region's boundary, where its
    seek stops, once it has asked to join there; aimed just outside the perimeter (``rim``, the
    queue authors' ``CPFA_controller::Returning``) it ends there and the seek's own leg stops at
    the boundary. Poses integrated from the commands, nothing around."""
    s = generic_scenario("queue_qst", ["robots.model=footbot_cpfa", "robots.count=1",
                                       f"controller.queue.return_leg={leg}"])
    b = QueueBehaviour(s, "robot_0", np.random.default_rng(0))
    b._cpfa._carrying, b._cpfa._state = True, CpfaState.RETURNING
    x, y, yaw, dt = 3.0, 0.0, math.pi, s.sim.dt
    empty = np.full(s.sensors.scan.rays, np.inf, dtype=np.float32)
    r_min = math.inf
    for k in range(1, 400):  # 40 s
        c = b.step(Observation("robot_0", k * s.dt_ns, Pose2D(x, y, yaw), 0.0, 0.0, empty, ForagingSense((), True)))
        yaw += c.angular * dt
        x, y = x + c.linear * dt * math.cos(yaw), y + c.linear * dt * math.sin(yaw)
        r_min = min(r_min, math.hypot(x, y))
    boundary = b._layout.inner_radius + b._lane
    assert b.phase in (Phase.JOINING, Phase.QUEUED)  # it asked for a cell at the boundary either way
    if leg == "centre":
        assert r_min < 0.6  # on across the innermost lane, toward the depot
    else:
        assert boundary - 0.05 < r_min < boundary + 0.1


@pytest.mark.parametrize("reach", [0.05, 0.1])
def test_a_queued_robot_reaches_an_entry_cell_within_entry_reach_and_a_dock_within_the_slot_tolerance(reach):
    """``controller.queue.entry_reach`` (the queue authors' 0.1 m waypoint threshold): 8 cm short
    of its next entry-line cell a queued robot has reached it (reports it) with 0.1 and not with
    0.05; 8 cm short of its dock it has not reached it either way (it must stand in the dock's zone)."""
    from depot_manager.protocol import DepotReport, ReportKind
    from swarm_sim.scenario import ScenarioError

    s = generic_scenario("queue_qmt", [f"controller.queue.entry_reach={reach}"])
    empty = np.full(s.sensors.scan.rays, np.inf, dtype=np.float32)
    b = QueueBehaviour(s, "robot_0", np.random.default_rng(0))
    dock_line, dock_cell = next(iter(sorted(b._docks)))
    for line, cell, dock in (("entry_line_0", 2, False), (dock_line, dock_cell, True)):
        b._phase, b._line, b._cell, b._grant = Phase.QUEUED, line, cell - 1, (line, cell)
        (x1, y1), (x2, y2) = b._slots[line][cell - 1:cell + 1]
        yaw = math.atan2(y2 - y1, x2 - x1)
        pose = Pose2D(x2 - 0.08 * math.cos(yaw), y2 - 0.08 * math.sin(yaw), yaw)
        sent = b.step(Observation("robot_0", 10**9, pose, 0.0, 0.0, empty, ForagingSense((), True))).messages
        reached = any(isinstance(m, DepotReport) and m.kind is ReportKind.AT and m.cell == cell for m in sent)
        assert reached == (reach == 0.1 and not dock)
    with pytest.raises(ScenarioError, match="controller.queue.entry_reach"):
        generic_scenario("queue_qmt", ["controller.queue.entry_reach=0.11"])  # over half a 0.2 m cell


@pytest.mark.parametrize("motion", ["model", "continuous"])
def test_line_stop_chooses_the_rule_that_halts_a_robot_on_the_lines(motion):
    """``controller.queue.line_stop`` (a diagnostic): ``model`` is the line drive's own path rule (the
    foot-bot's stop-turn-go: the authors' ring cone; continuous steering: none, so our brake);
    ``brake`` is never a path rule; ``ring`` is the authors' cone on either drive. A robot 0.22 m
    dead ahead (centre to centre; the scan reads its near side) is within the ring's reach; one
    abeam is outside the cone."""
    from swarm_controllers.avoidance import ray_angles
    from swarm_sim.registry import make_behaviour

    for stop, want in (("model", True if motion == "model" else None), ("brake", None), ("ring", True)):
        s = generic_scenario("queue_qst", ["robots.count=2", "robots.model=footbot_cpfa",
                                           f"controller.queue.queued_motion={motion}",
                                           f"controller.queue.line_stop={stop}"])
        b = make_behaviour(s, "robot_0", np.random.default_rng(0))
        angles = np.asarray(ray_angles(s.sensors.scan))
        for bearing, hit in ((0.0, want), (math.pi / 2, None if want is None else False)):
            ranges = np.full(len(angles), np.inf, dtype=np.float32)
            ranges[int(np.argmin(np.abs(np.angle(np.exp(1j * (angles - bearing))))))] = 0.22 - 0.085  # its near side
            assert b._path_stop(ranges, 30.0) == hit, (stop, bearing)
