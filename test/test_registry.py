"""The algorithm registry: one record per algorithm, read everywhere; a plug-in algorithm (the
dummy in test/plugins/dummy_algorithm, an installed package of its own: behaviour, world task and
its sense, server, message family, metric and scenario) is found through its entry point and
runs like a shipped paper (its graph == batch check is in test_conformance)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from depot_manager.codec import DEPOT_GRANTS, DEPOT_REPORTS, RADIO_TOPIC
from swarm_controllers.cpfa.codec import PHEROMONES_TOPIC
from swarm_msgs_py import topics
from swarm_sim import registry
from swarm_sim.outputs import Series, SeriesLog, ServerOutputs
from swarm_sim.scenario import ScenarioError, load_scenario

REPO = Path(__file__).resolve().parents[1]


def test_shipped_records_and_their_wiring():
    assert {"cpfa", "ddsa", "mdbsa_c", "mdbsa_d", "queue", "caging"} <= set(registry.known())
    queue = registry.algorithm("queue")
    inbound, outbound = registry.robot_topics(queue)
    assert set(inbound) == {DEPOT_GRANTS, topics.heard(RADIO_TOPIC), topics.heard(PHEROMONES_TOPIC)}
    assert set(outbound) == {DEPOT_REPORTS, RADIO_TOPIC, PHEROMONES_TOPIC}
    server_in, server_out = registry.server_topics(queue.servers[0])
    assert set(server_in) == {DEPOT_REPORTS} and set(server_out) == {DEPOT_GRANTS}
    assert registry.robot_topics(registry.algorithm("ddsa")) == ({}, {})
    assert set(registry.peer_topics(queue)) == {RADIO_TOPIC, PHEROMONES_TOPIC}  # the world relays these
    caging_in, caging_out = registry.robot_topics(registry.algorithm("caging"))
    caging = {f"/caging/type{k}_{name}" for k, name in enumerate(
        ("recruitment", "summon", "positioned", "oriented", "reached"))}
    assert set(caging_out) == caging and set(caging_in) == {topics.heard(t) for t in caging}


def test_records_are_refused_twice_and_unknown_names_are_named():
    with pytest.raises(ValueError, match="already registered"):
        registry.register(registry.algorithm("cpfa"))
    with pytest.raises(ScenarioError, match="controller.behaviour: unknown behaviour 'nope' \\(known: .*cpfa"):
        load_scenario("cpfa", ["controller.behaviour=nope"])
    with pytest.raises(ScenarioError, match="unknown key controller.colour"):
        load_scenario("cpfa", ["controller.colour=red"])
    with pytest.raises(ScenarioError, match="depot.delivery: queue delivers to docks"):
        load_scenario("queue_qmt", ["depot.delivery=depot"])


def test_sections_belong_to_the_algorithms_and_round_trip():
    from swarm_sim.scenario import scenario_from_dict, scenario_to_dict

    s = load_scenario("queue_qst", ["controller.queue.lane_spacing=0.25", "controller.cpfa.search_step=0.1"])
    again = scenario_from_dict(scenario_to_dict(s))
    assert again == s
    assert scenario_to_dict(s)["controller"]["queue"]["lane_spacing"] == 0.25
    with pytest.raises(ScenarioError, match="controller.queue.wrapping: expected one of"):
        load_scenario("queue_qst", ["controller.queue.wrapping=triple"])


def test_every_section_is_named_once(monkeypatch):
    """A section's name lives in the registry record and in its dataclass's SECTION: they agree
    for every shipped section, and a record that disagrees with its class is refused by name."""
    for name in registry.config_sections():
        assert registry.config_section(name).SECTION == name
    sections = {**registry.config_sections(), "cage": registry.config_sections()["caging"]}
    monkeypatch.setattr(registry, "config_sections", lambda: sections)
    with pytest.raises(ValueError, match="controller.cage is declared as .*CagingConfig, whose SECTION is 'caging'"):
        registry.config_section("cage")


def test_the_scenario_module_imports_no_algorithm():
    code = ("import sys, swarm_sim.scenario, swarm_sim.sites, swarm_sim.registry; "
            "print(sorted(m for m in sys.modules if m.split('.')[0] in ('swarm_controllers', 'depot_manager')))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert out.stdout.strip() == "[]", out.stderr


def test_plugin_algorithm_is_found_by_its_entry_point_and_runs():
    """The dummy is a package of its own, outside every swarmforage package, and ships its scenario."""
    from importlib.metadata import entry_points

    from swarm_sim.analysis.metrics import summarize
    from swarm_sim.batch import run_batch

    (entry,) = (e for e in entry_points(group=registry.ENTRY_POINT_GROUP) if e.name == "dummy")
    assert entry.value == "dummy_algorithm.registration" and "dummy" in registry.known()
    scenario_file = registry.scenario_files()["dummy"]
    assert scenario_file.parent.name == "scenarios" and scenario_file.parents[1].name == "dummy_algorithm"
    for package in ("swarm_sim", "swarm_controllers", "swarm_msgs_py", "depot_manager", "launch_py"):
        assert not scenario_file.is_relative_to(REPO / package)
    result = summarize(run_batch(load_scenario("dummy", ["sim.duration=20.0"])).trace)
    assert result["pings_heard"] == 4 * 10  # 4 robots ping every 2 s for 20 s
    assert "queue_length_max" not in result and "regions" not in result  # other algorithms' fields


def test_world_sections_are_named_once_and_declared_once(monkeypatch):
    for name in registry.world_sections():
        assert registry.world_section(name).SECTION == name
    sections = {**registry.world_sections(), "regionz": registry.world_sections()["regions"]}
    monkeypatch.setattr(registry, "world_sections", lambda: sections)
    with pytest.raises(ValueError, match="section regionz is declared as .*RegionConfig, whose SECTION is 'regions'"):
        registry.world_section("regionz")
    clash = registry.TaskSpec("other", core="m:C", sensing="m:S", world=(("transport", "elsewhere:Transport"),))
    with pytest.raises(ValueError, match="section transport is already declared as .*caging.world_config:TransportConfig"):
        registry.register_task(clash)
    assert "other" not in registry._TASKS


def test_a_server_is_found_by_its_channel_and_built_from_its_record():
    """The generic server node (``swarm-server --channel ...``) needs nothing but the channel."""
    depot = registry.server("depot")
    assert depot in registry.algorithm("queue").servers and depot.node_name == "depot_manager"
    assert registry.server("center").node_name == "center"  # the same record for MDBSA-C and -D
    with pytest.raises(ValueError, match="no algorithm registers a server on channel 'moon' \\(known: .*depot"):
        registry.server("moon")
    with pytest.raises(ValueError, match="a series reads /nowhere"):
        SeriesLog([registry.ServerSpec("nest", "m:C", depot.family, "test_registry:_BAD_OUTPUTS")], {})


_BAD_OUTPUTS = ServerOutputs(series=(Series("/nowhere", lambda value: {}),))


def test_a_probe_measures_the_runs_that_ask_for_it():
    """The queue paper's perimeter crossings are measured in the runs delivering at its docks
    (its strategies and its CPFA baseline), not in a plain CPFA, spiral, DRTM or caging run; a
    second record is refused."""
    (perimeter,) = registry.probes()
    assert registry.probes(load_scenario("queue_cpfa")) == (perimeter,) == registry.probes(load_scenario("queue_qmt"))
    for name in ("cpfa", "mdbsa_d", "drtm", "caging"):
        assert registry.probes(load_scenario(name)) == (), name
    with pytest.raises(ValueError, match="probe 'perimeter' is already registered"):
        registry.register_probe(perimeter)
    from swarm_sim.analysis.metrics import summarize
    from swarm_sim.batch import run_batch

    caging = summarize(run_batch(load_scenario("caging", ["sim.duration=1.0"])).trace)
    drtm = summarize(run_batch(load_scenario("drtm", ["sim.duration=1.0"])).trace)
    queue = summarize(run_batch(load_scenario("queue_cpfa", ["sim.duration=1.0", "robots.count=4"])).trace)
    assert "dropoff_times_s" not in caging and "dropoff_times_s" not in drtm and queue["dropoff_times_s"] == []


def test_a_row_carries_the_core_its_task_and_its_own_algorithm_only():
    """No padding: a DRTM row has no caging or queue field, a caging row no DRTM one."""
    from swarm_sim.analysis.metrics import summarize
    from swarm_sim.batch import run_batch

    rows = {name: summarize(run_batch(load_scenario(name, ["sim.duration=1.0"])).trace) for name in ("drtm", "caging")}
    fields = {a.name: {m.name for m in a.metrics} for a in registry.algorithms()}
    for name, row in rows.items():
        mine = fields[registry.of(load_scenario(name)).name]
        others = set().union(*(f for a, f in fields.items() if not f <= mine)) - mine
        assert mine <= set(row) and not others & set(row), (name, sorted(others & set(row)))
