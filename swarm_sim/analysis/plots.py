"""Pictures of a run: its summary panels and the robots' trajectories over the planned paths."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from swarm_sim import registry
from swarm_sim.analysis.metrics import RunTrace, delivered_over_time, summarize
from swarm_sim.analysis.replay import load_odometry
from swarm_sim.recording import bag_info
from swarm_sim.scenario import scenario_from_dict
from swarm_sim.sites import drop_zones


def plot_run(trace: RunTrace, out: Path) -> Path:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    summary = summarize(trace)
    series = sorted((name, points) for name, points in trace.series.items()
                    if points and np.ndim(points[0][1]) <= 1)  # not the per-robot poses of a task's state
    fig, axes = plt.subplots(1, 3 + len(series), figsize=(15 + 5 * len(series), 4))
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
    for ax, (name, points) in zip(axes[3:], series):  # the servers' series, e.g. queue lengths
        times = [t for t, _ in points] + [trace.sim_seconds]
        values = np.array([v for _, v in points] + [points[-1][1]], dtype=float).reshape(len(times), -1)
        for j in range(values.shape[1]):
            ax.step(times, values[:, j], where="post", label=f"{j}")
        ax.set(xlabel="sim time [s]", ylabel=name.replace("_", " "), title=name.replace("_", " "))
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(out, dpi=100)
    plt.close(fig)
    return out


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
    paths = registry.of(scenario).paths
    for waypoints in (registry.resolve(paths)(scenario) if paths else []):
        ax.plot(waypoints[:, 0], waypoints[:, 1], color="0.75", lw=0.6)
    for zone in drop_zones(scenario):
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

