"""How many velocities pybullet is told a tick, and how many robots are tilted: what planar robots save.

    python benchmarks/velocity_sets.py --robots 112 --warmup 60 --duration 60
    python benchmarks/velocity_sets.py --robots 1000 --warmup 60 --duration 20 --set robots.planar=true

A machine-independent count (the world's ``resetBaseVelocity`` calls, `World._set_velocities`),
for the speed figures that the load of a shared machine blurs: each call costs ~0.7 us. Runs
`run_batch` with the world's row selection (`swarm_sim.world.core._stale_rows`) and pose read-back
counted, over the ticks after ``--warmup`` sim seconds; arenas scaled as `profile_batch.py` does.
"""

from __future__ import annotations

import argparse
import sys

import numpy as np
from profile_batch import scaled_fields

import swarm_sim.world.core as core
from swarm_sim.batch import run_batch
from swarm_sim.scenario import load_scenario
from swarm_sim.world.core import tune_malloc


def count(scenario_name: str, robots: int, warmup: float, duration: float, overrides: list[str],
          arena: float | None) -> dict:
    scenario = load_scenario(scenario_name, overrides, **scaled_fields(scenario_name, robots, arena),
                             sim__duration=warmup + duration)
    sets: list[int] = []
    tilted: list[int] = []
    stale, read = core._stale_rows, core.World._read_state

    def counted(*args):
        k = stale(*args)
        sets.append(k)
        return k

    def read_counted(world):
        read(world)
        tilted.append(int((~world._upright).sum()))

    core._stale_rows, core.World._read_state = counted, read_counted
    try:
        run = run_batch(scenario)
    finally:
        core._stale_rows, core.World._read_state = stale, read
    w0 = round(warmup / scenario.sim.dt)
    per_tick = np.array(sets).reshape(-1, scenario.sim.physics_substeps).sum(axis=1)[w0:]
    return {"scenario": scenario_name, "robots": robots, "model": scenario.robots.model,
            "planar": scenario.robots.planar, "velocity_sets_per_tick": round(float(per_tick.mean()), 1),
            "tilted_robots_per_tick": round(float(np.mean(tilted[w0 + 1:])), 1),
            "delivered": len(run.trace.drops)}


def main(argv: list[str] | None = None) -> int:
    tune_malloc()  # as the commands that run a world do (`tune_malloc`): time it as they run it
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenario", default="queue_qmt")
    parser.add_argument("--robots", type=int, nargs="+", default=[112, 1000])
    parser.add_argument("--warmup", type=float, default=60.0)
    parser.add_argument("--duration", type=float, default=20.0)
    parser.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE")
    args = parser.parse_args(argv)
    for n in args.robots:
        print(count(args.scenario, n, args.warmup, args.duration, args.overrides, 38.0 if n >= 1000 else None),
              flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
