"""The algorithm registry: one declarative record per algorithm, read by everything else.

ARGoS registers its controllers and loop functions by name, rosbags keeps a table of storage
plug-ins; here an `Algorithm` record says everything the rest of the code needs to know about
an algorithm: its behaviour, its world task, its scenario sections and checks, the servers it
needs, the message families its robots exchange, the drop zones it works with, its metrics, its
planned paths and its paper comparison. The launcher, the batch runner, the nodes, the launch
file, analysis and the comparisons read these records; no other module switches on an
algorithm's name. A `DeliveryKind` record says what a ``depot.delivery`` value means (the drop
zones it implies), registered by whoever provides it: ``depot`` by the shared core, the others by
their papers.

Every paper is a package that registers itself the way a third-party plug-in does: a module
named in the Python entry-point group ``swarmforage.algorithms`` (`importlib.metadata`, as
pytest and Gymnasium find their plug-ins) calls `register` / `register_task` when imported.
The entry points are loaded the first time the registry is read. A registering package ships
its scenario files in a ``scenarios/`` folder beside its registering module (`scenario_files`).

Records name code by ``"module:attribute"`` strings that are imported when first used, so the
registry (and the scenario loader that asks it for sections) imports no algorithm package, and
a behaviour's module loads only when a run uses it.

Sections: an algorithm declares its ``controller.<section>`` dataclasses (`Algorithm.config`), a
task or an algorithm the world facts it adds as top-level ``<section>`` dataclasses
(`TaskSpec.world`, `Algorithm.world`, `swarm_sim.scenario.WorldSection`). The loader accepts a
registered section in any scenario and builds it; ``TheSection.of(scenario)`` reads it back.

The registry imports the scenario schema for annotations only; the scenario's loader and
validation import the registry.

"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from dataclasses import dataclass
from functools import cache
from importlib.metadata import entry_points
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from swarm_msgs_py.topics import heard
from swarm_msgs_py.types import robot_index
from swarm_sim.presentation import Measure, Panel
from swarm_sim.protocol import ROBOTS

if TYPE_CHECKING:
    from swarm_sim.protocol import Server
    from swarm_sim.scenario.schema import DropZoneConfig, Scenario

ENTRY_POINT_GROUP = "swarmforage.algorithms"


@dataclass(frozen=True)
class ServerSpec:
    """A node core other than the world and the robots (`swarm_sim.protocol.Server`); on the
    graph it runs in the generic server node (``swarm-server --channel <channel>``,
    `swarm_sim.nodes.server_node`), built from this record alone."""

    channel: str
    """The channel its inbound messages travel on; also its name on ``/lockstep/ack``."""
    core: str
    """``module:Class``, built as ``Class(scenario)``."""
    family: str
    """``module:FAMILY``: the message family (`swarm_msgs_py.records.MessageFamily`) it speaks
    with the robots: it hears the family's messages on its channel and sends the others."""
    outputs: str | None = None
    """``module:OUTPUTS`` (`swarm_sim.outputs.ServerOutputs`): what its node publishes
    besides the family's messages (state topics, markers) and the run trace's time series read
    off what it publishes, the same in batch runs and bag replays (None: nothing)."""
    name: str = ""
    """Its node's name on the graph ('': the channel)."""

    @property
    def node_name(self) -> str:
        return self.name or self.channel


