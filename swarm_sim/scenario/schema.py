"""The scenario's schema: the generic world facts and the controller, as frozen dataclasses.

A scenario is a YAML file (shipped in a registered package's ``scenarios/`` folder, or any
path) loaded into these dataclasses, one per concern (`swarm_sim.scenario.loading`), and checked
(`swarm_sim.scenario.validation`). Every node of the graph and the batch runner load the same
file with the same overrides, so the depot, the arena or a drop zone is described exactly once.

What a task or an algorithm adds to the world (an object to move, a partition of the arena...)
is not here: it declares its own section in its registry record (`swarm_sim.registry`), a
dataclass deriving from `WorldSection` (a top-level key of the file) or from `Section` (a key
under ``controller``), and reads it back with ``TheSection.of(scenario)``.

This module imports nothing else of the project: the loader builds the declared sections, and a
section the file does not give is the defaults of the class the caller names in ``of``.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, ClassVar, Literal

if TYPE_CHECKING:
    from typing import Self  # Python >= 3.11; annotations only



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
    """End a run as soon as every behaviour says its task is over (a ``finished`` attribute, e.g.
    the caging robots once the object is delivered): the batch runner after that tick, the world
    node once every live robot's status says so (at that tick, or the next at the latest); the
    run's ``sim_seconds`` then says when, and its ``run_ended`` is ``finished``."""
    command_timeout: float = 0.5
    """Realtime mode: a robot whose newest command answers a tick more than this long before the
    current one [s of sim time] is stopped until a fresh one arrives, as a real robot's driver
    stops after its command timeout (diff_drive_controller's ``cmd_vel_timeout``, default 0.5 s);
    0: never (the robot keeps its last command). Lockstep waits for every command instead."""


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
class PlatformConfig:
    """Single values of a platform robot model overridden (to vary one factor at a time); None
    keeps the model's. The generic robot takes these from ``robots`` itself and refuses them here."""

    diameter: float | None = None
    """[m]"""
    height: float | None = None
    """[m]"""
    mass: float | None = None
    """[kg]"""
    max_linear_speed: float | None = None
    """[m/s]"""
    max_angular_speed: float | None = None
    """[rad/s]"""
    ring_range: float | None = None
    """[m] beyond the body: the proximity ring's reach (``sensors.proximity_ring.range``), on a
    model with a ring."""
    light_range: float | None = None
    """[m] how far the light is seen (``sensors.light_range``), instead of the model's (the
    foraging foot-bot's: everywhere in the arena)."""
    resource_detection_radius: float | None = None
    """[m] how far food is seen (``sensors.resource_detection_radius``), instead of the model's
    (the foraging foot-bot's: under its ground sensors)."""


@dataclass(frozen=True)
class StopTurnGoConfig:
    """The CPFA lineage's ``BaseController`` settings, read by the ``footbot_cpfa`` model's motion
    (`swarm_controllers.robots.stop_turn_go`). Defaults: the queue paper's authors' experiment files
    (Tameem786/Collision_Free_CPFA, ``experiments/*.xml``, ``<settings>``); the spiral paper's
    authors use 0.05 rad and 0.01 m (MARSLab-UTRGV, branch luki-dev, ``Distributed/experiments``)."""

    angle_tolerance: float = 0.1
    """``TargetAngleTolerance`` [rad]: a larger heading error is turned out on the spot first."""
    distance_tolerance: float = 0.05
    """``TargetDistanceTolerance`` [m]: a target this close is reached (the robot stops)."""
    collision_step: float = 0.08
    """``SearchStepSize`` [m]: the blind step pushed after a collision turn."""
    collision_turn: Literal["clockwise", "away"] = "clockwise"
    """How ``CollisionDetection`` turns: ``clockwise``, by the readings' angle, and forward instead
    of turning for ``collisionDelay`` (the CPFA's and the MDBSA authors' BaseController); or
    ``away``, away from the readings by 37.5 deg plus their angle, always turning (the DDSA
    authors' BaseController: MARSLab-UTRGV/DDSA-Distributed-Deterministic-Spiral-Search-Algorithm,
    luki-dev, ``source/Base/BaseController.cpp``, ``SetLeftTurn(37.5 - collisionAngle)`` /
    ``SetRightTurn(37.5 + collisionAngle)``, and a ``Move`` without the delay branch)."""


