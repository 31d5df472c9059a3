"""The scenario: the one place where every world fact and every parameter lives.

A scenario is a YAML file (``swarm_sim/scenarios/<name>.yaml`` or any path) loaded into frozen
dataclasses, one per concern. Every node of the graph and the batch runner load the same
file with the same overrides, so the depot, the arena or a drop zone is described exactly once.

Loading validates as it goes: unknown keys, wrong types and impossible geometry are refused
with a `ScenarioError` naming the offending key (``resources.count: expected int, got 'many'``).
"""

from __future__ import annotations

import dataclasses
import math
import re
import types
import typing
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, ClassVar, Literal, get_args, get_origin

import yaml

if TYPE_CHECKING:
    from typing import Self  # Python >= 3.11; annotations only

DEFAULT_SCENARIO = "cpfa"
"""The scenario every command runs unless told otherwise (the CPFA baseline)."""


class ScenarioError(ValueError):
    """A scenario file or override is broken; the message names the key."""


# --------------------------------------------------------------------------- concerns


@dataclass(frozen=True)
class SimConfig:
    dt: float = 0.1
    """Control tick [s]: observations go out and commands come back once per tick."""
    physics_substeps: int = 2
    """pybullet steps per tick (each of dt / physics_substeps seconds)."""
    duration: float = 1080.0
    """Run length [s of sim time]."""
    stop_when_finished: bool = False
    """Batch runner only: end a run as soon as every behaviour says its task is over (a
    ``finished`` attribute, e.g. the caging robots once the object is delivered); the run's
    ``sim_seconds`` then says when. For sweeps: a graph run always lasts ``duration``."""


@dataclass(frozen=True)
class ArenaConfig:
    size: float = 12.0
    """Side L of the square arena [m]; the arena spans [-L/2, L/2] on both axes."""
    wall_thickness: float = 0.1
    """[m]; walls stand just outside the arena square."""


@dataclass(frozen=True)
class NoiseConfig:
    linear_std: float = 0.0
    """Encoder noise: std of the per-tick distance error as a fraction of distance travelled."""
    angular_std: float = 0.0
    """Std of the per-tick heading error as a fraction of the angle turned."""


@dataclass(frozen=True)
class RobotConfig:
    count: int = 16
    diameter: float = 0.17
    """Foot-bot-like cylinder diameter [m]."""
    height: float = 0.1
    """[m]; only matters for pybullet's collision shapes."""
    max_linear_speed: float = 0.16
    """[m/s] (ARGoS CPFA foot-bot forward speed 16 cm/s)."""
    max_angular_speed: float = 2.0
    """[rad/s]."""
    mass: float = 1.0
    """[kg]; only the ratio to the bodies robots push matters (the transport task's object)."""
    start_spacing: float = 0.4
    """Robots start on a square grid of this pitch [m] centred on the depot (`start_layout`
    grid); the other layouts keep robot centres at least this far apart."""
    start_layout: Literal["grid", "depot_random", "depot_ring", "groups"] = "grid"
    """Where robots start (`swarm_sim.world.start`): `grid` on the square grid above;
    `groups` in `start_groups` (ARGoS ``<distribute>`` blocks with a grid ``layout``);
    `depot_random` uniformly at random inside the depot disc (the DRTM paper's "placed in the
    nest randomly"); `depot_ring` evenly spaced on a circle just inside the depot's edge (the
    DRTM paper's e-puck set-up, "evenly distributed along the perimeter of the nest")."""
    start_groups: tuple[tuple[float, float], ...] = ()
    """`groups` layout: the centres of the groups [m, world frame]. The robots are dealt out in
    order, an equal share per group (the first groups take one more when it does not divide),
    each group on a grid of `start_group_columns` columns at `start_spacing`, row by row,
    centred on its point as if the grid had as many rows as columns; all facing +x."""
    start_group_columns: int = 6
    """Columns (and nominal rows) of a group's grid (ARGoS ``layout="6, 6, 1"``)."""
    radio_range: float = 0.4
    """gamma: robot-to-robot messages reach only robots within this distance [m] (queue paper
    sec. III; used by tail joining)."""
    odometry_noise: NoiseConfig = field(default_factory=NoiseConfig)