@dataclass(frozen=True)
class TaskSpec:
    """A world task (`swarm_sim.world.tasks`)."""

    name: str
    core: str
    """``module:Class``, built as ``Class(world, seeds)`` when the world builds tick 0."""
    sensing: str
    """``module:SENSING`` (`swarm_msgs_py.sensing.Sensing`): the sense's type and the codec of
    each of its fields in the sense message."""
    metrics: str | None = None
    """``module:function`` ``(trace) -> dict`` of the task's JSON result fields."""
    state: str | None = None
    """``module:STATE``: a tuple of `swarm_msgs_py.sensing.StateTopic`, the world-level topics
    the world node publishes from the task's ``state()`` every tick; the batch runner and the
    bag replay keep each as the time series ``RunTrace.series[field]`` (None: none)."""
    headline: tuple[Measure, ...] = ()
    """What a run's text summary shows of the task's own fields (before its algorithm's)."""
    extends: str | None = None
    """The task it builds on (the DRTM nest is the foraging task with food and a light)."""
    panels: tuple[Panel, ...] = ()
    """Its panels of a run's summary figure (before its algorithm's)."""
    bodies: str | None = None
    """``module:function`` ``(scenario) -> {state field: diameter [m]}``: the bodies a replay
    video draws to scale where its state topics put them (the caging object)."""
    world: tuple[tuple[str, str], ...] = ()
    """(section, ``module:Dataclass``): the world facts it adds, each a top-level scenario
    section (a `swarm_sim.scenario.WorldSection`)."""


@dataclass(frozen=True)
class Probe:
    """A measurement a package makes beyond the world task's own metrics, in the runs that ask
    for it (their delivery kind names it, `DeliveryKind.probes`): an observer of the robots'
    odometry positions, fed every tick by the batch runner as they are stepped and by the bag
    replay as they were recorded, and the result fields it yields."""

    name: str
    observer: str
    """``module:Class`` built as ``Class(scenario, robots)``; ``update(t [s], xy)`` with the
    (robots, 2) odometry positions [m, world frame] every tick; ``result()`` -> what its metrics
    read as ``RunTrace.probes[name]``."""
    metrics: str
    """``module:function`` ``(trace) -> dict`` of its JSON result fields."""
    details: tuple[tuple[str, str], ...] = ()
    """(list field, count field): per-event lists that sweeps store as their length only."""


@dataclass(frozen=True)
class DeliveryKind:
    """What a ``depot.delivery`` value means: where resources are delivered."""

    name: str
    """What ``depot.delivery`` says."""
    zones: str
    """``module:function`` ``(scenario) -> tuple[DropZoneConfig, ...]``: the drop zones it
    implies (`swarm_sim.sites.drop_zones` adds the scenario's own ``drop_zones``)."""
    resources_inside: bool = False
    """Resources may lie inside its zones: the world places them clear of the other drop zones
    only (`swarm_sim.sites.zones_clear_of_resources`), and one lying in a zone is delivered as
    soon as it is picked up."""
    checks: tuple[str, ...] = ()
    """``module:function`` ``(scenario) -> None`` raising ValueError naming the key at fault:
    what a scenario delivering this way must satisfy."""
    world: tuple[tuple[str, str], ...] = ()
    """(section, ``module:Dataclass``): the world facts its zones are made of, each a top-level
    scenario section (a `swarm_sim.scenario.WorldSection`)."""
    probes: tuple[str, ...] = ()
    """The probes (`Probe`) that measure the runs delivering this way."""


@dataclass(frozen=True)
class Metric:
    """A JSON result field an algorithm adds; only its own runs' rows carry it."""

    name: str
    function: str
    """``module:function`` ``(trace) -> value``."""


