"""End-to-end: Q_MT on the real graph (world, 16 controller nodes, depot-manager node over DDS).
Deliveries happen at docks only; the manager's grants, state and markers are in the bag; the
bag gives the same metrics as the in-process batch run of the same seed."""

from __future__ import annotations

from graph_helpers import overrides, run_graph

from depot_manager.codec import DEPOT, DEPOT_GRANTS, DEPOT_MARKERS, DEPOT_REPORTS, DEPOT_STATE, RADIO_TOPIC
from depot_manager.protocol import DepotGrant, DepotReport, ReportKind
from depot_manager.state import queue_lengths
from swarm_msgs_py import server_state, topics
from swarm_sim.analysis.metrics import summarize
from swarm_sim.analysis.replay import load_run
from swarm_sim.batch import run_batch
from swarm_sim.recording import bag_info, read_bag
from swarm_sim.scenario import load_scenario

ROBOTS = 16
DURATION = 80.0
BUSY_DEPOT = ["arena.size=7.0", "resources.distribution=uniform", "resources.count=200"]
"""A small arena thick with resources: the foot-bots (as shipped, seed 0) deliver 3 by 80 s, with
up to 15 robots queued at the depot (the paper's arena took 150 s for 6)."""


def test_qmt_graph_run_delivers_at_docks_only(tmp_path):
    bag = tmp_path / "qmt"
    summary = run_graph(bag, "--scenario", "queue_qmt", "--robots", str(ROBOTS), "--duration", str(DURATION),
                        *overrides(BUSY_DEPOT))
    assert summary["stale_ticks"] == 0, summary
    assert summary["resources_delivered"] >= 3, summary
    assert summary["deliveries_outside_docks"] == 0

    trace = load_run(bag)
    assert trace.drops and all(d.zone.startswith("dock_") for d in trace.drops)
    counts = bag_info(bag).message_counts
    for topic in (DEPOT_REPORTS, DEPOT_GRANTS, DEPOT_STATE, DEPOT_MARKERS,
                  RADIO_TOPIC, topics.LOCKSTEP_ACK):
        assert counts.get(topic, 0) > 0, topic
    assert counts[topics.LOCKSTEP_ACK] >= DURATION / 0.1

    grants, reports, lengths = [], [], []
    for m in read_bag(bag):
        if m.topic == DEPOT_GRANTS:
            grants += DEPOT.decode(m.data)
        elif m.topic == DEPOT_REPORTS:
            reports += DEPOT.decode(m.data)
        elif m.topic == DEPOT_STATE:
            lengths.append(queue_lengths(server_state.decode_state(m.data)[1]))
    assert all(isinstance(g, DepotGrant) for g in grants) and all(isinstance(r, DepotReport) for r in reports)
    unloaded = {r.robot for r in reports if r.kind is ReportKind.UNLOADED}
    assert unloaded == {d.robot for d in trace.drops}
    assert all(len(q) == 4 for q in lengths)

    # the same seed in process gives the same run
    scenario = load_scenario("queue_qmt", [*BUSY_DEPOT, f"robots.count={ROBOTS}", f"sim.duration={DURATION}"])
    batch = summarize(run_batch(scenario).trace)
    assert summary["authors_collision_time_per_robot_s"] is not None
    for key in ("resources_delivered", "collision_time_per_robot_s", "dropoff_times_s", "perimeter_delay_mean_s",
                "queue_length_max", "authors_collision_time_per_robot_s", "authors_collision_time_total_min"):
        assert batch[key] == summary[key], key
