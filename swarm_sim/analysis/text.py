"""A run's summary as text: the run's own facts, then the measures its world task and its
algorithm declare (`swarm_sim.registry.Measure`), each with its unit and the paper's symbol;
every other field of the JSON result (one schema for all runs) stays out of the text, and so do
time series and per-robot tables, which only ``--json`` prints. ``swarm-run`` ends with these
lines and ``swarm-analyze`` prints them, so both read the same."""

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
NAME_WIDTH = 30
VALUE_WIDTH = 20


def measures(scenario: Scenario | None) -> tuple[Measure, ...]:
    """The run's facts, its task's measures and its algorithm's, in that order, each once."""
    own: tuple[Measure, ...] = ()
    if scenario is not None:
        algorithm = registry.of(scenario)
        own = (*registry.task(algorithm.task).headline, *algorithm.headline)
    return tuple({m.field: m for m in (*RUN, *own)}.values())


def _count(value: Any) -> int:
    """The total of a nested {key: count} table (``rejected_messages``)."""
    return sum(map(_count, value.values())) if isinstance(value, Mapping) else int(value)


def _value(value: Any, m: Measure) -> str:
    if value is None:
        return m.missing
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, Mapping):  # {where: {reason: count}}: the total, the first few places
        places = ", ".join(list(value)[:3]) + (" ..." if len(value) > 3 else "")
        return f"{_count(value)} ({places})"
    if isinstance(value, (list, tuple)) and all(isinstance(v, str) for v in value):
        return ", ".join(value)
    if isinstance(value, (int, float)) and m.scale != 1.0:
        value = value * m.scale
    if isinstance(value, float):
        value = f"{value:.6g}"
    return f"{value} {m.unit}" if m.unit else str(value)


def _is_series(value: Any) -> bool:
    """A time series or a table of numbers: JSON only."""
    return isinstance(value, (list, tuple)) and not all(isinstance(v, str) for v in value)


def summary_lines(summary: Mapping[str, Any], scenario: Scenario | None) -> list[str]:
    """``  field   value unit   symbol`` for each measure the summary has, then the files written."""
    lines = []
    for m in measures(scenario):
        value = summary.get(m.field)
        if m.field not in summary or _is_series(value) or (m.field in _QUIET_WHEN_EMPTY and not value):
            continue
        lines.append(f"  {m.field:{NAME_WIDTH}s} {_value(value, m):{VALUE_WIDTH}s} {m.symbol}".rstrip())
    for key in OUTPUTS:
        if key in summary:
            value = summary[key]
            lines.append(f"  {key:{NAME_WIDTH}s} {', '.join(value) if isinstance(value, list) else value}")
    return lines


def summary_line(summary: Mapping[str, Any], scenario: Scenario | None) -> str:
    """One line per run (``swarm-batch``): what ran, then its task's and algorithm's measures."""
    own = measures(scenario)[len(RUN):] if scenario is not None else ()
    shown = [f"{m.field} {_value(summary[m.field], m)}" for m in own
             if summary.get(m.field) is not None and not _is_series(summary[m.field])]
    head = (f"{summary.get('scenario')} seed={summary.get('seed')} robots={summary.get('robots')}: "
            f"{summary.get('sim_seconds', 0):.0f} s sim, {summary.get('wall_seconds', 0):.1f} s wall")
    return "; ".join([head, *shown])
