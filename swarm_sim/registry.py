"""The algorithm registry: one declarative record per algorithm, read by everything else.

ARGoS registers its controllers and loop functions by name, rosbags keeps a table of storage
plug-ins; here an `Algorithm` record says everything the rest of the code needs to know about
an algorithm: its behaviour, its world task, its scenario sections and checks, the servers it
needs, the message families its robots exchange, the drop zones it works with, its metrics, its
planned paths and its paper comparison. The launcher, the batch runner, the nodes, the launch
file, analysis and the comparisons read these records; no other module switches on an
algorithm's name.

Every paper is a package that registers itself the way a third-party plug-in does: a module
named in the Python entry-point group ``swarmforage.algorithms`` (`importlib.metadata`, as
pytest and Gymnasium find their plug-ins) calls `register` / `register_task` when imported.
The entry points are loaded the first time the registry is read. A registering package ships
its scenario files in a ``scenarios/`` folder beside its registering module (`scenario_files`).

Records name code by ``"module:attribute"`` strings that are imported when first used, so the
registry (and the scenario loader that asks it for sections) imports no algorithm package, and
a behaviour's module loads only when a run uses it.

"""

from __future__ import annotations

import importlib
import warnings
from collections.abc import Callable
from dataclasses import InitVar, dataclass
from functools import cache
from importlib.metadata import entry_points
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from swarm_sim.protocol import Server
    from swarm_sim.scenario import Scenario

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
    """``module:OUTPUTS`` (`swarm_msgs_py.server_outputs.ServerOutputs`): what its node publishes
    besides the family's messages (state topics, markers) and the run trace's time series read
    off what it publishes, the same in batch runs and bag replays (None: nothing)."""
    name: str = ""
    """Its node's name on the graph ('': the channel)."""
    node: InitVar[str | None] = None
    script: InitVar[str | None] = None
    replay: InitVar[str | None] = None
    """Deprecated and ignored: a plug-in's record written when each server had a node module and
    console script of its own, and a replay function beside its ``series()``, still loads (with
    a FutureWarning) but its server publishes and records only what `outputs` declares."""

    def __post_init__(self, node: str | None, script: str | None, replay: str | None) -> None:
        if node or script or replay:
            warnings.warn(f"ServerSpec({self.channel!r}): node=, script= and replay= are ignored (every server runs "
                          "in swarm_sim.nodes.server_node; declare its state, markers and series in outputs=)",
                          FutureWarning, stacklevel=3)

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
    """``module:SENSING`` (`swarm_msgs_py.sensing.Sensing`): the sense's type and the topic,
    ROS type and codec of each of its fields."""
    metrics: str | None = None
    """``module:function`` ``(trace) -> dict`` of the task's JSON result fields."""
    state: str | None = None
    """``module:STATE``: a tuple of `swarm_msgs_py.sensing.StateTopic`, the world-level topics
    the world node publishes from the task's ``state()`` every tick; the batch runner and the
    bag replay keep each as the time series ``RunTrace.series[field]`` (None: none)."""


@dataclass(frozen=True)
class Metric:
    """A JSON result field an algorithm adds; runs of other algorithms report `default`."""

    name: str
    function: str
    """``module:function`` ``(trace) -> value``."""
    default: Any = None


@dataclass(frozen=True)
class Algorithm:
    """Everything about one algorithm that code outside its own modules needs."""

    name: str
    """What ``controller.behaviour`` says."""
    paper: str
    """Where it is specified (a file of ../shared/papers and the section)."""
    behaviour: str
    """``module:Class``, built as ``Class(scenario, robot, rng)`` (`swarm_controllers.api.Behaviour`)."""
    task: str = "foraging"
    """The world task it runs in."""
    config: tuple[tuple[str, str], ...] = ()
    """(section, ``module:Dataclass``): its ``controller.<section>`` scenario sections."""
    checks: tuple[str, ...] = ()
    """``module:function`` ``(scenario) -> None`` raising ValueError naming the key at fault."""
    servers: tuple[ServerSpec, ...] = ()
    peers: tuple[str, ...] = ()
    """``module:FAMILY``: message families its robots send each other (every robot hears and
    sends all of them)."""
    deliveries: tuple[str, ...] = ("depot",)
    """The ``depot.delivery`` sites it works with (the drop zones it implies)."""
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


