"""The graph across lossy links: real-time factor, late ticks and whether the run equals batch.

    sudo python benchmarks/bench_network.py [--robots 8] [--duration 12] [--seed 11] [--scenario NAME ...]

Root only (network namespaces). The testbed of ``test/network`` (`netns.Testbed` with its
user-space switch `linkemu`): the world on one host, the controllers on two others (even and odd
robots), both controller links shaped alike, in lockstep and in realtime at 1x (command timeout
0.5 s); the rows with a partition cut hostb off for 3 s once a third of the run is done. Prints
the table of benchmarks/README.md (one markdown row per setting) and each run's per-host counts. With
several ``--scenario`` names (e.g. ``cpfa mdbsa_d queue_qmt drtm caging``: the papers with a server or
peer messages, in the network stage's arenas, `multihost.PAPERS`), one table per scenario.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import threading
from pathlib import Path

sys.path[:0] = [str(Path(__file__).resolve().parents[1] / "test" / d) for d in ("network", ".")]

from multihost import PAPERS, SMALL_ARENA, MultiHostRun, batch_differences, flags, robots_of  # noqa: E402
from netns import Testbed, available  # noqa: E402

from launch_py.dds import reserve_free_domain  # noqa: E402

SETTINGS = [  # (label, loss, delay [s], jitter [s], partition)
    ("none", 0.0, 0.0, 0.0, False),
    ("5 % loss", 0.05, 0.0, 0.0, False),
    ("20 +- 10 ms", 0.0, 0.020, 0.010, False),
    ("5 % loss, 20 +- 10 ms", 0.05, 0.020, 0.010, False),
    ("5 % loss, 20 +- 10 ms, 3 s partition", 0.05, 0.020, 0.010, True),
]


def one(mode: str, setting: tuple, robots: int, duration: float, seed: int, resend: float,
        scenario: list[str]) -> str:
    label, loss, delay, jitter, partition = setting
    bed = Testbed(("world", "hosta", "hostb", "cli"), shaped=True)
    try:
        for host in robots_of(robots):
            bed.netem(host, loss, delay, jitter)
        extra = ["--tick-timeout", "20", "--resend-period", str(resend)] if mode == "lockstep" else ["--mode", "realtime", "--real-time-factor", "1"]
        with tempfile.TemporaryDirectory() as tmp:
            run = MultiHostRun(bed, Path(tmp), robots, *flags(duration, seed, *scenario), *extra)
            if partition:
                run.wait_sim(duration / 3, 300)
                cut = threading.Thread(target=bed.partition, args=("hostb", 3.0))
                cut.start()
                cut.join()
            graph = run.finish(900)
            diff = batch_differences(run.bag, graph, robots, duration, seed, *scenario) if mode == "lockstep" else None
    finally:
        bed.close()
    hosts = graph["by_host"]
    frames = {h: bed.stats.get(h, {}) for h in hosts}
    late = sum(c["late"] for c in hosts.values())
    stale = graph["stale_ticks"]
    equal = "-" if diff is None else ("yes" if not diff else f"no ({', '.join(diff[:3])})")
    print(f"# {mode} {label}: {hosts} frames {frames}", file=sys.stderr, flush=True)
    mode = f"{mode}, re-send {resend:g} s" if mode == "lockstep" else mode
    return (f"| {mode} | {label} | {graph['real_time_factor']} | {stale} | {late} | "
            f"{sum(c['resent'] for c in hosts.values())} | {sum(c['lost'] for c in hosts.values())} | "
            f"{sum(c['stopped'] for c in hosts.values())} | {equal} |")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robots", type=int, default=8)
    parser.add_argument("--duration", type=float, default=12.0)
    parser.add_argument("--seed", type=int, default=11)
    parser.add_argument("--scenario", nargs="+", default=["cpfa"],
                        help="one table each (default: cpfa in the small arena; the network stage's papers in "
                             f"its arenas: {', '.join(PAPERS)})")
    parser.add_argument("--set", dest="overrides", action="append", metavar="KEY=VALUE",
                        help="scenario overrides for every scenario (default: cpfa the small arena, the network "
                             "stage's papers its arenas)")
    parser.add_argument("--modes", nargs="+", default=["lockstep", "realtime"])
    parser.add_argument("--resend-period", type=float, nargs="+", default=[0.25, 0.1],
                        help="lockstep: the world's re-send periods to try [s]")
    parser.add_argument("--settings", type=int, nargs="+", default=list(range(len(SETTINGS))),
                        help="which rows of SETTINGS (default all)")
    args = parser.parse_args()
    if (why := available()) is not None:
        sys.exit(f"bench_network: {why}")
    if "ROS_DOMAIN_ID" not in os.environ:
        domain, _ = reserve_free_domain()  # held while this runs
        os.environ["ROS_DOMAIN_ID"] = str(domain)
    for name in args.scenario:
        default = SMALL_ARENA if name == "cpfa" else PAPERS.get(name, (name, []))[1]
        scenario = [name, args.overrides if args.overrides is not None else default]
        print(f"{name}: {args.robots} robots, {args.duration:g} s of sim time, seed {args.seed}")
        print("| mode | links (both controller hosts) | real-time factor | stale ticks | late commands | ticks re-sent "
              "| ticks without a command | stops by the timeout | equals batch |")
        print("|---|---|---|---|---|---|---|---|---|")
        for mode in args.modes:
            for resend in args.resend_period if mode == "lockstep" else [0.25]:
                for i in args.settings:
                    print(one(mode, SETTINGS[i], args.robots, args.duration, args.seed, resend, scenario), flush=True)


if __name__ == "__main__":
    main()