@dataclass(frozen=True)
class ScanConfig:
    rays: int = 24
    fov: float = 2 * math.pi
    """Field of view [rad], centred on the heading."""
    range_max: float = 3.5
    """[m]"""
    range_min: float = 0.0
    """[m], measured from the robot's centre."""
    backend: Literal["analytic", "pybullet"] = "analytic"
    """`analytic`: exact ray/circle and ray/segment intersection in numpy; `pybullet`:
    rayTestBatch against the collision shapes (slower, kept to cross-check)."""


@dataclass(frozen=True)
class ProximityConfig:
    """Proximity sensors around the robot's body, each reporting whether it detects something
    and what (the caging paper's ``sensors<detect, id>``). Defaults: the Khepera III's nine
    infra-red sensors (K-Team user manual, sec. 3.3; directions and 0.02-0.2 m range as in
    Georgia Tech's Sim.I.am Khepera III model)."""

    angles: tuple[float, ...] = (128.0, 75.0, 42.0, 13.0, -13.0, -42.0, -75.0, -128.0, 180.0)
    """Sensor directions [deg, robot frame, counter-clockwise from the heading]."""
    range: float = 0.2
    """How far beyond the robot's body a sensor sees [m]."""


@dataclass(frozen=True)
class ProximityRingConfig:
    """The foot-bot's ring of proximity sensors as the ARGoS CPFA reads it for collision
    detection: what the queue and spiral papers' *collision time* counts (`swarm_sim.world.proximity`).
    The ring's sensors are the scan's rays; defaults are ARGoS's foot-bot and the CPFA's rule."""

    range: float = 0.1
    """How far beyond the body a sensor sees [m] (ARGoS ``footbot_entity.cpp``:
    PROXIMITY_SENSOR_RING_RANGE = 0.1, the ring on the body radius)."""
    ahead: float = 80.0
    """Half-angle [deg] around the heading within which the readings' mean vector must point:
    the CPFA's ``GoStraightAngleRangeInDegrees.Set(-80, 80)`` (``BaseController.cpp`` of
    Tameem786/Collision_Free_CPFA and BCLab-UNM/CPFA-ARGoS)."""


@dataclass(frozen=True)
class SensorConfig:
    scan: ScanConfig = field(default_factory=ScanConfig)
    resource_detection_radius: float = 0.13
    """Resources whose centre is within this distance of the robot's centre are detected [m]."""
    pickup_radius: float = 0.05
    """An empty robot whose centre is within this distance of a resource picks it up [m]
    (the ARGoS CPFA FoodRadius)."""
    light_range: float = 2.0
    """Light sensing (world tasks with a light, e.g. the DRTM nest): a light farther than this
    from the robot's centre is not detected [m]."""
    proximity: ProximityConfig = field(default_factory=ProximityConfig)
    """Used by the transport task."""
    proximity_ring: ProximityRingConfig = field(default_factory=ProximityRingConfig)
    """What the world counts as collision time (``RobotStats.avoidance_time_s``)."""
    position_range: float = 1.5
    """Transport task: a robot senses the position of the target object and of other robots
    whose centres are within this distance of its own [m] (what the caging paper's robots read
    from CoppeliaSim for D_ell, D_r, theta_ell, theta_r and D_object)."""


@dataclass(frozen=True)
class ResourceConfig:
    distribution: Literal["clustered", "uniform", "powerlaw", "powerlaw_tiers"] = "clustered"
    """`swarm_sim.world.resources`: square clusters, uniform, Hecker & Moses's power law, or
    the DDSA/MDBSA authors' power law (tiers from `count`)."""
    count: int = 320
    """Total resources; for `clustered` it must equal clusters * cluster_side**2."""
    clusters: int = 5
    cluster_side: int = 8
    """Each cluster is a cluster_side x cluster_side grid (the queue paper's 8 x 8)."""
    spacing: float = 0.1
    """Grid pitch inside a cluster or power-law pile [m]."""
    powerlaw_levels: int = 4
    """`powerlaw`: pile sizes 4^j for j < levels, 4^(levels-1-j) piles of each (Hecker & Moses)."""
    min_depot_clearance: float = 1.0
    """Resources are placed at least this far from the depot's edge [m]."""
    margin: float = 0.3
    """Resources keep this distance from the walls [m]."""
    respawn: bool = False
    """When a resource is delivered, place a new one by the same distribution."""


