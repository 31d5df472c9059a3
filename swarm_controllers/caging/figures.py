"""Pictures of a caging run from its trace (a batch run's or a bag's): ``swarm-analyze
--trajectories`` writes ``transport.png``: the object's path over the planned landmark path,
and snapshots of the cage during the transport."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from swarm_controllers.caging.metrics import caging_report, series_of, transport_stage
from swarm_sim.types import robot_index
from swarm_controllers.caging.landmarks import landmarks
from swarm_controllers.caging.world_config import TransportConfig

SNAPSHOTS = 6


def transport_figure(trace, directory: Path) -> list[Path]:
    """``<directory>/transport.png``: left, the arena with the landmarks, the planned path
    (dashed), the object's path (red) and where the robots went; right, the cage at
    `SNAPSHOTS` moments of the transport, drawn to scale around the object."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    scenario = trace.config
    stage = transport_stage(trace)
    report = caging_report(trace)
    obj_t, obj_positions = series_of(trace, "object")
    rob_t, rob_positions = series_of(trace, "robots")
    fig = plt.figure(figsize=(16, 7.5))
    grid = fig.add_gridspec(2, 5, width_ratios=[2.2, 2.2, 1, 1, 1])
    ax = fig.add_subplot(grid[:, :2])
    half = scenario.arena.size / 2
    ax.plot([-half, half, half, -half, -half], [-half, -half, half, half, -half], color="black", lw=1)
    marks = landmarks(scenario).points
    ax.plot(marks[:, 0], marks[:, 1], ".", color="0.8", ms=2, label=f"landmarks ({len(marks)})")
    robots = np.array(rob_positions) if rob_positions else np.zeros((0, 0, 2))
    for i in range(robots.shape[1]):
        ax.plot(robots[:, i, 0], robots[:, i, 1], lw=0.4, color="0.6")
    obj = np.array(obj_positions) if obj_positions else np.zeros((0, 2))
    if stage is not None:
        ax.plot(stage.planned[:, 0], stage.planned[:, 1], "--o", color="black", lw=1.2, ms=3, label="planned path")
        moving = (obj_t >= stage.start_s) & (obj_t <= stage.end_s)
        ax.plot(obj[moving, 0], obj[moving, 1], color="tab:red", lw=1.5, label="object's centre")
    if len(obj):
        ax.add_patch(plt.Circle(obj[0], TransportConfig.of(scenario).object.radius, fill=False, color="tab:red", ls=":"))
    ax.set(aspect="equal", xlabel="x [m]", ylabel="y [m]", xlim=(-half, half), ylim=(-half, half),
           title=f"{trace.scenario} seed {trace.seed}: error {_fmt(report.trajectory_error_pct)} %, "
                 f"cage held: {report.cage_held}")
    ax.legend(fontsize=7, loc="upper right")
    if stage is not None:
        _snapshots(fig, grid, scenario, stage, obj_t, obj, rob_t, robots)
    fig.tight_layout()
    out = Path(directory) / "transport.png"
    fig.savefig(out, dpi=100)
    plt.close(fig)
    return [out]


def _snapshots(fig, grid, scenario, stage, obj_t, obj, rob_t, robots) -> None:
    import matplotlib.pyplot as plt

    r, w = TransportConfig.of(scenario).object.radius, scenario.robots.diameter
    members = [robot_index(x) for x in stage.cage]
    index = {round(t, 6): k for k, t in enumerate(rob_t)}
    for n, t in enumerate(np.linspace(stage.start_s, stage.end_s, SNAPSHOTS)):
        k = int(np.searchsorted(obj_t, t))
        k = min(k, len(obj_t) - 1)
        ax = fig.add_subplot(grid[n // 3, 2 + n % 3])
        center = obj[k]
        ax.plot(stage.planned[:, 0], stage.planned[:, 1], "--", color="black", lw=0.8)
        ax.add_patch(plt.Circle(center, r, color="tab:red", alpha=0.5))
        j = index.get(round(obj_t[k], 6))
        if j is not None:
            polygon = robots[j, members]
            ax.plot(*np.vstack([polygon, polygon[:1]]).T, color="tab:blue", lw=0.8)
            for i, (x, y) in zip(members, polygon):
                ax.add_patch(plt.Circle((x, y), w / 2, color="tab:blue", alpha=0.7))
                ax.annotate(str(i), (x, y), ha="center", va="center", fontsize=6, color="white")
        span = r + 2 * w + 0.1
        ax.set(aspect="equal", xlim=(center[0] - span, center[0] + span), ylim=(center[1] - span, center[1] + span),
               title=f"t = {obj_t[k]:.0f} s")
        ax.tick_params(labelsize=6)


def _fmt(value: float | None) -> str:
    return "—" if value is None else f"{value:.1f}"
