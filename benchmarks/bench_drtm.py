"""The DRTM speed goal: one 20-minute comparison run (20 robots, 4 x 4 m, 12,000 ticks) in batch
in at most 10 s of wall time on one core.

    python benchmarks/bench_drtm.py [--scenario drtm artm] [--repeat 3] [--profile]

Prints, per run, wall and CPU seconds (the CPU time is the better figure on a shared machine:
other processes stretch the wall time but not this process's CPU time) and the median of each.
``--profile`` prints where the time goes (cProfile, which roughly doubles it).
"""

from __future__ import annotations

import argparse
import cProfile
import pstats
import resource
import statistics
import time

from swarm_sim.batch import run_batch
from swarm_sim.scenario import ScenarioError, load_scenario
from swarm_sim.world.core import tune_malloc

GOAL_S = 10.0


def main() -> None:
    tune_malloc()  # as the commands that run a world do (`tune_malloc`): time it as they run it
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenario", nargs="+", default=["drtm", "artm"])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--profile", action="store_true", help="profile one run of the first scenario instead")
    args = parser.parse_args()
    if args.profile:
        scenario = load_scenario(args.scenario[0], seed=args.seed)
        profiler = cProfile.Profile()
        profiler.enable()
        run_batch(scenario)
        profiler.disable()
        pstats.Stats(profiler).sort_stats("tottime").print_stats(20)
        return
    for name in args.scenario:
        scenario = load_scenario(name, seed=args.seed)
        walls, cpus = [], []
        for _ in range(args.repeat):
            wall0, cpu0 = time.perf_counter(), time.process_time()
            run = run_batch(scenario)
            walls.append(time.perf_counter() - wall0)
            cpus.append(time.process_time() - cpu0)
            print(f"batch {name} robots={scenario.robots.count} sim={scenario.sim.duration:.0f}s "
                  f"ticks={scenario.ticks} wall={walls[-1]:6.2f}s cpu={cpus[-1]:6.2f}s "
                  f"ms/tick={1e3 * cpus[-1] / scenario.ticks:5.3f} delivered={len(run.trace.drops)}", flush=True)
        wall, cpu = statistics.median(walls), statistics.median(cpus)
        print(f"median {name}: wall {wall:.2f} s, cpu {cpu:.2f} s over {args.repeat} runs "
              f"(goal <= {GOAL_S:.0f} s: {'met' if cpu <= GOAL_S else 'NOT met'} on CPU time)", flush=True)
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"peak RSS {peak:.0f} MB")


if __name__ == "__main__":
    try:
        main()
    except ScenarioError as exc:  # a bad --scenario or --set: one line, no traceback
        raise SystemExit(f"bench_drtm: {exc}") from None