@dataclass(frozen=True)
class DepotConfig:
    """The central depot: its disc, its docks and the perimeter around it (queue paper sec. III).
    World facts only; where the docks are is worked out by `swarm_sim.sites`."""

    center: tuple[float, float] = (0.0, 0.0)
    """[m, world frame]"""
    radius: float = 0.5
    """Radius of the central depot disc (the CPFA nest) [m]."""
    delivery: Literal["depot", "docks", "region_centers"] = "depot"
    """Where resources are delivered: `depot` anywhere in the depot disc (CPFA, DDSA,
    MDBSA-C); `docks` only at the docks after `unload_time` (queue strategies);
    `region_centers` at each region's center (MDBSA-D; see `regions`)."""
    perimeter_radius: float = 2.0
    """Radius of the perimeter (red circle) [m] around the depot; the queue paper's drop-off
    time runs from a carrier's entry into it."""
    docks: int = 4
    """Number K of docks on the depot boundary."""
    unload_time: float = 5.0
    """T_unload: a robot stays at its dock this long before its resource is dropped [s]. The
    queue paper gives no value; 5 s is our choice."""
    dock_radius: float = 0.06
    """A robot unloads while its centre is within this distance of the dock stop [m]."""
    dock_distance: float | None = None
    """Distance of the dock stops from the depot centre [m]; None: one robot radius outside
    the depot disc (where the queue layouts end)."""


@dataclass(frozen=True)
class RegionConfig:
    """The arena split into N_R = 4^k equal square regions (MDBSA paper eq. (3)); each region's
    centre is a drop zone when ``depot.delivery`` is `region_centers`."""

    count: int = 16
    """N_R, a power of 4 (the MDBSA paper's experiment 1 default is 16)."""
    center_radius: float = 0.25
    """Radius of each region centre's drop zone [m] (MDBSA-D), within which an idle MDBSA robot
    stops (the authors' ``RegionRadius``)."""


@dataclass(frozen=True)
class DropZoneConfig:
    """Somewhere a carried resource is delivered.

    `kind` is `depot` for the central depot disc (the default zone). Later kinds (docks with a
    dwell time, regional centres) are just more zones: the world drops a resource once its
    carrier has been inside a zone for `dwell` seconds without a break.
    """

    name: str
    center: tuple[float, float]
    radius: float
    dwell: float = 0.0
    kind: str = "depot"


@dataclass(frozen=True)
class ObstacleConfig:
    shape: Literal["box", "cylinder"]
    center: tuple[float, float]
    """[m, world frame]"""
    size: tuple[float, float] = (0.5, 0.5)
    """Box: full side lengths along its own x and y [m]; cylinder: (diameter, diameter)."""
    yaw: float = 0.0
    """Box orientation [rad]."""


@dataclass(frozen=True)
class TargetObjectConfig:
    """The transport task's cylindrical target object (caging paper sec. 3)."""

    radius: float = 0.3
    """r_object [m]."""
    mass: float = 0.3
    """M [kg]."""
    floor_friction: float = 0.4
    """Coulomb friction coefficient mu between the object and the floor: every physics substep
    the object's planar speed drops by mu g dt and its spin by (4/3) mu g dt / r (a uniformly
    pressed disc). The paper gives none; 0.4 is a plausible plastic-on-floor value."""


@dataclass(frozen=True)
class LandmarkConfig:
    """The transport task's landmarks: a square grid centred on the arena (caging paper sec. 3,
    Alg. 2); a landmark's neighbourhood eta is the up to eight grid neighbours around it."""

    step: float = 0.5
    """Grid step [m] (the paper's two discretisations: 0.5 and 1 m)."""
    extent: tuple[float, float] = (8.0, 7.0)
    """Width and height [m] of the rectangle the grid spans, corner landmarks included. The
    paper reports 255 landmarks for step 0.5 m and 72 for 1 m in its 10 x 10 m arena; an
    8 x 7 m grid is the one rectangle of whole metres that gives both (17 x 15 and 9 x 8), and
    it leaves 1 m to the walls, room for a cage around a landmark on its edge."""


@dataclass(frozen=True)
class TransportConfig:
    """World facts of the transport task (`swarm_controllers.caging.task`)."""

    object: TargetObjectConfig = field(default_factory=TargetObjectConfig)
    landmarks: LandmarkConfig = field(default_factory=LandmarkConfig)


