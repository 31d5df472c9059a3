"""Pictures of a run: its summary panels (``summary.png``) and the robots' trajectories over what
the algorithm lays out in the world (``trajectories.png``).

The panels are the ones the run's world task and algorithm declare (`swarm_sim.registry.Panel`):
each quantity on its own axis with its unit, series components named in the legend, integer
ticks for counts and for robot numbers, the reference lines and moments the paper draws. A grid
of at most three panels a row keeps the figure a sensible shape however many there are.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from swarm_msgs_py import topics
from swarm_sim import registry
from swarm_sim.analysis.metrics import RunTrace, summarize
from swarm_sim.analysis.replay import load_odometry
from swarm_sim.analysis.video import resource_points
from swarm_sim.recording import bag_info, read_bag
from swarm_sim.registry import Panel
from swarm_sim.scenario import Scenario, scenario_from_dict
from swarm_sim.sites import drop_zones

COLUMNS = 3
"""Panels per row of the summary figure."""
PANEL_INCHES = (5.0, 4.2)


def panels(scenario: Scenario) -> tuple[Panel, ...]:
    """The summary panels of a run of `scenario`: its task's, then its algorithm's."""
    algorithm = registry.of(scenario)
    return (*registry.task(algorithm.task).panels, *algorithm.panels)


def _data(trace: RunTrace, summary: Mapping[str, Any], source: str) -> Any:
    if ":" in source:
        return registry.resolve(source)(trace)
    if source in trace.series:
        return trace.series[source]
    return summary.get(source)


def _label(panel: Panel, j: int) -> str | None:
    if not panel.legend:
        return None
    if len(panel.legend) == 1 and "{i}" in panel.legend[0]:
        return panel.legend[0].format(i=j)
    return panel.legend[j] if j < len(panel.legend) else f"{j}"


def _integer_axis(axis) -> None:
    from matplotlib.ticker import MaxNLocator

    axis.set_major_locator(MaxNLocator(integer=True))


def robot_number(robot: str) -> int:
    return int(robot.rpartition("_")[2])


def _draw(ax, panel: Panel, trace: RunTrace, data: Any) -> None:
    values = np.zeros(0)
    if isinstance(data, Mapping):  # {robot: value}: bars per robot
        robots = sorted(data, key=robot_number)
        values = np.array([data[r] for r in robots], dtype=float)
        ax.bar([robot_number(r) for r in robots], values, color="tab:blue")
        ax.set_xlabel("robot")
        _integer_axis(ax.xaxis)
    else:
        points = list(data or ())
        if points:  # each value holds until the next; the last until the run's end
            times = [float(t) for t, _ in points] + [trace.sim_seconds]
            values = np.array([v for _, v in points] + [points[-1][1]], dtype=float).reshape(len(times), -1)
            for j in range(values.shape[1]):
                ax.step(times, values[:, j], where="post", label=_label(panel, j))
        ax.set_xlabel("sim time [s]")
        ax.set_xlim(0, max(trace.sim_seconds, 1e-9))
        if panel.marks:
            for t, text in registry.resolve(panel.marks)(trace):
                ax.axvline(t, color="0.4", ls=":", lw=1)
                ax.annotate(text, (t, 1.0), xycoords=("data", "axes fraction"), rotation=90, va="top",
                            ha="right", fontsize=7, color="0.3")
    if panel.references:
        for value, text in registry.resolve(panel.references)(trace):
            ax.axhline(value, color="tab:red", ls="--", lw=1, label=text)
    if panel.integer:
        _integer_axis(ax.yaxis)
    if values.size and np.nanmin(values) >= 0:  # amounts: from zero, and a visible axis when all are zero
        ax.set_ylim(bottom=0, top=max(ax.get_ylim()[1], 1.0 if panel.integer or not np.nanmax(values) else 0.0))
    ax.set(ylabel=panel.ylabel, title=panel.title)
    if not data:
        ax.text(0.5, 0.5, panel.empty, transform=ax.transAxes, ha="center", va="center",
                color="0.5")
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize=7)


def plot_run(trace: RunTrace, out: Path) -> Path | None:
    """``summary.png``: `summary_figure`; None (nothing written) if the run's task and algorithm
    declare no panels."""
    if trace.config is None or not panels(trace.config):
        return None
    return _save(summary_figure(trace), out, 100)


def _save(fig, out: Path, dpi: int) -> Path:
    import matplotlib.pyplot as plt

    fig.savefig(out, dpi=dpi, bbox_inches="tight")  # the legend beside the arena included
    plt.close(fig)
    return Path(out)


def summary_figure(trace: RunTrace):
    """The run's panels (`panels`) in a grid, titled with what ran (a matplotlib Figure)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    chosen = panels(trace.config) if trace.config is not None else ()
    summary = summarize(trace)
    n = max(1, len(chosen))
    columns = n if n <= COLUMNS else 2 if n == 4 else COLUMNS
    rows = math.ceil(n / columns)
    fig, axes = plt.subplots(rows, columns, figsize=(PANEL_INCHES[0] * columns, PANEL_INCHES[1] * rows + 0.5),
                             squeeze=False)
    for ax, panel in zip(axes.flat, chosen):
        _draw(ax, panel, trace, _data(trace, summary, panel.source))
    for ax in list(axes.flat)[len(chosen):]:
        ax.set_visible(False)
    algorithm = registry.of(trace.config).name if trace.config is not None else "?"
    ran = trace.scenario if algorithm == trace.scenario else f"{trace.scenario} ({algorithm})"
    model = f" ({trace.config.robots.model})" if trace.config is not None else ""
    fig.suptitle(f"{ran}: {len(trace.robots)} robots{model}, seed {trace.seed}, {trace.sim_seconds:.0f} s of sim time")
    fig.tight_layout()
    return fig