@dataclass(frozen=True)
class Algorithm:
    """Everything about one algorithm that code outside its own modules needs."""

    name: str
    """What ``controller.behaviour`` says."""
    paper: str
    """Where it is specified (a file of ../shared/papers and the section)."""
    behaviour: str
    """``module:Class``, built as ``Class(scenario, robot, rng)`` (`swarm_sim.behaviour.Behaviour`)."""
    task: str = "foraging"
    """The world task it runs in."""
    config: tuple[tuple[str, str], ...] = ()
    """(section, ``module:Dataclass``): its ``controller.<section>`` scenario sections."""
    world: tuple[tuple[str, str], ...] = ()
    """(section, ``module:Dataclass``): the world facts it adds, each a top-level scenario
    section (a `swarm_sim.scenario.WorldSection`)."""
    checks: tuple[str, ...] = ()
    """``module:function`` ``(scenario) -> None`` raising ValueError naming the key at fault."""
    servers: tuple[ServerSpec, ...] = ()
    peers: tuple[str, ...] = ()
    """``module:FAMILY``: message families its robots send each other (every robot hears and
    sends all of them)."""
    deliveries: tuple[str, ...] = ("depot",)
    """The ``depot.delivery`` kinds (`DeliveryKind`) it works with."""
    metrics: tuple[Metric, ...] = ()
    paths: str | None = None
    """``module:function`` ``(scenario) -> [(N, 2) waypoints]``: its planned paths, drawn
    under the recorded trajectories (None: it plans none)."""
    comparison: str | None = None
    """``module:OBJECT`` (`swarm_sim.compare.comparison.Comparison`): its paper's comparison."""
    trace_peers: bool = False
    """Keep its robots' peer messages in the run trace (``RunTrace.messages``): from the router
    in batch runs, from the recorded topics in bag replays (metrics that read the protocol)."""
    figures: str | None = None
    """``module:function`` ``(trace, directory) -> [Path]``: its own pictures of a run, drawn
    by ``swarm-analyze --trajectories`` (None: none)."""
    headline: tuple[Measure, ...] = ()
    """The paper's own measures, as a run's text summary shows them (after its task's)."""
    progress: str | None = None
    """``module:function`` ``(statuses) -> str``: what the world node's progress line says of the
    run, from every robot's last reported status (`swarm_msgs_py.types.BehaviourStatus`, by robot;
    e.g. the caging stage); None: its world task's ``progress()`` (deliveries)."""
    panels: tuple[Panel, ...] = ()
    """Its own panels of a run's summary figure (after its task's): e.g. its servers' series."""
    backdrop: str | None = None
    """``module:function`` ``(ax, scenario) -> None``: what it lays out in the world (a depot's
    queues and docks, regions, landmarks), drawn under the recorded trajectories on a matplotlib
    axis in metres, each part with a legend label."""
    states: tuple[str, ...] = ()
    """Every state its robots' statuses can report (``BehaviourStatus.state``), in the order a
    replay video's legend lists them, each with its own colour from the first frame."""
    authors_robot: str = "generic"
    """The robot model its authors' experiments ran on (``robots.model``, `swarm_sim.robots`):
    what ``swarm-compare --robot-model authors`` runs it on. Its shipped scenarios keep their own
    ``robots.model`` (the committed results were made with ``generic``)."""
    collision_rule: str | None = None
    """``module:function`` ``(scenario) -> rule``; ``rule(status: BehaviourStatus) -> float | None``:
    the half-angle [deg] about the heading within which the proximity ring's reading counts as
    collision time in the state the robot reports, None where it does not count (its authors
    count collision time in the controller, by state). Batch runs and bag replays then keep each
    robot's time by that rule in ``RunTrace.rule_collision_s`` (`swarm_sim.analysis.state_rules`)."""
    trace_status: bool = False
    """Keep every status its robots publish (``RunTrace.status_log``: batch runs ask every behaviour
    each tick, bag replays read ``/<robot>/status``), for metrics counted by state."""


_ALGORITHMS: dict[str, Algorithm] = {}
_TASKS: dict[str, TaskSpec] = {}
_DELIVERIES: dict[str, DeliveryKind] = {}
_PROBES: dict[str, Probe] = {}
_DEFAULT_SCENARIO: list[str] = []
"""The scenario that a registration declared the commands' default (`register_default_scenario`)."""
_PACKAGES: dict[str, Path] = {}
"""Entry-point name -> the folder of the module it loaded (where its ``scenarios/`` are)."""
_ORIGINS: dict[str, str] = {}
"""``algorithm:<name>`` / ``task:<name>`` -> the entry point that registered it."""
_loading = ""
_loaded = False


def _load_entries() -> None:
    """Import every module of the entry-point group once (sorted by name, so the order of
    registration does not depend on how the environment lists them)."""
    global _loaded, _loading
    if _loaded:
        return
    _loaded = True
    for entry in sorted(entry_points(group=ENTRY_POINT_GROUP), key=lambda e: e.name):
        _loading = entry.name
        try:
            module = importlib.import_module(entry.value)
        finally:
            _loading = ""
        _PACKAGES[entry.name] = Path(module.__file__).resolve().parent