@dataclass(frozen=True)
class AvoidanceConfig:
    distance: float = 0.3
    """Obstacles within this range of the robot's centre in the front sector trigger avoidance [m]."""
    front_fov: float = 2.0
    """Width of the front sector watched for obstacles [rad]."""
    turn_speed: float = 1.5
    """[rad/s] while turning away."""


class Section:
    """Base of an algorithm's scenario section (a frozen dataclass): `SECTION` is its key under
    ``controller``, `of` reads it from a scenario (its defaults if the scenario does not give it)."""

    SECTION: ClassVar[str] = ""

    @classmethod
    def of(cls, scenario: Scenario) -> Self:
        return scenario.controller.section(cls.SECTION)


@dataclass(frozen=True)
class ControllerConfig:
    """The robots' controller: which registered algorithm runs (`swarm_sim.registry`), the
    settings every behaviour shares, and the algorithms' own sections.

    An algorithm's section (``controller.cpfa``, ``controller.queue``...) is a frozen dataclass
    the algorithm declares in its registry record; `load_scenario` builds and checks it, and
    `section` hands it out. Sections left out of the file take their defaults.
    """

    behaviour: str = DEFAULT_SCENARIO
    """The registered algorithm (`swarm_sim.registry.known`)."""
    avoidance: AvoidanceConfig = field(default_factory=AvoidanceConfig)
    arrival_tolerance: float = 0.1
    """A target counts as reached within this distance [m]."""
    sections: tuple[tuple[str, Any], ...] = ()
    """(name, built section) for the sections given; see `section`."""

    def section(self, name: str) -> Any:
        """The algorithm section `name`, its defaults if the scenario did not give it."""
        for key, value in self.sections:
            if key == name:
                return value
        from swarm_sim.registry import config_section

        return config_section(name)()

    def with_section(self, name: str, value: Any) -> ControllerConfig:
        """A copy with section `name` replaced (tests and sweeps)."""
        rest = tuple((k, v) for k, v in self.sections if k != name)
        return dataclasses.replace(self, sections=tuple(sorted((*rest, (name, value)))))


@dataclass(frozen=True)
class Scenario:
    name: str = DEFAULT_SCENARIO
    seed: int = 0
    sim: SimConfig = field(default_factory=SimConfig)
    arena: ArenaConfig = field(default_factory=ArenaConfig)
    robots: RobotConfig = field(default_factory=RobotConfig)
    sensors: SensorConfig = field(default_factory=SensorConfig)
    resources: ResourceConfig = field(default_factory=ResourceConfig)
    depot: DepotConfig = field(default_factory=DepotConfig)
    regions: RegionConfig = field(default_factory=RegionConfig)
    drop_zones: tuple[DropZoneConfig, ...] = ()
    """Extra drop zones besides the ones ``depot.delivery`` implies (`swarm_sim.sites.drop_zones`)."""
    obstacles: tuple[ObstacleConfig, ...] = ()
    transport: TransportConfig = field(default_factory=TransportConfig)
    controller: ControllerConfig = field(default_factory=ControllerConfig)

    @property
    def dt_ns(self) -> int:
        return round(self.sim.dt * 1e9)

    @property
    def ticks(self) -> int:
        """Number of control ticks in a run."""
        return round(self.sim.duration / self.sim.dt)

    @property
    def robot_names(self) -> list[str]:
        return [f"robot_{i}" for i in range(self.robots.count)]


# --------------------------------------------------------------------------- loading


def _type_name(tp: Any) -> str:
    return getattr(tp, "__name__", None) or str(tp).replace("typing.", "")


_FLOAT_TEXT = re.compile(r"[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?")