def robot_colours(count: int) -> list:
    """`count` distinct colours, none grey (the planned paths' colour): tab10 up to 9 robots,
    tab20 up to 18, then evenly spaced along turbo (no colour repeats)."""
    import matplotlib

    for name, greys in (("tab10", (7,)), ("tab20", (14, 15))):
        palette = [c for i, c in enumerate(matplotlib.colormaps[name].colors) if i not in greys]
        if count <= len(palette):
            return palette[:count]
    return [matplotlib.colormaps["turbo"](x) for x in np.linspace(0.03, 0.97, count)]


def draw_world(ax, scenario: Scenario) -> None:
    """The arena's walls, the drop zones (where there are resources to deliver) and the obstacles [m]."""
    import matplotlib.pyplot as plt

    half = scenario.arena.size / 2
    ax.plot([-half, half, half, -half, -half], [-half, -half, half, half, -half], color="black", lw=1)
    for k, zone in enumerate(drop_zones(scenario) if scenario.resources.count else ()):
        ax.add_patch(plt.Circle(zone.center, zone.radius, color="tab:green", alpha=0.25, lw=0,
                                label="drop zone" if k == 0 else None))
    for k, ob in enumerate(scenario.obstacles):
        w, h = ob.size
        ax.add_patch(plt.Rectangle((ob.center[0] - w / 2, ob.center[1] - h / 2), w, h, color="tab:brown",
                                   alpha=0.7, label="obstacle" if k == 0 else None))


def plot_trajectories(path: Path | str, out: Path, *, start: float = 0.0, end: float | None = None) -> Path:
    """``trajectories.png``: `trajectories_figure`."""
    return _save(trajectories_figure(path, start=start, end=end), out, 110)