def origin(kind: str, name: str) -> str:
    """The entry point (a package's registration) that registered algorithm, task or delivery
    kind `name` (`kind` ``algorithm``, ``task`` or ``delivery``); empty if it was registered by a
    direct call."""
    _load_entries()
    return _ORIGINS.get(f"{kind}:{name}", "")


def scenario_files() -> dict[str, Path]:
    """Scenario name -> its YAML file, over every registered package's ``scenarios/`` folder;
    ValueError naming both files if two packages ship the same name."""
    _load_entries()
    out: dict[str, Path] = {}
    for folder in _PACKAGES.values():
        for path in sorted((folder / "scenarios").glob("*.yaml")):
            if path.stem in out:
                raise ValueError(f"scenario {path.stem!r} is shipped twice: {out[path.stem]} and {path}")
            out[path.stem] = path
    return dict(sorted(out.items()))


def _refuse_redeclared(sections: tuple[tuple[str, str], ...], declared: dict[str, str], where: str) -> None:
    """ValueError if a section of `sections` is already declared (in `declared`) as another dataclass."""
    for name, path in sections:
        if declared.get(name, path) != path:
            raise ValueError(f"section {where}{name} is already declared as {declared[name]}")


def register(algorithm: Algorithm) -> Algorithm:
    """Make `algorithm` known; refuses a second record of the same name or a section name
    already declared with another dataclass."""
    if algorithm.name in _ALGORITHMS:
        raise ValueError(f"algorithm {algorithm.name!r} is already registered")
    _refuse_redeclared(algorithm.config, _declared_config(), "controller.")
    _refuse_redeclared(algorithm.world, _declared_world(), "")
    _ALGORITHMS[algorithm.name] = algorithm
    _ORIGINS[f"algorithm:{algorithm.name}"] = _loading
    return algorithm


def register_task(task: TaskSpec) -> TaskSpec:
    """Make `task` known; refuses a second record of the same name or a world section already
    declared with another dataclass."""
    if task.name in _TASKS:
        raise ValueError(f"world task {task.name!r} is already registered")
    _refuse_redeclared(task.world, _declared_world(), "")
    _TASKS[task.name] = task
    _ORIGINS[f"task:{task.name}"] = _loading
    return task


def register_delivery(kind: DeliveryKind) -> DeliveryKind:
    """Make delivery kind `kind` known; refuses a second record of the same name or a world
    section already declared with another dataclass."""
    if kind.name in _DELIVERIES:
        raise ValueError(f"delivery kind {kind.name!r} is already registered")
    _refuse_redeclared(kind.world, _declared_world(), "")
    _DELIVERIES[kind.name] = kind
    _ORIGINS[f"delivery:{kind.name}"] = _loading
    return kind


def register_probe(probe: Probe) -> Probe:
    """Make `probe` known; refuses a second record of the same name."""
    if probe.name in _PROBES:
        raise ValueError(f"probe {probe.name!r} is already registered")
    _PROBES[probe.name] = probe
    return probe


def probes(scenario: Scenario | None = None) -> tuple[Probe, ...]:
    """The probes that measure runs of `scenario`: those its delivery kind asks for (None: every
    probe)."""
    _load_entries()
    if scenario is None:
        return tuple(_PROBES.values())
    return tuple(_PROBES[name] for name in delivery_kind(scenario.depot.delivery).probes)


def register_default_scenario(name: str) -> None:
    """Make scenario `name` (one the registering package ships) what every command runs unless
    told otherwise; refuses a second claim, naming both."""
    if _DEFAULT_SCENARIO and _DEFAULT_SCENARIO[0] != name:
        raise ValueError(f"default scenario: {name!r} claimed, but {_DEFAULT_SCENARIO[0]!r} already is")
    _DEFAULT_SCENARIO[:] = [name]


