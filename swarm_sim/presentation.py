"""How a registered task or algorithm is shown to a researcher: the measures a run's text
prints (`Measure`) and the panels of its summary figure (`Panel`). Records of the registry
(`swarm_sim.registry.TaskSpec`, `swarm_sim.registry.Algorithm`, which re-exports both), read by
`swarm_sim.analysis.text` and `swarm_sim.analysis.plots`; plain data, no imports of either."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Measure:
    """A result field (`swarm_sim.analysis.metrics.summarize`) that a run's text summary shows
    (``swarm-analyze``), in the paper's words and unit."""

    field: str
    unit: str = ""
    """Printed after the value (``s``, ``%``, ``min``, ``tokens``); empty for plain ratios."""
    symbol: str = ""
    """The paper's name for it (``V_f``, ``E_e``), printed beside the field."""
    scale: float = 1.0
    """The text shows the value times this (a fraction as ``%``: 100); the JSON keeps the value."""
    missing: str = "n/a"
    """What the text says when the value is null (a stage the run did not reach: ``not reached``)."""


@dataclass(frozen=True)
class Panel:
    """One panel of a run's summary figure (``summary.png``, `swarm_sim.analysis.plots.plot_run`),
    as the paper would print it: what it shows, with units, named legend entries and reference lines."""

    title: str
    ylabel: str
    """The quantity and its unit (``robots queued [robots]``)."""
    source: str
    """What is drawn: a run-trace series (``RunTrace.series``, e.g. a server's ``queue_lengths``),
    a JSON result field (a ``[[t, value], ...]`` series, or a ``{robot: value}`` table drawn as
    bars per robot), or ``module:function`` ``(trace) -> either of those``."""
    legend: tuple[str, ...] = ()
    """Names of a series' components (``x``, ``y``); one with ``{i}`` is a pattern for every
    component (``entry line {i}``). Empty: one unnamed line."""
    integer: bool = False
    """Counts: integer ticks on the value axis."""
    references: str | None = None
    """``module:function`` ``(trace) -> [(value, label)]``: horizontal lines the paper draws (F_d)."""
    marks: str | None = None
    """``module:function`` ``(trace) -> [(t [s], label)]``: moments marked by vertical lines
    (the caging stages' ends)."""
    empty: str = "nothing recorded in this run"
    """What the panel says when the run gives it nothing to draw."""
