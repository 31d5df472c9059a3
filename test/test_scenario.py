"""Scenario loading: every shipped scenario loads; bad input is refused naming the key."""

from __future__ import annotations

import numpy as np
import pytest

from swarm_sim.scenario import (
    Scenario,
    ScenarioError,
    load_scenario,
    parse_override,
    scenario_from_dict,
    scenario_to_dict,
)
from swarm_sim import registry
from swarm_sim.sites import drop_zones


@pytest.mark.parametrize("path", list(registry.scenario_files().values()), ids=lambda p: p.stem)
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
        (["sim.dt=1e-9"], "sim.dt: must be between 0.001 and 10 s"),
        (["sim.physics_substeps=10000000"], "sim.physics_substeps: must be between 1 and 1000"),
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


@pytest.mark.parametrize("content, named", [
    (b"name: a\nname: b\n", "duplicate key 'name' \\(line 2\\)"),
    (b"\xff\xfe", "not UTF-8 text"),
    (b"", "the file is empty"),
    (b"a: " + b"[" * 5000 + b"]" * 5000, "nested too deeply"),
    (b"- 1\n", "top level must be a mapping"),
    (b"sim: {duration: [1, 2}", "not valid YAML"),
])
def test_broken_scenario_files_are_refused_in_one_line(tmp_path, content, named):
    path = tmp_path / "broken.yaml"
    path.write_bytes(content)
    with pytest.raises(ScenarioError, match=named) as info:
        load_scenario(str(path))
    assert "\n" not in str(info.value)


def test_floats_in_exponent_form_and_bounds():
    assert load_scenario("cpfa", ["sim.duration=1e3"]).sim.duration == 1000.0  # YAML 1.1 reads 1e3 as a string
    with pytest.raises(ScenarioError, match="sim.duration: at most"):
        load_scenario("cpfa", ["sim.duration=1e30"])
    with pytest.raises(ScenarioError, match="seed: must not be negative"):
        load_scenario("cpfa", seed=-1)


@pytest.mark.parametrize("module, args, named", [
    ("swarm_sim.batch", ["--runs", "0"], "--runs: 0 is outside"),
    ("swarm_sim.batch", ["--jobs", "0"], "--jobs: 0 is outside"),
    ("swarm_sim.batch", ["--seed", "-1"], "--seed: -1 is outside"),
    ("swarm_sim.batch", ["--duration", "inf"], "--duration: inf is outside"),
    ("launch_py.run", ["--real-time-factor", "0"], "--real-time-factor: 0 is outside"),
    ("launch_py.run", ["--tick-timeout", "nan"], "--tick-timeout: nan is outside"),
    ("launch_py.run", ["--domain-id", "500"], "--domain-id: 500 is outside"),
])
def test_bad_flags_are_refused_in_one_line_without_a_traceback(module, args, named):
    import subprocess
    import sys

    out = subprocess.run([sys.executable, "-m", module, *args], capture_output=True, text=True, timeout=60)
    assert out.returncode == 2 and named in out.stderr and "Traceback" not in out.stderr, out.stderr


def test_swarm_run_never_overwrites_a_recording(tmp_path):
    import subprocess
    import sys

    (tmp_path / "old").mkdir()
    (tmp_path / "old" / "metadata.yaml").write_text("x")
    out = subprocess.run([sys.executable, "-m", "launch_py.run", "--bag", str(tmp_path / "old")],
                         capture_output=True, text=True, timeout=60)
    assert out.returncode == 2 and "already exists" in out.stderr and out.stdout == ""
    assert (tmp_path / "old" / "metadata.yaml").read_text() == "x"


def test_groups_start_layout_is_the_authors_distribute_blocks():
    from swarm_sim.world.start import start_positions

    s = load_scenario("queue_qmt", ["robots.count=50"])
    xy = start_positions(s, np.random.default_rng(0))
    assert xy.shape == (50, 2)
    for g, (gx, gy) in enumerate(s.robots.start_groups):
        share = xy[(13 * g if g < 2 else 26 + 12 * (g - 2)):][: 13 if g < 2 else 12]
        assert np.allclose(share.mean(axis=0)[0], gx, atol=0.3)  # 6 columns around the point
        assert np.all(np.abs(share[:, 0] - gx) <= 0.75 + 1e-9)
    d = np.hypot(*(xy[:, None, :] - xy[None, :, :]).transpose(2, 0, 1))
    assert d[np.triu_indices(50, 1)].min() >= s.robots.start_spacing - 1e-9
    with pytest.raises(ScenarioError, match="robots.start_groups"):
        load_scenario("queue_qmt", ["robots.start_groups=[[5.8, 0.0]]"])


def test_the_shipped_scenarios_are_listed(capsys):
    import argparse

    from swarm_sim.cli import add_scenario_arguments

    parser = argparse.ArgumentParser()
    add_scenario_arguments(parser)
    with pytest.raises(SystemExit) as end:
        parser.parse_args(["--list-scenarios"])
    assert end.value.code == 0
    lines = capsys.readouterr().out.splitlines()
    assert [ln.split()[0] for ln in lines[1:]] == list(registry.scenario_files())
    queue_qmt = next(ln for ln in lines if ln.startswith("queue_qmt "))
    assert queue_qmt.split()[1:4] == ["queue", "64", "1080.0"] and "Q_MT" in queue_qmt
    assert max(map(len, lines)) <= 120
