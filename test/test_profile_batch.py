"""The batch profiler (benchmarks/profile_batch.py): its phases add up, and it changes nothing."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import numpy as np

import swarm_sim.batch as batch
import swarm_sim.world.core as world_core
from swarm_controllers.avoidance import ObstacleAvoidance
from swarm_sim.batch import run_batch
from swarm_sim.scenario import load_scenario

_PATH = Path(__file__).resolve().parents[1] / "benchmarks" / "profile_batch.py"
_spec = importlib.util.spec_from_file_location("profile_batch", _PATH)
profile_batch = importlib.util.module_from_spec(_spec)
sys.modules[_spec.name] = profile_batch  # dataclasses look their module up there
_spec.loader.exec_module(profile_batch)


def test_phases_add_up_and_the_run_is_unchanged():
    scenario = load_scenario("queue_qmt", robots__count=4, sim__duration=3.0)
    def patched_names():
        return (batch.World, batch.make_behaviour, batch.Router, world_core.cast_scan, world_core.p,
                ObstacleAvoidance.update)

    names = patched_names()
    prof = profile_batch.profile_run(scenario, record_poses=True)
    assert patched_names() == names  # every swapped name is restored
    assert prof.ticks == scenario.ticks
    assert all(v >= 0.0 for v in prof.phases.values()), prof.phases
    assert abs(sum(prof.phases.values()) - prof.window_s) <= 0.05 * prof.window_s
    assert prof.window_s <= prof.run_s
    for phase in ("world: physics: pybullet stepSimulation", "world: ray casting", "behaviours: QueueBehaviour.step",
                  "behaviours: obstacle avoidance", "servers: DepotServer.step", "bookkeeping: probes (perimeter log)"):
        assert any(name.startswith(phase) for name in prof.phases), (phase, sorted(prof.phases))
    assert prof.calls["behaviours: QueueBehaviour.step"] == 4 * scenario.ticks
    plain = run_batch(scenario, record_poses=True)
    np.testing.assert_array_equal(prof.run.poses, plain.poses)
    assert prof.run.trace.status == plain.trace.status
    assert prof.run.trace.stats == plain.trace.stats
    assert profile_batch.profile_run(scenario, warmup_ticks=10).ticks == scenario.ticks - 10


def test_scaled_arena_scales_the_resource_clusters_with_the_area():
    fields = profile_batch.scaled_fields("cpfa", 1000, 38.0)
    assert fields["arena__size"] == 38.0
    assert fields["resources__count"] == fields["resources__clusters"] * 64 == 3200
    assert profile_batch.scaled_fields("cpfa", 112, None) == {"robots__count": 112}


def test_a_bad_scenario_or_key_is_one_line_and_exit_2(capsys):
    for argv in (["--scenario", "nope", "--robots", "4", "--duration", "1"],
                 ["--scenario", "cpfa", "--robots", "4", "--duration", "1", "--set", "sim.dt=-1"]):
        assert profile_batch.main(argv) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and err[0].startswith("profile_batch: ") and "Traceback" not in err[0]
