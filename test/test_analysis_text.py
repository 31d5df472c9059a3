"""A run's text summary shows the run's facts and the measures its own task and algorithm declare,
with units, and no other algorithm's fields (the JSON keeps one schema for all)."""

from __future__ import annotations

import pytest
import yaml

from swarm_sim import registry
from swarm_sim.analysis.metrics import summarize
from swarm_sim.analysis.text import RUN, summary_lines
from swarm_sim.batch import run_batch
from swarm_sim.scenario import load_scenario


def _first_scenario(name: str) -> str:
    for stem, path in registry.scenario_files().items():
        if (yaml.safe_load(path.read_text()).get("controller") or {}).get("behaviour") == name:
            return stem
    raise AssertionError(f"no shipped scenario runs {name!r}")


@pytest.mark.parametrize("name", registry.known())
def test_text_shows_its_own_measures_only(name):
    scenario = load_scenario(_first_scenario(name), ["sim.duration=2.0"])
    summary = summarize(run_batch(scenario).trace)
    shown = {line.split()[0]: line for line in summary_lines(summary, scenario)}
    record = registry.algorithm(name)
    own = (*registry.task(record.task).headline, *record.headline)
    assert [m.field for m in own if m.field not in shown] == []
    for m in own:
        value = summary[m.field]
        text = "n/a" if value is None else f"{value:.6g}" if isinstance(value, float) else str(value)
        assert shown[m.field].split(None, 1)[1] == (f"{text} {m.unit}" if m.unit and value is not None else text)
    others = {m.field for a in registry.algorithms() for m in a.headline} - {m.field for m in (*own, *RUN)}
    assert others and not others & set(shown), sorted(others & set(shown))
    assert "sim_seconds" in shown and shown["sim_seconds"].endswith(" s")
    assert not any(isinstance(summary.get(k), (list, dict)) and summary.get(k) for k in shown
                   if k not in ("dead_nodes", "rejected_messages")), "series stay in --json"
