"""What a researcher reads and sees after a run: for one algorithm of each registered paper, a
short graph run (``swarm-run``, no ``--json``) ends with the paper's own measures, each with its
unit, and ``swarm-analyze`` of the bag prints the very same lines; no other paper's measure and no
time series appear in the text. The bag's summary figure is the paper's (`test_figures`), its
trajectories are drawn over what the algorithm lays out, one colour per robot, titled with planned
paths only where there are some. The papers are found through the registry, not listed here."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import matplotlib
import matplotlib.pyplot as plt
import numpy as np
import pytest
import yaml
from test_figures import check_summary_figure

from swarm_sim import registry
from swarm_sim.analysis.metrics import summarize
from swarm_sim.analysis.plots import summary_figure, trajectories_figure
from swarm_sim.analysis.replay import load_run
from swarm_sim.analysis.text import RUN

REPO = Path(__file__).resolve().parents[1]


def _one_per_paper() -> list[tuple[str, str]]:
    """(algorithm, scenario): each paper's first algorithm that a shipped scenario runs."""
    scenarios = {}
    for stem, path in registry.scenario_files().items():
        behaviour = (yaml.safe_load(path.read_text()).get("controller") or {}).get("behaviour")
        scenarios.setdefault(behaviour, stem)
    out = {}
    for a in registry.algorithms():
        if a.name in scenarios:
            out.setdefault(registry.origin("algorithm", a.name), (a.name, scenarios[a.name]))
    return sorted(out.values())


def _block(text: str, start: str, end: str | None) -> list[str]:
    lines = text.splitlines()
    first = next(i for i, line in enumerate(lines) if line.startswith(start)) + 1
    last = next((i for i, line in enumerate(lines[first:], first) if end and line.startswith(end)), len(lines))
    return lines[first:last]


@pytest.mark.parametrize(("name", "scenario"), _one_per_paper())
def test_a_run_ends_with_its_papers_measures_and_analysis_reads_the_same(name, scenario, tmp_path):
    bag = tmp_path / "bag"
    run = subprocess.run(
        # 4 robots: the text and its reading do not depend on how many (the papers' 20-64 took minutes)
        [sys.executable, "-m", "launch_py.run", "--scenario", scenario, "--duration", "8", "--robots", "4", "--bag", str(bag),
         "--tick-timeout", "20", "--domain-id", os.environ["ROS_DOMAIN_ID"]],
        capture_output=True, text=True, timeout=300, cwd=REPO)
    assert run.returncode == 0, run.stdout[-2000:] + run.stderr[-2000:]
    at_end = _block(run.stdout, "[swarm-run] done:", "[swarm-run] bag:")
    analyze = subprocess.run([sys.executable, "-m", "swarm_sim.analysis.cli", str(bag), "--no-plot"],
                             capture_output=True, text=True, timeout=120, cwd=REPO)
    assert analyze.returncode == 0, analyze.stderr
    assert _block(analyze.stdout, f"{bag}:", None) == at_end  # one text for both commands

    shown = {line.split()[0]: line for line in at_end}
    record = registry.algorithm(name)
    own = (*registry.task(record.task).headline, *record.headline)
    trace = load_run(bag)
    summary = summarize(trace)
    for m in own:
        if m.field not in summary:  # a probe's measure this run did not ask for: not shown either
            assert m.field not in shown, m.field
            continue
        line = shown[m.field]
        value = line[len(m.field) + 2:].strip()
        if m.symbol:
            assert value.endswith(m.symbol), line
            value = value[: -len(m.symbol)].strip()
        if value not in (m.missing, "yes", "no"):
            assert re.fullmatch(rf"-?[\d.e+-]+{' ' + re.escape(m.unit) if m.unit else ''}", value), line
    others = {m.field for a in registry.algorithms() for m in a.headline} - {m.field for m in (*own, *RUN)}
    assert not others & set(shown), sorted(others & set(shown))
    assert "[[" not in run.stdout  # series only in --json

    check_summary_figure(summary_figure(trace), trace.config)
    fig = trajectories_figure(bag)
    ax = fig.axes[0]
    assert ("over the planned paths" in ax.get_title()) == bool(record.paths), ax.get_title()
    robots = [ln for ln in ax.lines if ln.get_label().startswith("robot_")]
    assert len(robots) == len(trace.robots)
    assert len({tuple(np.round(matplotlib.colors.to_rgba(ln.get_color()), 4)) for ln in robots}) == len(robots)
    world = [t.get_text() for t in ax.get_legend().get_texts() if not t.get_text().startswith("robot_")]
    if record.backdrop:  # its layout is drawn, and named in the legend
        assert len(set(world) - {"drop zone", "planned paths", "obstacle"}) >= 1, world
    plt.close("all")
