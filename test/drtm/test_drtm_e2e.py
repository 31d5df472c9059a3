"""End-to-end: DRTM on the real graph (world, one controller node per robot, the nest node over
DDS). The nest's state is in the bag on every tick, latched, and tells the ledger's story; the
bag gives the same DRTM measures as the in-process batch run of the same seed."""

from __future__ import annotations

import yaml
from graph_helpers import overrides, run_graph

from swarm_controllers.drtm.codec import NEST, NEST_REPORTS, NEST_STATE
from swarm_controllers.drtm.protocol import NestEvent, NestReport, NestState
from swarm_sim.analysis.metrics import summarize
from swarm_sim.batch import run_batch
from swarm_sim.recording import bag_info, read_bag
from swarm_sim.scenario import load_scenario

ROBOTS = 5
DURATION = 40.0
BUSY = ["resources.count=60"]
"""More food than the paper's 20 so that robots deliver within 40 s."""
NEST_FIELDS = ("food_deviation", "energy_efficiency", "oae_total", "food_collected", "nest_food_final",
               "nest_food_series", "active_robots_series", "oae_series", "oae_by_robot", "trips_by_robot",
               "oae_by_state", "oae_returning_total")


def test_drtm_graph_run_publishes_the_nest_state_every_tick(tmp_path):
    bag = tmp_path / "drtm"
    summary = run_graph(bag, "--scenario", "drtm", "--robots", str(ROBOTS), "--duration", str(DURATION),
                        "--controller-processes", "0", *overrides(BUSY))
    assert summary["stale_ticks"] == 0 and summary["server_stale_ticks"] == 0, summary
    assert summary["food_collected"] >= 1, summary

    meta = yaml.safe_load((bag / "metadata.yaml").read_text())["rosbag2_bagfile_information"]
    qos = {t["topic_metadata"]["name"]: t["topic_metadata"]["offered_qos_profiles"]
           for t in meta["topics_with_message_count"]}
    assert "transient_local" in str(qos[NEST_STATE])  # latched: a late echo gets it at once
    assert bag_info(bag).message_counts.get(NEST_REPORTS, 0) > 0

    states: list[NestState] = []
    reports: list[NestReport] = []
    for m in read_bag(bag):
        if m.topic == NEST_STATE:
            states.extend(NEST.decode(m.data))
        elif m.topic == NEST_REPORTS:
            reports.extend(NEST.decode(m.data))
    ticks = round(DURATION / 0.1)
    assert [s.stamp_ns for s in states] == [k * 100_000_000 for k in range(ticks)]  # one per tick
    assert (states[0].food, states[0].waiting, states[0].total_oaes) == (5.0, ROBOTS, 0)
    assert min(s.waiting for s in states) < ROBOTS  # robots went foraging
    left = [r for r in reports if r.event is NestEvent.LEFT]
    assert left and min(r.stamp_ns for r in left) >= 50 * 100_000_000  # nobody before T_1 = 50 ticks
    deposits = sum(r.event is NestEvent.DEPOSITED for r in reports)
    assert deposits >= 1
    # F changes only through deliveries and consumption: without a deposit in between it falls
    arrivals = sorted(r.stamp_ns for r in reports if r.event is NestEvent.DEPOSITED)
    for a, b in zip(states, states[1:]):
        if not any(a.stamp_ns - 100_000_000 <= t < b.stamp_ns for t in arrivals):
            assert b.food < a.food
    assert states[-1].total_oaes == sum(r.event is NestEvent.AVOIDED for r in reports if r.stamp_ns < states[-1].stamp_ns)

    scenario = load_scenario("drtm", [f"robots.count={ROBOTS}", f"sim.duration={DURATION}", *BUSY])
    batch = summarize(run_batch(scenario).trace)
    for key in NEST_FIELDS:
        assert batch[key] == summary[key], key
