"""A run's summary as text: the run's own facts, then the measures its world task and its
algorithm declare (`swarm_sim.registry.Measure`), each with its unit; every other field of the
JSON result (one schema for all runs) stays out of the text."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from swarm_sim import registry
from swarm_sim.registry import Measure
from swarm_sim.scenario import Scenario

RUN = (Measure("scenario"), Measure("seed"), Measure("robots"), Measure("mode"), Measure("run_ended"),
       Measure("dead_nodes"), Measure("sim_seconds", "s"), Measure("wall_seconds", "s"), Measure("stale_ticks"),
       Measure("clamped_commands"), Measure("rejected_messages"))
"""What every run's text shows first."""
_QUIET_WHEN_EMPTY = ("dead_nodes", "rejected_messages")
OUTPUTS = ("plot", "trajectories", "figures", "video", "video_frames")
"""Files a command wrote, shown last."""


def measures(scenario: Scenario | None) -> tuple[Measure, ...]:
    """The run's facts, its task's measures and its algorithm's, in that order, each once."""
    own: tuple[Measure, ...] = ()
    if scenario is not None:
        algorithm = registry.of(scenario)
        own = (*registry.task(algorithm.task).headline, *algorithm.headline)
    return tuple({m.field: m for m in (*RUN, *own)}.values())


def _value(value: Any, unit: str) -> str:
    if value is None:
        return "n/a"
    if isinstance(value, float):
        value = f"{value:.6g}"
    return f"{value} {unit}" if unit else str(value)


def summary_lines(summary: Mapping[str, Any], scenario: Scenario | None) -> list[str]:
    """``  name   value unit`` for each measure the summary has, then the files written."""
    lines = []
    for m in measures(scenario):
        if m.field not in summary or (m.field in _QUIET_WHEN_EMPTY and not summary[m.field]):
            continue
        lines.append(f"  {m.field:28s} {_value(summary[m.field], m.unit)}")
    lines += [f"  {key:28s} {summary[key]}" for key in OUTPUTS if key in summary]
    return lines
