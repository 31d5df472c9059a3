"""swarm-analyze: a run's metrics from its bag alone (no ROS running, no rclpy needed).

``load_run(bag) -> RunTrace`` decodes the world's events and counters and the behaviours'
status messages with the `swarm_msgs_py` codecs; the metric functions of `swarm_sim.metrics`
then compute exactly what the batch runner computes.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

from swarm_msgs_py import diagnostics, odometry, server_state, topics
from swarm_msgs_py import clock as clock_codec
from swarm_sim.bag import BagError, bag_info, read_bag
from swarm_sim.metrics import PerimeterLog, RunTrace, delivered_over_time, summarize
from swarm_sim.scenario import scenario_from_dict
from swarm_sim.types import NS_PER_S, DropEvent, robot_index


def load_run(path: Path | str) -> RunTrace:
    """Build the trace of a recorded run; raises BagError naming what is missing."""
    path = Path(path)
    info = bag_info(path)
    meta = info.metadata
    if "scenario" not in meta:
        raise BagError(f"{path}: no swarmforage scenario in the bag's metadata (not a swarm-run bag?)")
    scenario = scenario_from_dict(json.loads(meta["scenario"]))
    trace = RunTrace(
        scenario=scenario.name, seed=scenario.seed, robots=tuple(scenario.robot_names),
        sim_seconds=float(meta.get("sim_seconds", 0.0)), wall_seconds=float(meta.get("wall_seconds", 0.0)),
        total_resources=scenario.resources.count, mode=meta.get("mode", "lockstep"), config=scenario,
    )
    index = {r: i for i, r in enumerate(trace.robots)}
    positions: dict[int, np.ndarray] = {}  # stamp -> (robots, 2) odometry positions
    last_clock = 0
    for m in read_bag(path):
        if m.topic.endswith("/" + topics.ODOM):
            robot = m.topic[1:].partition("/")[0]
            if robot in index:
                stamp, pose, _, _ = odometry.decode_odometry(m.data)
                if stamp not in positions:
                    positions[stamp] = np.full((len(index), 2), np.nan)
                positions[stamp][index[robot]] = (pose.x, pose.y)
        elif m.topic == topics.DEPOT_STATE:
            stamp, state = server_state.decode_state(m.data)
            trace.queue_lengths.append((stamp / NS_PER_S, server_state.queue_lengths(state)))
        elif m.topic == topics.CLOCK:
            last_clock = max(last_clock, clock_codec.decode_clock(m.data))
        elif m.topic == topics.WORLD_EVENTS:
            for event in diagnostics.decode_events(m.data)[1]:
                (trace.drops if isinstance(event, DropEvent) else trace.pickups).append(event)
        elif m.topic == topics.WORLD_ROBOT_STATS:
            trace.stats = diagnostics.decode_robot_stats(m.data)[1]
        elif m.topic.endswith("/" + topics.STATUS):
            status = diagnostics.decode_status(m.data)
            trace.status[status.robot] = status
    if not trace.sim_seconds:  # the run was cut off before it could write its totals
        trace.sim_seconds = last_clock / NS_PER_S
    trace.perimeter_entries, trace.perimeter_exits = _perimeter_log(trace, positions)
    return trace


def _perimeter_log(trace: RunTrace, positions: dict[int, np.ndarray]) -> tuple[dict, dict]:
    """Replay the recorded odometry through the `PerimeterLog` the batch runner feeds live (a
    robot missing from a tick keeps its previous position)."""
    depot = trace.config.depot
    log = PerimeterLog(trace.robots, depot.center, depot.perimeter_radius)
    previous = np.full((len(trace.robots), 2), np.inf)
    for stamp in sorted(positions):
        xy = positions[stamp]
        missing = np.isnan(xy[:, 0])
        xy[missing] = previous[missing]
        log.update(stamp / NS_PER_S, xy)
        previous = xy
    return log.entries, log.exits


def load_odometry(path: Path | str) -> dict[str, np.ndarray]:
    """Per robot, the (ticks, 4) array of odometry (t [s], x, y, yaw) the controllers received."""
    rows: dict[str, list[tuple[float, float, float, float]]] = {}
    for m in read_bag(Path(path)):
        if m.topic.endswith("/" + topics.ODOM):
            robot = m.topic.strip("/").split("/")[0]
            stamp, pose, _, _ = odometry.decode_odometry(m.data)
            rows.setdefault(robot, []).append((stamp / NS_PER_S, pose.x, pose.y, pose.yaw))
    return {r: np.array(v) for r, v in sorted(rows.items(), key=lambda kv: robot_index(kv[0]))}


def plot_run(trace: RunTrace, out: Path) -> Path:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    summary = summarize(trace)
    queues = bool(trace.queue_lengths)
    fig, axes = plt.subplots(1, 4 if queues else 3, figsize=(20 if queues else 15, 4))
    ax1, ax2, ax3 = axes[:3]
    times, counts = delivered_over_time(trace)
    ax1.step(times, counts, where="post")
    ax1.set(xlabel="sim time [s]", ylabel="resources delivered",
            title=f"{trace.scenario}, {len(trace.robots)} robots, seed {trace.seed}")
    names = list(trace.robots)
    idx = np.arange(len(names))
    ax2.bar(idx, [summary["collision_time_s_by_robot"][r] for r in names])
    ax2.set(xlabel="robot", ylabel="collision time [s]", title="collision time per robot")
    ax3.bar(idx, [summary["oae_by_robot"][r] for r in names], color="tab:orange")
    ax3.bar(idx, [summary["trips_by_robot"][r] for r in names], color="tab:green", alpha=0.7)
    ax3.set(xlabel="robot", ylabel="count", title="obstacle-avoidance events (orange), trips (green)")
    if queues:
        times = [t for t, _ in trace.queue_lengths] + [trace.sim_seconds]
        lengths = np.array([q for _, q in trace.queue_lengths] + [trace.queue_lengths[-1][1]])
        for j in range(lengths.shape[1]):
            axes[3].step(times, lengths[:, j], where="post", label=f"entry line {j}")
        axes[3].set(xlabel="sim time [s]", ylabel="robots queued", title="queue lengths")
        axes[3].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(out, dpi=100)
    plt.close(fig)
    return out


def planned_paths(scenario) -> list[np.ndarray]:
    """The spirals the search behaviours plan: one per robot (DDSA) or per region (MDBSA);
    empty for the other behaviours. Built by the behaviours' own code, not re-derived."""
    behaviour = scenario.controller.behaviour
    if behaviour == "ddsa":
        from swarm_controllers.ddsa import DdsaBehaviour

        rng = np.random.default_rng(0)
        return [DdsaBehaviour(scenario, r, rng).path.waypoints for r in scenario.robot_names]
    if behaviour in ("mdbsa_c", "mdbsa_d"):
        from swarm_controllers.center import region_paths

        return [p.waypoints for p in region_paths(scenario)]
    return []


