"""Pictures of a caging run from its trace (a batch run's or a bag's): ``swarm-analyze
--trajectories`` writes ``transport.png``: the object's path over the planned landmark path,
and snapshots of the cage during the transport. Also the caging record's summary panels (the
object's position, path and deviation over sim time, the stages' ends marked) and the landmarks
drawn under the trajectories."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from swarm_controllers.caging.landmarks import landmarks
from swarm_controllers.caging.metrics import caging_report, distance_to_polyline, series_of, transport_stage
from swarm_controllers.caging.world_config import TransportConfig
from swarm_msgs_py.types import robot_index
from swarm_sim.compare.report import save_figure

SNAPSHOTS = 6


def transport_figure(trace, directory: Path) -> list[Path]:
    """``<directory>/transport.png``: left, the arena with the landmarks, where the robots went,
    the object at the start, the planned path and the object's path; right, the cage at
    `SNAPSHOTS` moments of the transport, to scale around the object, with one legend."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    scenario = trace.config
    stage = transport_stage(trace)
    report = caging_report(trace)
    obj_t, obj_positions = series_of(trace, "object")
    rob_t, rob_positions = series_of(trace, "robots")
    fig = plt.figure(figsize=(16, 7.5), layout="constrained")
    grid = fig.add_gridspec(2, 5, width_ratios=[2.2, 2.2, 1, 1, 1])
    ax = fig.add_subplot(grid[:, :2])
    half = scenario.arena.size / 2
    ax.plot([-half, half, half, -half, -half], [-half, -half, half, half, -half], color="black", lw=1)
    landmark_grid(ax, scenario)
    robots = np.array(rob_positions) if rob_positions else np.zeros((0, 0, 2))
    for i in range(robots.shape[1]):
        ax.plot(robots[:, i, 0], robots[:, i, 1], lw=0.4, color="0.6", label="robots' paths" if i == 0 else None)
    obj = np.array(obj_positions) if obj_positions else np.zeros((0, 2))
    if len(obj):
        ax.add_patch(plt.Circle(obj[0], TransportConfig.of(scenario).object.radius, fill=False, color="tab:red",
                                ls=":", label="object at the start"))
    if stage is not None:
        ax.plot(stage.planned[:, 0], stage.planned[:, 1], "--o", color="black", lw=1.2, ms=3,
                label="planned path (landmarks of T_r* reversed)")
        moving = (obj_t >= stage.start_s) & (obj_t <= stage.end_s)
        ax.plot(obj[moving, 0], obj[moving, 1], color="tab:red", lw=1.5, label="object's centre, transported")
    outcome = (f"path error {_fmt(report.trajectory_error_m, 2)} m ({_fmt(report.trajectory_error_pct)} %), "
               f"cage held: {_yes(report.cage_held)}" if report.trajectory_error_m is not None
               else "the object was not delivered in this run")
    ax.set(aspect="equal", xlabel="x [m]", ylabel="y [m]", xlim=(-half, half), ylim=(-half, half),
           title=f"{trace.scenario} seed {trace.seed}: {outcome}")
    ax.legend(fontsize=8, loc="upper right")
    if stage is not None:
        _snapshots(fig, grid, scenario, stage, obj_t, obj, rob_t, robots)
    else:
        note = fig.add_subplot(grid[:, 2:])
        note.axis("off")
        note.text(0.5, 0.5, "no transport in this run: the cage was never complete", ha="center", va="center")
    out = Path(directory) / "transport.png"
    save_figure(fig, out)
    plt.close(fig)
    return [out]