def _convert(value: Any, tp: Any, key: str) -> Any:
    """Convert a YAML value to the annotated type, or raise naming `key`."""
    origin = get_origin(tp)
    if tp is Any:
        return value
    if dataclasses.is_dataclass(tp):
        if not isinstance(value, dict):
            raise ScenarioError(f"{key}: expected a mapping, got {value!r}")
        return _build(tp, value, key)
    if origin is Literal:
        if value not in get_args(tp):
            choices = ", ".join(repr(a) for a in get_args(tp))
            raise ScenarioError(f"{key}: expected one of {choices}, got {value!r}")
        return value
    if origin in (typing.Union, types.UnionType):
        errors = []
        for arg in get_args(tp):
            if arg is type(None):
                if value is None:
                    return None
                continue
            try:
                return _convert(value, arg, key)
            except ScenarioError as exc:
                errors.append(str(exc))
        raise ScenarioError(errors[0] if errors else f"{key}: bad value {value!r}")
    if origin is tuple:
        args = get_args(tp)
        if not isinstance(value, (list, tuple)):
            raise ScenarioError(f"{key}: expected a list, got {value!r}")
        if len(args) == 2 and args[1] is Ellipsis:
            return tuple(_convert(v, args[0], f"{key}[{i}]") for i, v in enumerate(value))
        if len(value) != len(args):
            raise ScenarioError(f"{key}: expected {len(args)} values, got {len(value)}")
        return tuple(_convert(v, a, f"{key}[{i}]") for i, (v, a) in enumerate(zip(value, args)))
    if tp is float:
        if isinstance(value, str) and _FLOAT_TEXT.fullmatch(value.strip()):
            value = float(value)  # YAML 1.1 reads 1e30 (no dot) as a string
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ScenarioError(f"{key}: expected a number, got {value!r}")
        if not math.isfinite(value):
            raise ScenarioError(f"{key}: expected a finite number, got {value!r}")
        return float(value)
    if tp is int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise ScenarioError(f"{key}: expected int, got {value!r}")
        return value
    if tp is bool:
        if not isinstance(value, bool):
            raise ScenarioError(f"{key}: expected true or false, got {value!r}")
        return value
    if tp is str:
        if not isinstance(value, str):
            raise ScenarioError(f"{key}: expected a string, got {value!r}")
        return value
    raise ScenarioError(f"{key}: unsupported type {_type_name(tp)}")


def _build(cls: type, data: dict[str, Any], prefix: str) -> Any:
    if cls is ControllerConfig:
        data = _with_sections(data, prefix)
    hints = typing.get_type_hints(cls)
    names = {f.name for f in dataclasses.fields(cls)}
    unknown = sorted(set(data) - names)
    if unknown:
        where = f"{prefix}." if prefix else ""
        raise ScenarioError(
            f"unknown key {where}{unknown[0]} (known keys: {', '.join(sorted(names))})"
        )
    kwargs = {}
    for name, value in data.items():
        key = f"{prefix}.{name}" if prefix else name
        kwargs[name] = _convert(value, hints[name], key)
    try:
        return cls(**kwargs)
    except TypeError as exc:  # a field without default left out
        raise ScenarioError(f"{prefix or 'scenario'}: {exc}") from None


def _with_sections(data: dict[str, Any], prefix: str) -> dict[str, Any]:
    """The ``controller`` mapping with the algorithms' sections built into ``sections``: every
    key that is not a field of ControllerConfig must name a registered section."""
    from swarm_sim.registry import config_section, config_sections

    fixed = {f.name for f in dataclasses.fields(ControllerConfig)} - {"sections"}
    out = {k: v for k, v in data.items() if k in fixed}
    sections = []
    for name in sorted(set(data) - fixed):
        if name not in config_sections():
            known = ", ".join(sorted(fixed | set(config_sections())))
            raise ScenarioError(f"unknown key {prefix}.{name} (known keys: {known})")
        value = data[name] if data[name] is not None else {}
        sections.append((name, _convert(value, config_section(name), f"{prefix}.{name}")))
    if sections:
        out["sections"] = tuple(sections)
    return out


def _set_path(data: dict[str, Any], dotted: str, value: Any) -> None:
    parts = dotted.split(".")
    node = data
    for part in parts[:-1]:
        child = node.setdefault(part, {})
        if not isinstance(child, dict):
            raise ScenarioError(f"--set {dotted}: {part} is not a mapping")
        node = child
    node[parts[-1]] = value


def parse_override(text: str) -> tuple[str, Any]:
    """``"robots.count=8"`` -> ``("robots.count", 8)``; the value is parsed as YAML."""
    key, sep, raw = text.partition("=")
    if not sep or not key.strip():
        raise ScenarioError(f"--set {text!r}: expected KEY=VALUE, e.g. robots.count=8")
    try:
        return key.strip(), yaml.safe_load(raw)
    except yaml.YAMLError as exc:
        raise ScenarioError(f"--set {key}: cannot parse value {raw!r}: {exc}") from None


