"""Batch runner speed: sim seconds per wall second on one core (CPFA, 12 x 12 m, 320 resources).

    python benchmarks/bench_batch.py [--robots 112] [--duration 120]
"""

from __future__ import annotations

import argparse
import cProfile
import pstats
import resource
import time

from swarm_sim.batch import run_batch
from swarm_sim.scenario import ScenarioError, load_scenario
from swarm_sim.world.core import tune_malloc


def main() -> None:
    tune_malloc()  # as the commands that run a world do (`tune_malloc`): time it as they run it
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robots", type=int, nargs="+", default=[16, 64, 112])
    parser.add_argument("--duration", type=float, default=120.0)
    parser.add_argument("--scenario", default="cpfa")
    parser.add_argument("--profile", action="store_true", help="print the top functions of the last run")
    args = parser.parse_args()
    for n in args.robots:
        scenario = load_scenario(args.scenario, robots__count=n, sim__duration=args.duration)
        profiler = cProfile.Profile() if args.profile else None
        t0 = time.perf_counter()
        if profiler:
            profiler.enable()
        run = run_batch(scenario)
        if profiler:
            profiler.disable()
        wall = time.perf_counter() - t0
        print(f"batch {args.scenario} robots={n:4d} sim={args.duration:.0f}s wall={wall:6.2f}s "
              f"rtf={args.duration / wall:6.1f}x  ms/tick={1e3 * wall / scenario.ticks:5.2f}  "
              f"delivered={len(run.trace.drops)}", flush=True)
        if profiler:
            pstats.Stats(profiler).sort_stats("tottime").print_stats(15)
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"peak RSS {peak:.0f} MB")


if __name__ == "__main__":
    try:
        main()
    except ScenarioError as exc:  # a bad --scenario or --set: one line, no traceback
        raise SystemExit(f"bench_batch: {exc}") from None
