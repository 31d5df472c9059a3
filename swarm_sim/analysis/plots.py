"""Pictures of a run: its summary panels and the robots' trajectories over the planned paths."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from swarm_sim.analysis.metrics import RunTrace, delivered_over_time, summarize
from swarm_sim.analysis.replay import load_odometry
from swarm_sim.bag import bag_info
from swarm_sim.scenario import scenario_from_dict


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