@dataclass(frozen=True)
class WheelTurningConfig:
    """The ARGoS foraging example's ``wheel_turning`` and ``diffusion`` parameters
    (ilpincy/argos3-examples, ``experiments/foraging.argos``), read by the ``footbot_foraging``
    model's motion (`swarm_controllers.robots.wheel_turning`)."""

    hard_turn_angle: float = 90.0
    """``hard_turn_angle_threshold`` [deg]: above it the robot turns in place."""
    soft_turn_angle: float = 70.0
    """``soft_turn_angle_threshold`` [deg]: a hard turn becomes soft at or below it."""
    no_turn_angle: float = 10.0
    """``no_turn_angle_threshold`` [deg]: at or below it the robot drives straight."""
    go_straight_angle: float = 5.0
    """``go_straight_angle_range`` = -5:5 [deg]: the proximity vector within it, and shorter
    than `delta`, is ignored."""
    delta: float = 0.1
    """``delta``: the longest proximity vector (sum of the 24 readings) ignored."""


@dataclass(frozen=True)
class RobotConfig:
    model: str = "generic"
    """The robot model (`swarm_sim.robots`): ``generic`` (this section's values as they are),
    ``footbot_cpfa`` (the ARGoS foot-bot with the CPFA lineage's stop-turn-go motion: the queue and
    spiral papers' authors'), ``footbot_foraging`` (the foot-bot with the ARGoS foraging example's
    motion and sensors: the DRTM paper's), ``khepera3`` (the caging paper's). A platform model
    fixes diameter, height, mass and both speed limits (`platform` overrides single ones), its
    sensors and its motion layer."""
    planar: bool | None = None
    """The world keeps the robots exactly upright; None: the model's choice (every platform
    model yes, the generic robot no)."""
    platform: PlatformConfig = field(default_factory=PlatformConfig)
    stop_turn_go: StopTurnGoConfig = field(default_factory=StopTurnGoConfig)
    wheel_turning: WheelTurningConfig = field(default_factory=WheelTurningConfig)
    count: int = 16
    diameter: float = 0.17
    """Foot-bot-like cylinder diameter [m] (a platform `model` sets its own)."""
    height: float = 0.1
    """[m]; only matters for pybullet's collision shapes."""
    max_linear_speed: float = 0.16
    """[m/s] (ARGoS CPFA foot-bot forward speed 16 cm/s)."""
    max_angular_speed: float = 2.0
    """[rad/s]."""
    mass: float = 1.0
    """[kg]; only the ratio to the bodies robots push matters (a task's movable object)."""
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
    """Read by the world tasks whose robots sense what touches them."""
    proximity_ring: ProximityRingConfig = field(default_factory=ProximityRingConfig)
    """What the world counts as collision time (``RobotStats.avoidance_time_s``)."""
    position_range: float = 1.5
    """World tasks that sense bodies: a robot senses the position of a task's movable object and
    of other robots whose centres are within this distance of its own [m] (what the caging
    paper's robots read from CoppeliaSim for D_ell, D_r, theta_ell, theta_r and D_object)."""


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
    """The central depot: its disc and where resources are delivered. World facts only; the drop
    zones a delivery kind implies are worked out by its registered record, from world sections of
    its own where it needs more (`swarm_sim.sites.drop_zones`)."""

    center: tuple[float, float] = (0.0, 0.0)
    """[m, world frame]"""
    radius: float = 0.5
    """Radius of the central depot disc (the CPFA nest) [m]."""
    delivery: str = "depot"
    """Where resources are delivered: a registered delivery kind (`swarm_sim.registry.DeliveryKind`):
    `depot` anywhere in the depot disc (the shared core's); the papers register the others."""


@dataclass(frozen=True)
class DropZoneConfig:
    """Somewhere a carried resource is delivered.

    `kind` is `depot` for the central depot disc (the default zone); the zones a delivery kind
    implies name their own kind. The world drops a resource once its carrier has been inside a
    zone for `dwell` seconds without a break.
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
class AvoidanceConfig:
    distance: float = 0.3
    """Obstacles within this range of the robot's centre in the front sector trigger avoidance [m]."""
    front_fov: float = 2.0
    """Width of the front sector watched for obstacles [rad]."""
    turn_speed: float = 1.5
    """[rad/s] while turning away."""


def _find(sections: tuple[tuple[str, Any], ...], name: str) -> Any:
    """The built section `name` of (name, section) pairs, None if absent."""
    for key, value in sections:
        if key == name:
            return value
    return None


