"""swarm-analyze: a run's metrics from its bag alone (no ROS running, no rclpy needed)."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from swarm_sim import registry
from swarm_sim.analysis.metrics import summarize
from swarm_sim.analysis.plots import plot_run, plot_trajectories
from swarm_sim.analysis.replay import load_run
from swarm_sim.recording import BagError


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="swarm-analyze", description=__doc__.splitlines()[0])
    parser.add_argument("bags", nargs="+", type=Path, help="bag directories written by swarm-run")
    parser.add_argument("--json", action="store_true", help="print one JSON object per run")
    parser.add_argument("--plot", type=Path, help="PNG path (default: <bag>/summary.png)")
    parser.add_argument("--no-plot", action="store_true")
    parser.add_argument("--trajectories", action="store_true",
                        help="also draw <bag>/trajectories.png (odometry over the planned paths) and the "
                             "algorithm's own figures (caging: <bag>/transport.png)")
    args = parser.parse_args(argv)
    status = 0
    for bag in args.bags:
        try:
            trace = load_run(bag)
        except (BagError, ValueError) as exc:
            print(f"swarm-analyze: {exc}", file=sys.stderr)
            status = 1
            continue
        summary = summarize(trace)
        if not args.no_plot:
            summary["plot"] = str(plot_run(trace, args.plot or bag / "summary.png"))
        if args.trajectories:
            summary["trajectories"] = str(plot_trajectories(bag, bag / "trajectories.png"))
            figures = registry.of(trace.config).figures
            if figures:  # the algorithm's own pictures (caging: the object's path, the cage)
                summary["figures"] = [str(p) for p in registry.resolve(figures)(trace, bag)]
        if args.json:
            print(json.dumps(summary))
        else:
            print(f"{bag}:")
            own = [m.name for m in registry.of(trace.config).metrics]
            for key in dict.fromkeys(("scenario", "seed", "robots", "mode", "sim_seconds", "wall_seconds",
                        "resources_delivered", "total_resources", "collision_time_per_robot_s",
                        "oae_per_robot", "trips_per_robot", "stale_ticks", "clamped_commands",
                        "resources_collected_pct", "dropoff_time_mean_s", "perimeter_delay_mean_s",
                        "deliveries_outside_docks",
                        "queue_length_mean", "queue_length_max", "resources_per_robot",
                        "foraging_rate_per_min", "regions", *own, "plot", "trajectories", "figures")):
                if key in summary:
                    print(f"  {key:28s} {summary[key]}")
    return status


if __name__ == "__main__":
    sys.exit(main())
