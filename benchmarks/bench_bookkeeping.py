"""What a batch run's bookkeeping costs: the run with and without the state-dependent collision
rule (`swarm_sim.analysis.state_rules.RuleLog`) and with the servers' state series held still.

    python benchmarks/bench_bookkeeping.py [--scenario queue_qmt] [--robots 112] [--duration 120] [--repeat 7]

Each variant runs the same scenario and seed in this process, alternated ``--repeat`` times after
a warm-up; CPU time per tick (``time.process_time``), medians. Neither variant changes what the
robots do: the rule only counts, and the series only reads the server's state (the
"held still" variant hands the series the first state it got, so the depot's snapshot is not
rebuilt). The difference to the full run is that piece's cost.
"""

from __future__ import annotations

import argparse
import dataclasses
import statistics
import time

import swarm_sim.batch as batch
from swarm_sim import registry
from swarm_sim.scenario import ScenarioError, load_scenario
from swarm_sim.world.core import tune_malloc


def _without_rule(of):
    return lambda scenario: dataclasses.replace(of(scenario), collision_rule=None)


def _held_state(servers):
    """`make_servers` whose servers answer `state()` with their first state."""
    def make(scenario):
        made = servers(scenario)
        for server in made.values():
            first = server.state()
            server.state = lambda first=first: first
        return made
    return make


def main() -> None:
    tune_malloc()  # as the commands that run a world do (`tune_malloc`): time it as they run it
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenario", default="queue_qmt")
    parser.add_argument("--robots", type=int, default=112)
    parser.add_argument("--duration", type=float, default=120.0)
    parser.add_argument("--repeat", type=int, default=7)
    args = parser.parse_args()
    scenario = load_scenario(args.scenario, robots__count=args.robots, sim__duration=args.duration)
    of, servers = batch.of, batch.make_servers
    variants = {
        "full run": {},
        "without the collision rule": {"of": _without_rule(of)},
        "state series held still": {"make_servers": _held_state(servers)},
    }
    if registry.of(scenario).collision_rule is None:
        del variants["without the collision rule"]
    times: dict[str, list[float]] = {name: [] for name in variants}
    batch.run_batch(scenario)  # warm-up: numba, caches
    for _ in range(args.repeat):
        for name, patch in variants.items():
            batch.of, batch.make_servers = patch.get("of", of), patch.get("make_servers", servers)
            c0 = time.process_time()
            batch.run_batch(scenario)
            times[name].append(1e3 * (time.process_time() - c0) / scenario.ticks)
    batch.of, batch.make_servers = of, servers
    full = statistics.median(times["full run"])
    print(f"{args.scenario}, {args.robots} robots, {args.duration:.0f} s, {args.repeat} alternated runs each")
    for name, values in times.items():
        median = statistics.median(values)
        piece = "" if name == "full run" else f"  piece: {full - median:+.3f} ms/tick ({100 * (full - median) / full:+.1f} %)"
        print(f"  {name:28s} {median:6.3f} ms/tick (min {min(values):.3f}){piece}")


if __name__ == "__main__":
    try:
        main()
    except ScenarioError as exc:  # a bad --scenario or --set: one line, no traceback
        raise SystemExit(f"bench_bookkeeping: {exc}") from None