def default_scenario() -> str:
    """The commands' default scenario; ValueError if no registered package declares one."""
    _load_entries()
    if not _DEFAULT_SCENARIO:
        raise ValueError("no registered package declares a default scenario (register_default_scenario)")
    return _DEFAULT_SCENARIO[0]


def resolve(path: str) -> Any:
    """``"package.module:attribute"`` -> the attribute (imported on first use)."""
    module, _, attribute = path.partition(":")
    return getattr(importlib.import_module(module), attribute)


def known() -> tuple[str, ...]:
    _load_entries()
    return tuple(sorted(_ALGORITHMS))


def algorithms() -> tuple[Algorithm, ...]:
    _load_entries()
    return tuple(_ALGORITHMS[name] for name in sorted(_ALGORITHMS))


def algorithm(name: str) -> Algorithm:
    """The record of `name`; ValueError naming the known ones."""
    _load_entries()
    try:
        return _ALGORITHMS[name]
    except KeyError:
        raise ValueError(
            f"controller.behaviour: unknown behaviour {name!r} (known: {', '.join(known())})"
        ) from None


def of(scenario: Scenario) -> Algorithm:
    """The algorithm a scenario runs."""
    return algorithm(scenario.controller.behaviour)


def task(name: str) -> TaskSpec:
    _load_entries()
    try:
        return _TASKS[name]
    except KeyError:
        raise ValueError(f"unknown world task {name!r} (known: {', '.join(sorted(_TASKS))})") from None


def _declared_config() -> dict[str, str]:
    return {name: path for a in _ALGORITHMS.values() for name, path in a.config}


def _declared_world() -> dict[str, str]:
    records = (*_TASKS.values(), *_ALGORITHMS.values(), *_DELIVERIES.values())
    return {name: path for r in records for name, path in r.world}


def config_sections() -> dict[str, str]:
    """Every registered ``controller.<section>`` -> its ``module:Dataclass``."""
    _load_entries()
    return _declared_config()


def world_sections() -> dict[str, str]:
    """Every registered top-level world section -> its ``module:Dataclass``."""
    _load_entries()
    return _declared_world()


@cache
def _section_class(path: str) -> type:
    return resolve(path)


def _declared_class(sections: dict[str, str], name: str, key: str) -> type:
    """The dataclass declared for section `name` (scenario key `key`).

    The registry names a section so that a scenario's keys are checked without importing every
    algorithm's config module; the dataclass's own ``SECTION`` is what it reads back (`of`).
    The two must be one name, so a record whose name and class disagree is refused here."""
    if name not in sections:
        raise ValueError(f"no task or algorithm declares a section {key}")
    cls = _section_class(sections[name])
    if getattr(cls, "SECTION", None) != name:
        raise ValueError(f"section {key} is declared as {sections[name]}, whose SECTION is "
                         f"{getattr(cls, 'SECTION', None)!r}")
    return cls


def config_section(name: str) -> type:
    """The dataclass of section ``controller.<name>`` (a `swarm_sim.scenario.Section`)."""
    return _declared_class(config_sections(), name, f"controller.{name}")


def world_section(name: str) -> type:
    """The dataclass of the top-level world section `name` (a `swarm_sim.scenario.WorldSection`)."""
    return _declared_class(world_sections(), name, name)


def delivery_kinds() -> tuple[str, ...]:
    """Every registered delivery kind (what ``depot.delivery`` may say)."""
    _load_entries()
    return tuple(sorted(_DELIVERIES))


def delivery_kind(name: str) -> DeliveryKind:
    """The record of delivery kind `name`; ValueError naming the key and the known kinds."""
    _load_entries()
    try:
        return _DELIVERIES[name]
    except KeyError:
        raise ValueError(
            f"depot.delivery: unknown delivery kind {name!r} (known: {', '.join(delivery_kinds())})"
        ) from None


def delivery_zones(scenario: Scenario, kind: str | None = None) -> tuple[DropZoneConfig, ...]:
    """The drop zones delivery kind `kind` implies in the scenario's world (default: the kind
    ``depot.delivery`` names), without the scenario's own ``drop_zones`` (`swarm_sim.sites.drop_zones`
    gives them all)."""
    return tuple(resolve(delivery_kind(kind or scenario.depot.delivery).zones)(scenario))