def resolve_path(name_or_path: str) -> Path:
    """A scenario name (``cpfa``, shipped by a registered package: `registry.scenario_files`) or a
    path to a YAML file."""
    from swarm_sim.registry import scenario_files

    path = Path(name_or_path)
    if path.suffix in (".yaml", ".yml") or path.exists():
        if not path.is_file():
            raise ScenarioError(f"scenario file {path} does not exist")
        return path
    try:
        shipped = scenario_files()
    except ValueError as exc:
        raise ScenarioError(str(exc)) from None
    if name_or_path not in shipped:
        raise ScenarioError(f"unknown scenario {name_or_path!r} (known: {', '.join(shipped)})")
    return shipped[name_or_path]


def load_scenario(
    name_or_path: str = DEFAULT_SCENARIO,
    overrides: typing.Iterable[str] = (),
    **fields: Any,
) -> Scenario:
    """Load, override, build and validate a scenario.

    `overrides` are ``a.b=VALUE`` strings (the CLI's ``--set``); `fields` are dotted keys
    with ``__`` for dots, e.g. ``robots__count=8`` (the CLI's ``--robots``).
    """
    path = resolve_path(name_or_path)
    data = read_yaml(path)
    for text in overrides:
        _set_path(data, *parse_override(text))
    for key, value in fields.items():
        if value is not None:
            _set_path(data, key.replace("__", "."), value)
    scenario = _build(Scenario, data, "")
    validate(scenario)
    return scenario


START_RANDOM_COVERAGE = 0.4
"""`depot_random` start: robots may cover at most this fraction of the disc their centres
(widened by half the spacing) can use, so rejection sampling always finds room."""
MAX_DURATION = 1e7
"""[s] of sim time (about 116 days): a longer run is a typo, not an experiment."""
MIN_DT, MAX_DT = 1e-3, 10.0
"""[s] bounds of the control tick: the robots' controllers run at 1 kHz at most (a 1 ns tick
would make a one-second run a billion ticks), and a tick longer than 10 s is not control."""
MAX_SUBSTEPS = 1000
"""pybullet steps per tick."""
MAX_FILE_BYTES = 1 << 20
"""A scenario file larger than this is refused (ours are ~1 KB)."""


class _StrictLoader(yaml.SafeLoader):
    """safe_load that refuses duplicate keys (YAML says they are an error; PyYAML keeps the last)."""

    def construct_mapping(self, node, deep=False):  # noqa: ANN001 - PyYAML's signature
        seen = set()
        for key_node, _ in node.value:
            key = self.construct_object(key_node, deep=True)
            if isinstance(key, str) and key in seen:
                raise ScenarioError(f"duplicate key {key!r} (line {key_node.start_mark.line + 1})")
            seen.add(key)
        return super().construct_mapping(node, deep)


def read_yaml(path: Path) -> dict[str, Any]:
    """A scenario file's mapping; ScenarioError naming the file and the problem for anything
    that is not a non-empty, UTF-8, YAML mapping without duplicate keys."""
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise ScenarioError(f"{path}: cannot read: {exc.strerror}") from None
    if len(raw) > MAX_FILE_BYTES:
        raise ScenarioError(f"{path}: {len(raw)} bytes is larger than a scenario file can be ({MAX_FILE_BYTES})")
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ScenarioError(f"{path}: not UTF-8 text (byte {exc.start})") from None
    try:
        data = yaml.load(text, Loader=_StrictLoader)  # noqa: S506 - a SafeLoader subclass
    except ScenarioError as exc:
        raise ScenarioError(f"{path}: {exc}") from None
    except yaml.YAMLError as exc:
        raise ScenarioError(f"{path}: not valid YAML: {' '.join(str(exc).split())}") from None
    except RecursionError:
        raise ScenarioError(f"{path}: nested too deeply") from None
    if data is None:
        raise ScenarioError(f"{path}: the file is empty")
    if not isinstance(data, dict):
        raise ScenarioError(f"{path}: the top level must be a mapping")
    return data


def scenario_to_dict(scenario: Scenario) -> dict[str, Any]:
    """Plain-data form (for bag metadata and JSON results); `_build` accepts it back."""

    def plain(value: Any) -> Any:
        if dataclasses.is_dataclass(value):
            return {f.name: plain(getattr(value, f.name)) for f in dataclasses.fields(value)}
        if isinstance(value, tuple):
            return [plain(v) for v in value]
        return value

    data = plain(scenario)
    controller = data["controller"]
    for name, section in controller.pop("sections"):
        controller[name] = section
    return data