def plot_trajectories(path: Path | str, out: Path, *, start: float = 0.0, end: float | None = None) -> Path:
    """The robots' recorded trajectories over the planned spirals (as the MDBSA paper's Figs. 1,
    4 and 5): grey = planned, colour = each robot's odometry between `start` and `end` [s]."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    scenario = scenario_from_dict(json.loads(bag_info(Path(path)).metadata["scenario"]))
    odometry_rows = load_odometry(path)
    fig, ax = plt.subplots(figsize=(8, 8))
    half = scenario.arena.size / 2
    ax.plot([-half, half, half, -half, -half], [-half, -half, half, half, -half], color="black", lw=1)
    for waypoints in planned_paths(scenario):
        ax.plot(waypoints[:, 0], waypoints[:, 1], color="0.75", lw=0.6)
    for zone in scenario.all_drop_zones():
        ax.add_patch(plt.Circle(zone.center, zone.radius, color="tab:green", alpha=0.3))
    cmap = plt.get_cmap("tab10")
    for i, (robot, rows) in enumerate(odometry_rows.items()):
        keep = (rows[:, 0] >= start) & (rows[:, 0] <= (end if end is not None else np.inf))
        ax.plot(rows[keep, 1], rows[keep, 2], lw=0.8, color=cmap(i % 10), label=robot)
    ax.set(aspect="equal", xlabel="x [m]", ylabel="y [m]",
           title=f"{scenario.name}: trajectories over the planned paths")
    if len(odometry_rows) <= 16:
        ax.legend(fontsize=6, loc="upper right")
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    plt.close(fig)
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="swarm-analyze", description=__doc__.splitlines()[0])
    parser.add_argument("bags", nargs="+", type=Path, help="bag directories written by swarm-run")
    parser.add_argument("--json", action="store_true", help="print one JSON object per run")
    parser.add_argument("--plot", type=Path, help="PNG path (default: <bag>/summary.png)")
    parser.add_argument("--no-plot", action="store_true")
    parser.add_argument("--trajectories", action="store_true",
                        help="also draw <bag>/trajectories.png: odometry over the planned spirals")
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
        if args.json:
            print(json.dumps(summary))
        else:
            print(f"{bag}:")
            for key in ("scenario", "seed", "robots", "mode", "sim_seconds", "wall_seconds",
                        "resources_delivered", "total_resources", "collision_time_per_robot_s",
                        "oae_per_robot", "trips_per_robot", "stale_ticks", "clamped_commands",
                        "resources_collected_pct", "dropoff_time_mean_s", "perimeter_delay_mean_s",
                        "deliveries_outside_docks",
                        "queue_length_mean", "queue_length_max", "resources_per_robot",
                        "foraging_rate_per_min", "regions", "plot", "trajectories"):
                if key in summary:
                    print(f"  {key:28s} {summary[key]}")
    return status


if __name__ == "__main__":
    sys.exit(main())