def check_scenario(scenario: Scenario) -> None:
    """The registered half of validating a scenario: the delivery kind's checks pass, the
    behaviour is registered, the delivery kind suits it and its own checks pass (ValueError
    naming the key; `swarm_sim.scenario.validation` reports it as a ScenarioError)."""
    for check in delivery_kind(scenario.depot.delivery).checks:
        resolve(check)(scenario)
    a = of(scenario)
    if scenario.depot.delivery not in a.deliveries:
        raise ValueError(
            f"depot.delivery: {a.name} delivers to {' or '.join(a.deliveries)}, "
            f"not {scenario.depot.delivery!r}"
        )
    for check in a.checks:
        resolve(check)(scenario)


# --------------------------------------------------------------------------- building cores


def make_behaviour(scenario: Scenario, robot: str, rng: np.random.Generator) -> Any:
    """The behaviour of the scenario's algorithm for `robot`."""
    robot_index(robot)  # refuse ids that are not robot_<i>
    return resolve(of(scenario).behaviour)(scenario, robot, rng)


def server(channel: str) -> ServerSpec:
    """The server registered on `channel` (by any algorithm); ValueError naming the known
    channels, or the algorithms that register different servers on it."""
    found = {s: a.name for a in algorithms() for s in a.servers if s.channel == channel}
    if not found:
        known = sorted({s.channel for a in algorithms() for s in a.servers})
        raise ValueError(f"no algorithm registers a server on channel {channel!r} (known: {', '.join(known)})")
    if len(found) > 1:
        raise ValueError(f"channel {channel!r}: different servers registered by {', '.join(sorted(found.values()))}")
    return next(iter(found))


def make_servers(scenario: Scenario) -> dict[str, Server]:
    """The server cores the scenario's algorithm needs, by channel."""
    return {s.channel: resolve(s.core)(scenario) for s in of(scenario).servers}


def task_factory(scenario: Scenario) -> Callable[..., Any]:
    """The world task class of the scenario's algorithm."""
    return resolve(task(of(scenario).task).core)


# --------------------------------------------------------------------------- wiring on the graph


def _channel(cls: type) -> str:
    """The channel a message class travels on (`swarm_sim.protocol.channel_of`)."""
    return getattr(cls, "CHANNEL", ROBOTS)


def robot_topics(algorithm: Algorithm) -> tuple[dict[str, Any], dict[str, Any]]:
    """(inbound, outbound) topic -> message family of a robot's controller: with each server it
    sends the family's messages on the server's channel and hears the rest; its peer families
    it sends on their topics and hears on the world's relay of them (`peer_topics`)."""
    inbound: dict[str, Any] = {}
    outbound: dict[str, Any] = {}
    for spec in algorithm.servers:
        family = resolve(spec.family)
        for cls, topic in family.topics.items():
            (outbound if _channel(cls) == spec.channel else inbound)[topic] = family
    for topic, family in peer_topics(algorithm).items():
        outbound[topic] = family
        inbound[heard(topic)] = family
    return inbound, outbound


def peer_topics(algorithm: Algorithm) -> dict[str, Any]:
    """Topic -> message family of what the robots send each other; the world relays each to
    ``heard(topic)`` (robots never match each other directly: N relays, not N x N matches)."""
    return {topic: family for family in map(resolve, algorithm.peers) for topic in family.topics.values()}


def server_topics(spec: ServerSpec) -> tuple[dict[str, Any], dict[str, Any]]:
    """(inbound, outbound) topic -> message family of a server: it hears its channel's
    messages and sends the others."""
    family = resolve(spec.family)
    inbound = {t: family for cls, t in family.topics.items() if _channel(cls) == spec.channel}
    outbound = {t: family for cls, t in family.topics.items() if _channel(cls) != spec.channel}
    return inbound, outbound
