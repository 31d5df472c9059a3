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
    # A measure of a probe the run did not ask for is absent from its row, and not shown (the
    # CPFA's drop-off time is the perimeter probe's: measured only where it delivers at docks).
    own = tuple(m for m in own if m.field in summary)
    assert [m.field for m in own if m.field not in shown] == []
    for m in own:
        value = summary[m.field]
        if value is None:
            text = m.missing
        elif isinstance(value, bool):
            text = "yes" if value else "no"
        else:
            scaled = value * m.scale if m.scale != 1.0 else value
            text = f"{scaled:.6g}" if isinstance(scaled, float) else str(scaled)
            text = f"{text} {m.unit}" if m.unit else text
        assert shown[m.field].split(None, 1)[1].startswith(text), (shown[m.field], text)
        assert shown[m.field].endswith(m.symbol)
    others = {m.field for a in registry.algorithms() for m in a.headline} - {m.field for m in (*own, *RUN)}
    assert others and not others & set(shown), sorted(others & set(shown))
    assert "sim_seconds" in shown and shown["sim_seconds"].endswith(" s")
    assert not any(isinstance(summary.get(k), (list, dict)) and summary.get(k) for k in shown
                   if k not in ("dead_nodes", "rejected_messages")), "series stay in --json"


def test_series_and_tables_stay_in_json():
    """A measure whose value is a series (a list of points) is not printed; a table of counts
    (rejected messages) reads as its total and where."""
    scenario = load_scenario(_first_scenario("ddsa"), ["sim.duration=2.0"])
    summary = summarize(run_batch(scenario).trace)
    summary["resources_per_robot"] = [[60.0, 1.0], [120.0, 2.0]]
    summary["rejected_messages"] = {"/robot_1/cmd_vel": {"late": 2, "malformed": 1}, "/lockstep/ack": {"unknown node": 4}}
    shown = {line.split()[0]: line for line in summary_lines(summary, scenario)}
    assert "resources_per_robot" not in shown
    assert shown["rejected_messages"].split(None, 1)[1] == "7 (/robot_1/cmd_vel, /lockstep/ack)"


def test_a_measure_reads_in_the_papers_units():
    """E_e is a fraction in the JSON and a percentage in the text; a stage the run did not reach
    says so."""
    from swarm_sim.analysis import text
    from swarm_sim.registry import Measure

    assert text._value(0.1199, Measure("energy_efficiency", "%", "E_e", scale=100.0)) == "11.99 %"
    assert text._value(None, Measure("search_time_s", "s", missing="not reached")) == "not reached"
    assert text._value(True, Measure("cage_held")) == "yes"


def test_the_batch_line_shows_the_algorithms_measures():
    """``swarm-batch`` prints one line per run: what ran, then its own measures (not the
    foraging fields for a caging run); null measures are left out."""
    from swarm_sim.analysis.text import summary_line

    scenario = load_scenario(_first_scenario("caging"), ["sim.duration=2.0"])
    line = summary_line(summarize(run_batch(scenario).trace), scenario)
    assert line.startswith("caging seed=0 robots=8: 2 s sim, ")
    assert "landmarks 255" in line and "object_delivered no" in line
    assert "resources" not in line and "not reached" not in line
