"""Scenario loading: every shipped scenario loads; bad input is refused naming the key."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from depot_manager.config import DockingConfig
from swarm_sim import registry
from swarm_sim.scenario import (
    ControllerConfig,
    Scenario,
    ScenarioError,
    load_scenario,
    parse_override,
    scenario_from_dict,
    scenario_to_dict,
)
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

    validate(dataclasses.replace(Scenario(), controller=ControllerConfig(behaviour=registry.default_scenario())))
    with pytest.raises(ScenarioError, match="controller.behaviour: unknown behaviour '' \\(known: "):
        validate(Scenario())  # a scenario names its algorithm


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
        load_scenario("cpfa", ["sim.duration=1e8"])
    with pytest.raises(ScenarioError, match="sim.duration: expected a finite number within"):
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
    ("launch_py.run", ["--domain-id", "any"], "--domain-id: expected an integer"),
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


# --------------------------------------------------------------------------- declared world sections


def test_world_sections_are_declared_by_their_task_algorithm_or_delivery_kind():
    """``transport`` belongs to the caging paper's task, ``regions`` to the MDBSA records,
    ``docking`` to the queue paper's docks delivery; the loader builds them from their top-level
    keys and ``of`` reads them back (defaults if absent)."""
    from swarm_controllers.caging.world_config import TransportConfig
    from swarm_controllers.spiral.regions import RegionConfig

    assert registry.world_sections() == {
        "docking": "depot_manager.config:DockingConfig",
        "regions": "swarm_controllers.spiral.regions:RegionConfig",
        "transport": "swarm_controllers.caging.world_config:TransportConfig",
    }
    assert dict(registry.delivery_kind("docks").world) == {"docking": registry.world_sections()["docking"]}
    assert dict(registry.task("transport").world) == {"transport": registry.world_sections()["transport"]}
    assert {name for name in ("mdbsa_c", "mdbsa_d", "ddsa") if registry.algorithm(name).world} == {"mdbsa_c", "mdbsa_d"}
    caging = load_scenario("caging", ["transport.object.radius=0.35"])
    assert TransportConfig.of(caging).object.radius == 0.35
    assert scenario_to_dict(caging)["transport"]["object"]["radius"] == 0.35  # at the top level, as in the file
    assert scenario_from_dict(scenario_to_dict(caging)) == caging
    cpfa = load_scenario("cpfa")
    assert cpfa.sections == () and "transport" not in scenario_to_dict(cpfa)
    assert TransportConfig.of(cpfa) == TransportConfig() and RegionConfig.of(cpfa) == RegionConfig()
    assert RegionConfig.of(load_scenario("mdbsa_d")).center_radius == 0.15  # what mdbsa_d.yaml says
    # any registered section is accepted in any scenario (an older bag's metadata carries them all)
    assert RegionConfig.of(load_scenario("ddsa", ["regions.count=64"])).count == 64
    again = cpfa.with_section("regions", RegionConfig(count=4))
    assert RegionConfig.of(again).count == 4 and again.sections == (("regions", RegionConfig(count=4)),)


@pytest.mark.parametrize(("name", "override", "message"), [
    ("caging", "transport.object.radius=-1", "transport.object.radius: must be positive"),
    ("caging", "transport.object.floor_friction=-0.1", "transport.object.floor_friction: must not be negative"),
    ("caging", "transport.landmarks.step=0", "transport.landmarks.step: must be positive"),
    ("caging", "transport.swarm_distance=-0.1", "transport.swarm_distance: must not be negative"),
    ("caging", "transport.swarm_distance=5.4", "transport.swarm_distance: 5.4 m from an object at the centre of "
                                               "the 8 x 7 m landmark rectangle leaves no start in it (its corners "
                                               "are 5.32 m away)"),
    ("caging", "transport.object.radius=big", "transport.object.radius: expected a number, got 'big'"),
    ("caging", "transport.colour=red", "unknown key transport.colour (known keys: landmarks, object, swarm_distance)"),
    ("caging", "transport=3", "transport: expected a mapping"),
    ("mdbsa_d", "regions.count=5", "regions.count: 5 is not a power of 4"),
    ("cpfa", "regions.count=5", "regions.count: 5 is not a power of 4"),
    ("mdbsa_c", "regions.center_radius=0", "regions.center_radius: must be positive"),
    ("cpfa", "region.count=4", "unknown key region (known keys: arena, controller, depot, docking, drop_zones, "
                               "name, obstacles, regions, resources, robots, seed, sensors, sim, transport)"),
    ("cpfa", "sections=[]", "unknown key sections"),
])
def test_a_bad_value_in_a_declared_world_section_is_refused_naming_the_key(name, override, message):
    with pytest.raises(ScenarioError) as info:
        load_scenario(name, [override])
    assert str(info.value).startswith(message) and "\n" not in str(info.value), str(info.value)


def test_a_scenario_file_with_a_bad_world_section_gets_one_line(tmp_path):
    text = registry.scenario_files()["caging"].read_text()
    assert "  landmarks: {step: 0.5," in text
    path = tmp_path / "bad_caging.yaml"
    path.write_text(text.replace("  landmarks: {step: 0.5,", "  landmarks: {step: -0.5,", 1))
    with pytest.raises(ScenarioError, match=r"^transport.landmarks.step: must be positive$"):
        load_scenario(str(path))


# --------------------------------------------------------------------------- delivery kinds


def test_delivery_kinds_are_registered_by_whoever_provides_them():
    assert set(registry.delivery_kinds()) >= {"depot", "docks", "region_centers"}
    assert registry.delivery_kind("depot").zones.startswith("swarm_sim.")
    assert registry.delivery_kind("docks").zones.startswith("depot_manager.")
    assert registry.delivery_kind("region_centers").zones.startswith("swarm_controllers.spiral.")
    assert registry.delivery_kind("region_centers").resources_inside
    assert not registry.delivery_kind("docks").resources_inside
    with pytest.raises(ValueError, match="delivery kind 'docks' is already registered"):
        registry.register_delivery(registry.delivery_kind("docks"))
    assert [z.name for z in drop_zones(load_scenario("queue_cpfa"))] == ["depot"]  # the authors' CPFA: one nest
    assert registry.delivery_kind("perimeter_depot").probes == registry.delivery_kind("docks").probes == ("perimeter",)
    s = load_scenario("queue_cpfa", ["depot.delivery=docks"])  # the text's reading
    zones = drop_zones(s)
    assert [z.name for z in zones] == [f"dock_{k}" for k in range(4)]
    docking = DockingConfig.of(s)
    assert all((z.radius, z.dwell) == (docking.dock_radius, docking.unload_time) for z in zones)
    assert [z.name for z in registry.delivery_zones(load_scenario("cpfa"), "docks")] == [f"dock_{k}" for k in range(4)]


@pytest.mark.parametrize(("override", "message"), [
    ("depot.delivery=nowhere", "depot.delivery: unknown delivery kind 'nowhere' (known: depot, docks, "),
    ("depot.delivery=3", "depot.delivery: expected a string, got 3"),
    ("depot.delivery=docks", None),  # the CPFA baseline also delivers at the docks (queue_cpfa)
    ("depot.delivery=region_centers", "depot.delivery: cpfa delivers to depot or docks or perimeter_depot, not 'region_centers'"),
])
def test_an_unknown_or_unsuitable_delivery_kind_is_refused_naming_the_key(override, message):
    if message is None:
        assert load_scenario("cpfa", [override]).depot.delivery == "docks"
        return
    with pytest.raises(ScenarioError) as info:
        load_scenario("cpfa", [override])
    assert str(info.value).startswith(message), str(info.value)


def test_a_delivery_kinds_own_checks_run():
    """The docks kind needs its perimeter inside the arena; the depot kind does not."""
    with pytest.raises(ScenarioError, match="docking.perimeter_radius: a perimeter of 6.5 m does not fit"):
        load_scenario("queue_qse", ["docking.perimeter_radius=6.5"])
    assert DockingConfig.of(load_scenario("cpfa", ["docking.perimeter_radius=6.5"])).perimeter_radius == 6.5


@pytest.mark.parametrize(("override", "message"), [
    ("docking.docks=0", "docking.docks: need at least one dock"),
    ("docking.dock_radius=0", "docking.dock_radius: must be positive"),
    ("docking.unload_time=-1", "docking.unload_time: must not be negative"),
    ("docking.dock_distance=0", "docking.dock_distance: must be positive"),
    ("docking.docks=40", "docking.docks: 40 docks do not fit side by side"),
    ("docking.perimeter_radius=0.4", "docking.perimeter_radius: must exceed depot.radius"),
    ("depot.docks=4", "depot.docks: moved to docking.docks"),
])
def test_the_docking_section_is_checked_naming_the_key(override, message):
    with pytest.raises(ScenarioError) as info:
        load_scenario("queue_cpfa", ["depot.delivery=docks", "depot.radius=0.5", override])
    assert str(info.value).startswith(message), str(info.value)


def test_a_recorded_scenario_with_the_docks_under_depot_still_loads():
    """Bags recorded before the ``docking`` section kept its fields under ``depot``: the loader
    of a recorded scenario carries them over (`DockingConfig.MOVED`), and they keep their values."""
    s = load_scenario("queue_cpfa", ["docking.unload_time=7.0"])
    old = scenario_to_dict(s)
    old["depot"].update(old.pop("docking"))
    assert "docking" not in old and old["depot"]["unload_time"] == 7.0
    assert scenario_from_dict(old) == s
    assert DockingConfig.of(scenario_from_dict(old)).unload_time == 7.0