def _snapshots(fig, grid, scenario, stage, obj_t, obj, rob_t, robots) -> None:
    import matplotlib.pyplot as plt
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch
    from matplotlib.ticker import MaxNLocator

    r, w = TransportConfig.of(scenario).object.radius, scenario.robots.diameter
    members = [robot_index(x) for x in stage.cage]
    index = {round(t, 6): k for k, t in enumerate(rob_t)}
    span = r + 2 * w + 0.1
    for n, t in enumerate(np.linspace(stage.start_s, stage.end_s, SNAPSHOTS)):
        k = min(int(np.searchsorted(obj_t, t)), len(obj_t) - 1)
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
        done = min(100.0, 100.0 * (obj_t[k] - stage.start_s) / max(stage.end_s - stage.start_s, 1e-9))
        ax.set(aspect="equal", xlim=(center[0] - span, center[0] + span), ylim=(center[1] - span, center[1] + span),
               title=f"t = {obj_t[k]:.0f} s, {done:.0f} %")
        ax.title.set_fontsize(9)
        ax.xaxis.set_major_locator(MaxNLocator(3))
        ax.yaxis.set_major_locator(MaxNLocator(3))
        ax.tick_params(labelsize=8)
        ax.set_xlabel("x [m]", fontsize=8)
        if n % 3 == 0:
            ax.set_ylabel("y [m]", fontsize=8)
    handles = [Line2D([], [], color="black", ls="--", lw=0.8, label="planned path"),
               Patch(color="tab:red", alpha=0.5, label=f"object (r = {r:g} m)"),
               Line2D([], [], color="tab:blue", marker="o", lw=0.8, label="cage robots (numbered) and their polygon")]
    fig.legend(handles=handles, loc="lower center", bbox_to_anchor=(0.75, 0.0), ncol=3, fontsize=8, frameon=False,
               title="the cage during the transport (sim time, and % of the transport's time)", title_fontsize=9)


def _fmt(value: float | None, digits: int = 1) -> str:
    return "-" if value is None else f"{value:.{digits}f}"


def _yes(value: bool | None) -> str:
    return "not reached" if value is None else "yes" if value else "no"


# ---------------------------------------------------------------- summary panels, backdrop


def stage_ends(trace) -> list[tuple[float, str]]:
    """(t [s], what ended): the search (the first type 0), the recruitment (the cage complete),
    the transport (the object delivered), as far as the run got."""
    r = caging_report(trace)
    out = []
    if r.search_time_s is not None:
        out.append((r.search_time_s, "object found"))
        if r.recruitment_time_s is not None:
            out.append((r.search_time_s + r.recruitment_time_s, "cage complete"))
    if r.total_time_s is not None:
        out.append((r.total_time_s, "delivered"))
    return out


def object_path(trace) -> list[tuple[float, float]]:
    """(t [s], the length of the object centre's path so far [m])."""
    times, positions = series_of(trace, "object")
    if not len(times):
        return []
    xy = np.asarray(positions, dtype=float)
    return list(zip(times.tolist(), np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(xy, axis=0).T))]).tolist()))


def planned_length(trace) -> list[tuple[float, str]]:
    """The planned path's length [m] (the paper's path minimum length), once the cage is complete."""
    r = caging_report(trace)
    return [(r.planned_path_m, "planned path length")] if r.planned_path_m is not None else []


def path_deviation(trace) -> list[tuple[float, float]]:
    """(t [s], the object centre's distance from the planned path [m]) during the transport."""
    stage = transport_stage(trace)
    if stage is None:
        return []
    times, positions = series_of(trace, "object")
    window = (times >= stage.start_s - 1e-9) & (times <= stage.end_s + 1e-9)
    if not window.any():
        return []
    distance = distance_to_polyline(np.asarray(positions, dtype=float)[window], stage.planned)
    return list(zip(times[window].tolist(), distance.tolist()))


def landmark_grid(ax, scenario) -> None:
    """The landmarks (`Algorithm.backdrop`)."""
    marks = landmarks(scenario).points
    ax.plot(marks[:, 0], marks[:, 1], ".", color="0.7", ms=2, zorder=1, label=f"landmarks ({len(marks)})")


def bodies(scenario) -> dict[str, float]:
    """The object, drawn to scale in replay videos: ``object`` -> its diameter 2r [m]."""
    return {"object": 2.0 * TransportConfig.of(scenario).object.radius}