_ALGORITHMS: dict[str, Algorithm] = {}
_TASKS: dict[str, TaskSpec] = {}
_PACKAGES: dict[str, Path] = {}
"""Entry-point name -> the folder of the module it loaded (where its ``scenarios/`` are)."""
_loaded = False


def _load_entries() -> None:
    """Import every module of the entry-point group once (sorted by name, so the order of
    registration does not depend on how the environment lists them)."""
    global _loaded
    if _loaded:
        return
    _loaded = True
    for entry in sorted(entry_points(group=ENTRY_POINT_GROUP), key=lambda e: e.name):
        module = importlib.import_module(entry.value)
        _PACKAGES[entry.name] = Path(module.__file__).resolve().parent


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


def register(algorithm: Algorithm) -> Algorithm:
    """Make `algorithm` known; refuses a second record of the same name or a section name
    already declared with another dataclass."""
    if algorithm.name in _ALGORITHMS:
        raise ValueError(f"algorithm {algorithm.name!r} is already registered")
    for name, path in algorithm.config:
        for other in _ALGORITHMS.values():
            if dict(other.config).get(name, path) != path:
                raise ValueError(f"section controller.{name} is already declared as {dict(other.config)[name]}")
    _ALGORITHMS[algorithm.name] = algorithm
    return algorithm


def register_task(task: TaskSpec) -> TaskSpec:
    if task.name in _TASKS:
        raise ValueError(f"world task {task.name!r} is already registered")
    _TASKS[task.name] = task
    return task


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


def config_sections() -> dict[str, str]:
    """Every registered ``controller.<section>`` -> its ``module:Dataclass``."""
    _load_entries()
    return {name: path for a in _ALGORITHMS.values() for name, path in a.config}


@cache
def _section_class(path: str) -> type:
    return resolve(path)


def config_section(name: str) -> type:
    """The dataclass of section ``controller.<name>``.

    The registry names a section so that a scenario's keys are checked without importing every
    algorithm's config module; the dataclass's own ``SECTION`` is what it reads back (`Section.of`).
    The two must be one name, so a record whose name and class disagree is refused here."""
    sections = config_sections()
    if name not in sections:
        raise ValueError(f"no algorithm declares a section controller.{name}")
    cls = _section_class(sections[name])
    if getattr(cls, "SECTION", None) != name:
        raise ValueError(f"section controller.{name} is declared as {sections[name]}, whose SECTION is "
                         f"{getattr(cls, 'SECTION', None)!r}")
    return cls


def check_scenario(scenario: Scenario) -> None:
    """The algorithm-specific half of loading a scenario: the behaviour is registered, the
    delivery sites suit it and its own checks pass (ScenarioError naming the key)."""
    from swarm_sim.scenario import ScenarioError

    try:
        a = of(scenario)
        if scenario.depot.delivery not in a.deliveries:
            raise ValueError(
                f"depot.delivery: {a.name} delivers to {' or '.join(a.deliveries)}, "
                f"not {scenario.depot.delivery!r}"
            )
        for check in a.checks:
            resolve(check)(scenario)
    except ValueError as exc:
        raise ScenarioError(str(exc)) from None


# --------------------------------------------------------------------------- building cores


def make_behaviour(scenario: Scenario, robot: str, rng: np.random.Generator) -> Any:
    """The behaviour of the scenario's algorithm for `robot`."""
    from swarm_sim.types import robot_index

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
    from swarm_sim.protocol import ROBOTS

    return getattr(cls, "CHANNEL", ROBOTS)


def robot_topics(algorithm: Algorithm) -> tuple[dict[str, Any], dict[str, Any]]:
    """(inbound, outbound) topic -> message family of a robot's controller: with each server it
    sends the family's messages on the server's channel and hears the rest; its peer families
    it sends on their topics and hears on the world's relay of them (`peer_topics`)."""
    from swarm_msgs_py.topics import heard

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
