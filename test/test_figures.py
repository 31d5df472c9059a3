"""The summary figure a paper would print, for every registered algorithm (a short batch run of its
first shipped scenario): only the panels its task and record declare, each with its unit, legend
entries named (never "0"/"1"), integer ticks for counts and robot numbers, a sensible shape, the
reference lines the paper draws (the DRTM's F_d). Trajectories: `test_run_text` draws them from
each paper's graph bag; here the colours and the helpers."""

from __future__ import annotations

import re

import matplotlib
import numpy as np
import pytest
import yaml

from swarm_sim import registry
from swarm_sim.analysis.plots import panels, robot_colours, summary_figure
from swarm_sim.batch import run_batch
from swarm_sim.scenario import load_scenario

matplotlib.use("Agg")


def _first_scenario(name: str) -> str:
    for stem, path in registry.scenario_files().items():
        if (yaml.safe_load(path.read_text()).get("controller") or {}).get("behaviour") == name:
            return stem
    raise AssertionError(f"no shipped scenario runs {name!r}")


def _integers(values) -> bool:
    return all(float(v).is_integer() for v in values)


def check_summary_figure(fig, scenario) -> None:
    """What every run's summary figure must look like (also used on graph bags)."""
    declared = panels(scenario)
    shown = [ax for ax in fig.axes if ax.get_visible()]
    assert declared and len(shown) == len(declared)
    width, height = fig.get_size_inches()
    assert 0.8 <= width / height <= 3.5, (width, height)  # no 3000 x 400 strips
    for ax, panel in zip(shown, declared):
        assert ax.get_title() == panel.title
        assert re.search(r"\[.+\]", ax.get_ylabel()), ax.get_ylabel()  # a unit
        assert ax.get_xlabel() in ("sim time [s]", "robot")
        legend = ax.get_legend()
        labels = [t.get_text() for t in legend.get_texts()] if legend else []
        assert not any(re.fullmatch(r"\d+", text) for text in labels), labels
        low, high = ax.get_ylim()
        if panel.integer:
            assert _integers(t for t in ax.get_yticks() if low <= t <= high), ax.get_yticks()
        if ax.get_xlabel() == "robot":
            lo, hi = ax.get_xlim()
            assert _integers(t for t in ax.get_xticks() if lo <= t <= hi), ax.get_xticks()
        dashed = [ln for ln in ax.lines if ln.get_linestyle() == "--"]  # reference lines
        assert all(ln.get_label() in labels for ln in dashed), f"{panel.title}: a reference line is not named"


@pytest.mark.parametrize("name", registry.known())
def test_the_summary_figure_shows_what_the_paper_would(name):
    scenario = load_scenario(_first_scenario(name), ["sim.duration=6.0"])
    fig = summary_figure(run_batch(scenario).trace)
    try:
        check_summary_figure(fig, scenario)
    finally:
        matplotlib.pyplot.close(fig)


def test_the_drtm_food_panel_draws_f_d():
    scenario = load_scenario(_first_scenario("drtm"), ["sim.duration=6.0"])
    fig = summary_figure(run_batch(scenario).trace)
    try:
        (food,) = [ax for ax in fig.axes if ax.get_title().startswith("food in the nest")]
        (line,) = [ln for ln in food.lines if ln.get_label().startswith("F_d")]
        assert set(line.get_ydata()) == {20.0}  # controller.nest.desired_food
    finally:
        matplotlib.pyplot.close(fig)


def test_queue_lengths_and_trips_are_separate_named_panels():
    scenario = load_scenario("queue_qmt", ["robots.count=8", "sim.duration=6.0"])
    titles = [p.title for p in panels(scenario)]
    assert "robots queued on each entry line" in titles and "trips per robot" in titles
    (queue,) = [p for p in panels(scenario) if p.source == "queue_lengths"]
    assert queue.legend == ("entry line {i}",) and queue.integer


def test_robot_colours_never_repeat_and_are_not_grey():
    for count in (1, 8, 9, 10, 16, 18, 19, 64, 112):
        colours = [tuple(np.round(matplotlib.colors.to_rgba(c), 4)) for c in robot_colours(count)]
        assert len(set(colours)) == count
        assert not any(r == g == b for r, g, b, _ in colours), count


@pytest.mark.parametrize("name", [a.name for a in registry.algorithms() if a.states])
def test_the_states_a_record_lists_are_the_ones_its_robots_report(name):
    """The replay legend lists `Algorithm.states` up front: they must be what statuses say."""
    trace = run_batch(load_scenario(_first_scenario(name), ["sim.duration=30.0"])).trace
    reported = {s.state for s in trace.status.values()}
    assert reported and reported <= set(registry.algorithm(name).states), reported