def trajectories_figure(path: Path | str, *, start: float = 0.0, end: float | None = None):
    """The robots' recorded trajectories in the bag at `path` between `start` and `end` [s], one
    colour each, over what the algorithm lays out (its planned paths in grey, its `backdrop`: a
    depot's queues and docks, regions, landmarks), as the MDBSA paper's Figs. 1, 4 and 5 and the
    queue paper's Figs. 3-7 draw them (a matplotlib Figure)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    scenario = scenario_from_dict(json.loads(bag_info(Path(path)).metadata["scenario"]))
    odometry_rows = load_odometry(path)
    algorithm = registry.of(scenario)
    fig, ax = plt.subplots(figsize=(9, 8))
    draw_world(ax, scenario)
    paths = registry.resolve(algorithm.paths)(scenario) if algorithm.paths else []
    for k, waypoints in enumerate(paths):
        ax.plot(waypoints[:, 0], waypoints[:, 1], color="0.75", lw=0.6, zorder=1,
                label="planned paths" if k == 0 else None)
    if algorithm.backdrop:
        registry.resolve(algorithm.backdrop)(ax, scenario)
    resources = _resources_at_start(path)
    if len(resources):
        ax.scatter(resources[:, 0], resources[:, 1], s=2, color="goldenrod", zorder=2, lw=0,
                   label="resources at the start")
    robots = sorted(odometry_rows, key=robot_number)
    for colour, robot in zip(robot_colours(len(robots)), robots):
        rows = odometry_rows[robot]
        keep = (rows[:, 0] >= start) & (rows[:, 0] <= (end if end is not None else np.inf))
        ax.plot(rows[keep, 1], rows[keep, 2], lw=0.8, color=colour, label=robot, zorder=3)
    half = scenario.arena.size / 2
    ax.set(aspect="equal", xlabel="x [m]", ylabel="y [m]", xlim=(-half * 1.02, half * 1.02),
           ylim=(-half * 1.02, half * 1.02),
           title=f"{scenario.name}: {len(robots)} robots' trajectories ({scenario.robots.model})"
                 + (" over the planned paths" if paths else "")
                 + f", {start:g}-{end if end is not None else _end(odometry_rows):g} s")
    _legend_outside(ax, len(robots))
    if len(robots) > LEGEND_ROBOTS:  # too many to name: a colour scale of robot numbers instead
        from matplotlib.colors import BoundaryNorm, ListedColormap

        numbers = [robot_number(r) for r in robots]
        scale = plt.cm.ScalarMappable(norm=BoundaryNorm(np.arange(len(robots) + 1) - 0.5, len(robots)),
                                      cmap=ListedColormap(robot_colours(len(robots))))
        bar = fig.colorbar(scale, ax=ax, location="bottom", shrink=0.5, pad=0.08, aspect=40, label="robot")
        every = range(0, len(robots), max(1, len(robots) // 8))
        bar.set_ticks(list(every), labels=[str(numbers[i]) for i in every])
        bar.minorticks_off()
    fig.tight_layout()
    return fig


def _resources_at_start(path: Path | str) -> np.ndarray:
    """(n, 2) the resources of the first ``/world/markers`` in the bag [m] (none: empty)."""
    for m in read_bag(path):
        if m.topic == topics.WORLD_MARKERS:
            return resource_points(m.data)
    return np.zeros((0, 2))


def _end(rows: Mapping[str, np.ndarray]) -> float:
    return max((float(r[-1, 0]) for r in rows.values() if len(r)), default=0.0)


LEGEND_ROBOTS = 24
"""Robots named in a trajectories legend; more get a colour scale."""


def _legend_outside(ax, robots: int) -> None:
    """The legend beside the arena: the world's parts, then the robots (named up to `LEGEND_ROBOTS`)."""
    handles, labels = ax.get_legend_handles_labels()
    keep = [(h, lab) for h, lab in zip(handles, labels) if robots <= LEGEND_ROBOTS or not lab.startswith("robot_")]
    if keep:
        ax.legend(*zip(*keep), fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0,
                  ncol=2 if len(keep) > 30 else 1)

