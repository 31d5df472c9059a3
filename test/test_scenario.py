"""Scenario loading: every shipped scenario loads; bad input is refused naming the key."""

from __future__ import annotations

import pytest

from swarm_sim.scenario import (
    SCENARIO_DIR,
    Scenario,
    ScenarioError,
    load_scenario,
    parse_override,
    scenario_from_dict,
    scenario_to_dict,
)
from swarm_sim.sites import drop_zones


@pytest.mark.parametrize("path", sorted(SCENARIO_DIR.glob("*.yaml")), ids=lambda p: p.stem)
def test_shipped_scenarios_load(path):
    scenario = load_scenario(path.stem)
    assert scenario.name == path.stem
    assert scenario_from_dict(scenario_to_dict(scenario)) == scenario


def test_overrides_and_fields():
    s = load_scenario("cpfa", ["robots.count=8", "resources.respawn=true"], sim__duration=12.5, seed=7)
    assert (s.robots.count, s.resources.respawn, s.sim.duration, s.seed) == (8, True, 12.5, 7)
    assert s.ticks == 125
    assert s.robot_names[:2] == ["robot_0", "robot_1"]
    assert [z.name for z in drop_zones(s)] == ["depot"]


@pytest.mark.parametrize(
    ("overrides", "message"),
    [
        (["robots.cont=3"], "unknown key robots.cont"),
        (["resources.count=many"], "resources.count: expected int"),
        (["robots.diameter=[1, 2]"], "robots.diameter: expected a number"),
        (["resources.distribution=spiral"], "resources.distribution: expected one of"),
        (["robots.count=5000"], "robots.count"),
        (["depot.center=[9.0, 0.0]"], "depot"),
        (["resources.count=10"], "resources.count: 10 != clusters"),
        (["sim.dt=0"], "sim.dt"),
        (["obstacles=[{shape: box, center: [20.0, 0.0]}]"], "obstacles[0].center"),
        (["drop_zones=[{name: depot, center: [1.0, 1.0], radius: 0.2}]"], "drop_zones"),
        (["sensors.scan.rays=0"], "sensors.scan.rays"),
        (["arena=3"], "arena: expected a mapping"),
        (["sim.duration=.nan"], "sim.duration: expected a finite number"),
    ],
)
def test_bad_input_names_the_key(overrides, message):
    with pytest.raises(ScenarioError, match=message.replace("[", r"\[").replace("]", r"\]")):
        load_scenario("cpfa", overrides)


def test_bad_files(tmp_path):
    broken = tmp_path / "broken.yaml"
    broken.write_text("robots: {count: [\n")
    with pytest.raises(ScenarioError, match="not valid YAML"):
        load_scenario(str(broken))
    with pytest.raises(ScenarioError, match="unknown scenario 'nope'"):
        load_scenario("nope")
    with pytest.raises(ScenarioError, match="does not exist"):
        load_scenario(str(tmp_path / "missing.yaml"))
    listy = tmp_path / "list.yaml"
    listy.write_text("- 1\n- 2\n")
    with pytest.raises(ScenarioError, match="top level must be a mapping"):
        load_scenario(str(listy))


def test_parse_override():
    assert parse_override("a.b=[1, 2]") == ("a.b", [1, 2])
    with pytest.raises(ScenarioError, match="KEY=VALUE"):
        parse_override("robots.count")


def test_defaults_are_valid():
    from swarm_sim.scenario import validate

    validate(Scenario())