def _with(sections: tuple[tuple[str, Any], ...], name: str, value: Any) -> tuple[tuple[str, Any], ...]:
    """`sections` with section `name` replaced, sorted by name."""
    rest = tuple((k, v) for k, v in sections if k != name)
    return tuple(sorted((*rest, (name, value)), key=lambda kv: kv[0]))


class Section:
    """Base of an algorithm's scenario section (a frozen dataclass): `SECTION` is its key under
    ``controller``, `of` reads it from a scenario (its defaults if the scenario does not give it)."""

    SECTION: ClassVar[str] = ""

    @classmethod
    def of(cls, scenario: Scenario) -> Self:
        found = scenario.controller.section(cls.SECTION)
        return cls() if found is None else found


class WorldSection:
    """Base of a world-fact section a task, an algorithm or a delivery kind declares (a frozen
    dataclass, named in the ``world`` of its registry record): `SECTION` is its top-level key in a
    scenario file, `of` reads it from a scenario (its defaults if the scenario does not give it),
    `check` refuses impossible values when the scenario is loaded."""

    SECTION: ClassVar[str] = ""
    MOVED: ClassVar[Mapping[str, str]] = {}
    """Dotted keys where scenarios recorded earlier kept some of its fields -> the field: a
    recorded scenario still loads (`swarm_sim.scenario.scenario_from_dict` carries them over)."""

    @classmethod
    def of(cls, scenario: Scenario) -> Self:
        found = scenario.section(cls.SECTION)
        return cls() if found is None else found

    def check(self) -> None:
        """Raise ValueError naming the key at fault (``<SECTION>.<field>: ...``); none by default."""


@dataclass(frozen=True)
class ControllerConfig:
    """The robots' controller: which registered algorithm runs (`swarm_sim.registry`), the
    settings every behaviour shares, and the algorithms' own sections.

    An algorithm's section (``controller.cpfa``, ``controller.queue``...) is a frozen dataclass
    the algorithm declares in its registry record; `load_scenario` builds and checks it, and
    `section` hands it out. Sections left out of the file take their defaults.
    """

    behaviour: str = ""
    """The registered algorithm (`swarm_sim.registry.known`); every scenario names one."""
    avoidance: AvoidanceConfig = field(default_factory=AvoidanceConfig)
    arrival_tolerance: float = 0.1
    """A target counts as reached within this distance [m]."""
    sections: tuple[tuple[str, Any], ...] = ()
    """(name, built section) for the sections given, sorted by name; see `section`."""

    def section(self, name: str) -> Any:
        """The algorithm section `name` as the scenario gives it, None if it does not (`Section.of`
        then takes the class's defaults)."""
        return _find(self.sections, name)

    def with_section(self, name: str, value: Any) -> ControllerConfig:
        """A copy with section `name` replaced (tests and sweeps)."""
        return dataclasses.replace(self, sections=_with(self.sections, name, value))


@dataclass(frozen=True)
class Scenario:
    """A whole scenario: the generic world facts, the controller, and the world sections that
    tasks and algorithms declare (`sections`)."""

    name: str = ""
    seed: int = 0
    sim: SimConfig = field(default_factory=SimConfig)
    arena: ArenaConfig = field(default_factory=ArenaConfig)
    robots: RobotConfig = field(default_factory=RobotConfig)
    sensors: SensorConfig = field(default_factory=SensorConfig)
    resources: ResourceConfig = field(default_factory=ResourceConfig)
    depot: DepotConfig = field(default_factory=DepotConfig)
    drop_zones: tuple[DropZoneConfig, ...] = ()
    """Extra drop zones besides the ones ``depot.delivery`` implies (`swarm_sim.sites.drop_zones`)."""
    obstacles: tuple[ObstacleConfig, ...] = ()
    controller: ControllerConfig = field(default_factory=ControllerConfig)
    sections: tuple[tuple[str, Any], ...] = ()
    """(name, built section) for the world sections given (top-level keys that tasks and
    algorithms declare, `swarm_sim.registry.world_sections`), sorted by name; see `section`."""

    def section(self, name: str) -> Any:
        """The world section `name` as the scenario gives it, None if it does not
        (`WorldSection.of` then takes the class's defaults)."""
        return _find(self.sections, name)

    def with_section(self, name: str, value: Any) -> Scenario:
        """A copy with world section `name` replaced (tests and sweeps)."""
        return dataclasses.replace(self, sections=_with(self.sections, name, value))

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