def scenario_from_dict(data: dict[str, Any]) -> Scenario:
    scenario = _build(Scenario, data, "")
    validate(scenario)
    return scenario


# --------------------------------------------------------------------------- geometry checks


def _require(condition: bool, message: str) -> None:
    if not condition:
        raise ScenarioError(message)


def _inside(point: tuple[float, float], half: float, clearance: float) -> bool:
    return abs(point[0]) + clearance <= half and abs(point[1]) + clearance <= half


def validate(s: Scenario) -> None:
    """Refuse impossible scenarios, naming the key at fault."""
    _require(MIN_DT <= s.sim.dt <= MAX_DT, f"sim.dt: must be between {MIN_DT:g} and {MAX_DT:g} s")
    _require(1 <= s.sim.physics_substeps <= MAX_SUBSTEPS,
             f"sim.physics_substeps: must be between 1 and {MAX_SUBSTEPS}")
    _require(s.sim.duration >= s.sim.dt, "sim.duration: must be at least one tick (sim.dt)")
    _require(s.sim.duration <= MAX_DURATION, f"sim.duration: at most {MAX_DURATION:g} s of sim time")
    _require(s.seed >= 0, "seed: must not be negative")
    _require(s.arena.size > 0, "arena.size: must be positive")
    half = s.arena.size / 2
    _require(
        _inside(s.depot.center, half, s.depot.radius),
        f"depot: a disc of radius {s.depot.radius} m at {s.depot.center} is outside the arena",
    )
    r = s.robots
    _require(r.count >= 1, "robots.count: need at least one robot")
    _require(r.diameter > 0, "robots.diameter: must be positive")
    _require(r.max_linear_speed > 0, "robots.max_linear_speed: must be positive")
    _require(r.max_angular_speed > 0, "robots.max_angular_speed: must be positive")
    _require(r.mass > 0, "robots.mass: must be positive")
    _require(
        r.start_spacing >= r.diameter,
        f"robots.start_spacing: {r.start_spacing} m is less than the robot diameter {r.diameter} m",
    )
    if r.start_layout == "grid":
        side = math.ceil(math.sqrt(r.count))
        extent = (side - 1) * r.start_spacing / 2 + r.diameter / 2
        _require(
            _inside(s.depot.center, half, extent),
            f"robots.count: {r.count} robots on a {side}x{side} grid of pitch {r.start_spacing} m "
            f"do not fit in the {s.arena.size} m arena",
        )
    elif r.start_layout == "groups":
        _require(len(r.start_groups) >= 1, "robots.start_groups: the groups layout needs at least one group")
        _require(r.start_group_columns >= 1, "robots.start_group_columns: need at least one column")
        per = math.ceil(r.count / len(r.start_groups))
        rows = math.ceil(per / r.start_group_columns)
        extent = max(r.start_group_columns - 1, 2 * rows - 1 - (r.start_group_columns - 1)) * r.start_spacing / 2
        for i, g in enumerate(r.start_groups):
            _require(_inside(g, half, extent + r.diameter / 2),
                     f"robots.start_groups[{i}]: a group of {per} robots at {g} does not fit in the arena")
    else:
        room = s.depot.radius - r.diameter / 2  # robot centres stay this close to the depot centre
        _require(room > 0, f"robots.start_layout: robots of diameter {r.diameter} m do not fit in the "
                           f"depot of radius {s.depot.radius} m")
        if r.start_layout == "depot_ring":
            _require(
                r.count == 1 or 2 * room * math.sin(math.pi / r.count) >= r.start_spacing,
                f"robots.count: {r.count} robots {r.start_spacing} m apart do not fit on a ring of "
                f"radius {room:.3f} m inside the depot",
            )
        else:  # random sequential addition jams near 55 % coverage; stay well below it
            _require(
                r.count * (r.start_spacing / 2) ** 2 <= START_RANDOM_COVERAGE * (room + r.start_spacing / 2) ** 2,
                f"robots.count: {r.count} robots {r.start_spacing} m apart are too many to place at "
                f"random in the depot of radius {s.depot.radius} m",
            )
    _require(s.sensors.light_range > 0, "sensors.light_range: must be positive")
    sc = s.sensors.scan
    _require(sc.rays >= 1, "sensors.scan.rays: need at least one ray")
    _require(0 < sc.fov <= 2 * math.pi + 1e-9, "sensors.scan.fov: must be in (0, 2*pi]")
    _require(sc.range_max > sc.range_min >= 0, "sensors.scan.range_max: must exceed range_min")
    _require(s.sensors.resource_detection_radius > 0, "sensors.resource_detection_radius: must be positive")
    _require(s.sensors.pickup_radius > 0, "sensors.pickup_radius: must be positive")
    _require(s.sensors.proximity.range > 0, "sensors.proximity.range: must be positive")
    _require(s.sensors.proximity_ring.range > 0, "sensors.proximity_ring.range: must be positive")
    _require(0 <= s.sensors.proximity_ring.ahead <= 180, "sensors.proximity_ring.ahead: must be in [0, 180] deg")
    _require(s.sensors.position_range > 0, "sensors.position_range: must be positive")
    t = s.transport
    _require(t.object.radius > 0, "transport.object.radius: must be positive")
    _require(t.object.mass > 0, "transport.object.mass: must be positive")
    _require(t.object.floor_friction >= 0, "transport.object.floor_friction: must not be negative")
    _require(t.landmarks.step > 0, "transport.landmarks.step: must be positive")
    _require(min(t.landmarks.extent) >= 0, "transport.landmarks.extent: must not be negative")
    res = s.resources
    _require(res.count >= 0, "resources.count: must not be negative")
    _require(res.spacing > 0, "resources.spacing: must be positive")
    _require(res.margin >= 0, "resources.margin: must not be negative")
    if res.distribution == "clustered":
        _require(res.clusters >= 1 and res.cluster_side >= 1, "resources.clusters: need >= 1 cluster")
        _require(
            res.count == res.clusters * res.cluster_side**2,
            f"resources.count: {res.count} != clusters * cluster_side^2 = "
            f"{res.clusters * res.cluster_side ** 2}",
        )
        span = (res.cluster_side - 1) * res.spacing
        _require(
            span + 2 * res.margin < s.arena.size,
            f"resources.cluster_side: a {span:.2f} m cluster does not fit in the arena",
        )
    if res.distribution == "powerlaw":
        _require(res.powerlaw_levels >= 1, "resources.powerlaw_levels: need at least 1")
    for i, z in enumerate(s.drop_zones):
        _require(z.radius > 0, f"drop_zones[{i}].radius: must be positive")
        _require(z.dwell >= 0, f"drop_zones[{i}].dwell: must not be negative")
        _require(_inside(z.center, half, 0.0), f"drop_zones[{i}].center: {z.center} is outside the arena")
    from swarm_sim.sites import drop_zones

    names = [z.name for z in drop_zones(s)]
    _require(len(set(names)) == len(names), "drop_zones: zone names must be unique ('depot' is taken)")
    for i, o in enumerate(s.obstacles):
        _require(min(o.size) > 0, f"obstacles[{i}].size: must be positive")
        _require(_inside(o.center, half, 0.0), f"obstacles[{i}].center: {o.center} is outside the arena")
    _require(s.controller.arrival_tolerance > 0, "controller.arrival_tolerance: must be positive")
    _require(r.radio_range > 0, "robots.radio_range: must be positive")
    g = s.regions
    k = round(math.log(g.count, 4)) if g.count >= 1 else -1
    _require(k >= 0 and 4**k == g.count, f"regions.count: {g.count} is not a power of 4")
    _require(g.center_radius > 0, "regions.center_radius: must be positive")
    d = s.depot
    _require(d.unload_time >= 0, "depot.unload_time: must not be negative")
    _require(d.dock_radius > 0, "depot.dock_radius: must be positive")
    _require(d.docks >= 1, "depot.docks: need at least one dock")
    _require(d.dock_distance is None or d.dock_distance > 0, "depot.dock_distance: must be positive")
    stop = d.radius + r.diameter / 2 if d.dock_distance is None else d.dock_distance
    _require(
        d.docks == 1 or 2 * stop * math.sin(math.pi / d.docks) >= r.diameter,
        f"depot.docks: {d.docks} docks do not fit side by side {stop} m from the depot centre",
    )
    _require(d.perimeter_radius > d.radius, "depot.perimeter_radius: must exceed depot.radius")
    if d.delivery == "docks":
        _require(
            _inside(d.center, half, d.perimeter_radius),
            f"depot.perimeter_radius: a perimeter of {d.perimeter_radius} m does not fit in the arena",
        )
    from swarm_sim.registry import check_scenario

    check_scenario(s)
