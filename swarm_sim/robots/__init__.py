"""Robot models: the platform a scenario's robots are (``robots.model``), as the papers' authors simulated it.

A model is a body (diameter, height, mass), its speed limits, its sensors (the proximity ring the
world counts collision time with and the behaviours avoid with, the light sensor's reach, ground
sensing of food), whether the world keeps it upright (`planar`), and the motion layer between the
behaviour and the wheels (`motion`, ``module:Class`` of a `swarm_controllers.motion.Drive`): like
the authors' ``BaseController``, behaviours set targets and headings and the model decides how the
robot moves there, so every algorithm runs on every model by configuration.

- ``generic``: today's robot, everything as the scenario's ``robots`` and ``sensors`` sections
  say, steered continuously and re-aimed every tick; not planar (the world's huge roll and pitch
  inertia keep it nearly upright, as before).
- ``footbot_cpfa``: the ARGoS foot-bot (`swarm_sim.robots.footbot`) driven as the CPFA lineage's
  ``BaseController`` drives it (the queue and spiral papers' code): stop-turn-go, and the
  lineage's collision detection (`swarm_controllers.robots.stop_turn_go`). Forward 16 cm/s
  (``RobotForwardSpeed``), turning with the wheels at +-8 cm/s (``RobotRotationSpeed``): 1.143
  rad/s (the queue and spiral authors' experiment files).
- ``footbot_foraging``: the foot-bot as the ARGoS foraging example drives it (the DRTM paper's
  set-up, `swarm_controllers.robots.wheel_turning`): ``max_speed`` 10 cm/s, turning in place at
  2 x 0.1 / 0.14 = 1.43 rad/s; the light seen anywhere in the arena; food seen when it lies under a
  motor ground sensor.
- ``khepera3``: K-Team's Khepera III (`swarm_sim.robots.khepera3`, the caging paper's robot),
  steered continuously (the caging behaviour drives it with its own PIDs).

Applying a model (`apply_model`, when a scenario is loaded) writes its values into the scenario,
so every reader of ``robots.diameter`` or ``sensors.scan`` sees the platform's; the values a
platform fixes replace the file's (the files describe the generic robot). ``robots.platform``
overrides single values of a platform model (to vary one factor: its body, speed limits and
sensor ranges), ``robots.planar`` the model's choice. This package imports nothing of the
project: the loader hands it the scenario.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from swarm_sim.robots import footbot, khepera3


def exp_reading(d: np.ndarray) -> np.ndarray:
    """The generic robot's proximity reading exp(-d), d [m] from the body (0 inside it)."""
    return np.exp(-np.maximum(d, 0.0))


def exp_value(d: float) -> float:
    """`exp_reading` of one hit, in plain floats."""
    return math.exp(-max(d, 0.0))


@dataclass(frozen=True)
class RobotModel:
    """One platform. None: the scenario's own value (the generic robot)."""

    name: str
    platform: str
    """What robot, in one line, and where its values come from."""
    motion: str
    """``module:Class`` of its motion layer (`swarm_controllers.motion.Drive`)."""
    planar: bool
    """The world keeps it exactly upright (no roll or pitch), as ARGoS's dynamics2d and
    CoppeliaSim's planar set-ups do."""
    diameter: float | None = None
    """[m]"""
    height: float | None = None
    """[m]"""
    mass: float | None = None
    """[kg]"""
    max_linear_speed: float | None = None
    """[m/s] the fastest the motion layer drives."""
    max_angular_speed: float | None = None
    """[rad/s] the fastest the motion layer turns."""
    ring_rays: int | None = None
    """The scan's rays, laid out as the proximity ring's sensors (``sensors.scan.rays``)."""
    ring_fov: float | None = None
    """[rad] ``sensors.scan.fov`` for that layout."""
    ring_range: float | None = None
    """[m] beyond the body (``sensors.proximity_ring.range``)."""
    ring_reading: Callable[[np.ndarray], np.ndarray] = exp_reading
    """A ring sensor's reading of a hit d [m] from the body (numpy, elementwise: the world's)."""
    ring_value: Callable[[float], float] = exp_value
    """The same for one hit, in plain floats (a controller's)."""
    light_everywhere: bool = False
    """The light sensor has no range (``sensors.light_range`` becomes the arena's diagonal)."""
    ground_food: bool = False
    """Food is seen when it lies under a ground sensor: ``sensors.resource_detection_radius`` =
    the food's radius (``sensors.pickup_radius``, within which it is taken) + the sensor's
    distance from the centre."""
    centre_in_depot: bool = False
    """A start in the depot (``robots.start_layout`` depot_random, depot_ring) puts the robots'
    centres in it, their bodies may reach over its edge: ARGoS's ``<distribute>`` only keeps the
    bodies from overlapping, and its loop functions count a robot in the nest by its position
    (the foraging example's ``CForagingLoopFunctions::PreStep``: ``cPos.GetX() < -1.5f``). The
    generic robot starts with its whole body inside."""


GENERIC = "generic"

MODELS: dict[str, RobotModel] = {m.name: m for m in (
    RobotModel(
        name=GENERIC,
        platform="today's robot: the scenario's robots and sensors sections as they are",
        motion="swarm_controllers.motion:ContinuousDrive",
        planar=False,
    ),
    RobotModel(
        name="footbot_cpfa",
        platform="ARGoS foot-bot (ilpincy/argos3) with the CPFA lineage's BaseController "
                 "(Tameem786/Collision_Free_CPFA, Artglz/Collision_Free_CPFA, MARSLab-UTRGV spiral code)",
        motion="swarm_controllers.robots.stop_turn_go:StopTurnGo",
        planar=True,
        diameter=2 * footbot.BODY_RADIUS, height=footbot.BODY_HEIGHT, mass=footbot.MASS,
        max_linear_speed=0.16, max_angular_speed=footbot.wheel_speed_to_turn_rate(0.08),
        ring_rays=footbot.RING_SENSORS, ring_fov=footbot.RING_FOV, ring_range=footbot.RING_RANGE,
        ring_reading=footbot.ring_reading, ring_value=footbot.ring_value, centre_in_depot=True,
    ),
    RobotModel(
        name="footbot_foraging",
        platform="ARGoS foot-bot (ilpincy/argos3) with the foraging example's wheel_turning and "
                 "diffusion (ilpincy/argos3-examples, controllers/footbot_foraging, experiments/foraging.argos)",
        motion="swarm_controllers.robots.wheel_turning:WheelTurning",
        planar=True,
        diameter=2 * footbot.BODY_RADIUS, height=footbot.BODY_HEIGHT, mass=footbot.MASS,
        max_linear_speed=0.1, max_angular_speed=footbot.wheel_speed_to_turn_rate(0.1),
        ring_rays=footbot.RING_SENSORS, ring_fov=footbot.RING_FOV, ring_range=footbot.RING_RANGE,
        ring_reading=footbot.ring_reading, ring_value=footbot.ring_value, light_everywhere=True,
        ground_food=True, centre_in_depot=True,
    ),
    RobotModel(
        name="khepera3",
        platform="K-Team Khepera III (user manual secs. 3.1, 3.2.1; Sim.I.am's wheel base)",
        motion="swarm_controllers.motion:ContinuousDrive",
        planar=True,
        diameter=khepera3.DIAMETER, height=khepera3.HEIGHT, mass=khepera3.MASS,
        max_linear_speed=khepera3.MAX_SPEED, max_angular_speed=khepera3.MAX_TURN_RATE,
    ),
)}

BODY_FIELDS = ("diameter", "height", "mass", "max_linear_speed", "max_angular_speed")
"""The ``robots`` fields a platform fixes and ``robots.platform`` may override."""
SENSOR_FIELDS = {"ring_range": "proximity_ring.range", "light_range": "light_range",
                 "resource_detection_radius": "resource_detection_radius"}
"""The sensor ranges ``robots.platform`` may override -> the ``sensors`` key each replaces."""


def known_models() -> tuple[str, ...]:
    return tuple(sorted(MODELS))


def robot_model(name: str) -> RobotModel:
    """The model `name`; ValueError naming ``robots.model`` and the known models."""
    try:
        return MODELS[name]
    except (KeyError, TypeError):
        raise ValueError(f"robots.model: unknown robot model {name!r} (known: {', '.join(known_models())})") from None


def model_of(scenario: Any) -> RobotModel:
    """The model of a (loaded) scenario."""
    return robot_model(scenario.robots.model)


def depot_start_room(scenario: Any) -> float:
    """[m] how far from the depot's centre a robot's centre may start (`RobotModel.centre_in_depot`)."""
    inside = 0.0 if model_of(scenario).centre_in_depot else scenario.robots.diameter / 2
    return scenario.depot.radius - inside


def apply_model(scenario: Any) -> Any:
    """`scenario` with its robot model's values written in (see the module docstring); ValueError
    naming the key for an unknown model or a platform override the generic robot cannot take.
    Idempotent: a scenario read back from a bag's metadata comes out the same."""
    r = scenario.robots
    model = robot_model(r.model)
    overrides = {f: getattr(r.platform, f) for f in (*BODY_FIELDS, *SENSOR_FIELDS)
                 if getattr(r.platform, f) is not None}
    for key, value in overrides.items():
        if not value > 0:
            raise ValueError(f"robots.platform.{key}: must be positive")
    planar = model.planar if r.planar is None else r.planar
    if model.name == GENERIC:
        if overrides:
            key = next(iter(overrides))
            own = f"sensors.{SENSOR_FIELDS[key]}" if key in SENSOR_FIELDS else f"robots.{key}"
            raise ValueError(f"robots.platform.{key}: the generic robot takes {own} itself "
                             f"(robots.platform overrides a platform model)")
        return dataclasses.replace(scenario, robots=dataclasses.replace(r, planar=planar))
    if "ring_range" in overrides and model.ring_range is None:
        raise ValueError(f"robots.platform.ring_range: the {model.name} robot model has no proximity ring")
    body = {f: overrides.get(f, getattr(model, f)) for f in BODY_FIELDS}
    # Robots start at least one body apart: the files' spacing is the generic robot's.
    robots = dataclasses.replace(r, **body, planar=planar, start_spacing=max(r.start_spacing, body["diameter"]))
    s = scenario.sensors
    sensors = s
    if model.ring_rays is not None:
        sensors = dataclasses.replace(
            sensors, scan=dataclasses.replace(s.scan, rays=model.ring_rays, fov=model.ring_fov),
            proximity_ring=dataclasses.replace(s.proximity_ring, range=model.ring_range),
        )
    if model.light_everywhere:
        sensors = dataclasses.replace(sensors, light_range=math.hypot(scenario.arena.size, scenario.arena.size))
    if model.ground_food:
        sensors = dataclasses.replace(
            sensors, resource_detection_radius=s.pickup_radius + footbot.GROUND_SENSOR_OFFSET)
    for field, key in SENSOR_FIELDS.items():
        if field in overrides:
            sensors = _replaced(sensors, key, overrides[field])
    return dataclasses.replace(scenario, robots=robots, sensors=sensors)


def _replaced(obj: Any, dotted: str, value: Any) -> Any:
    """Frozen dataclass `obj` with the field at `dotted` (``proximity_ring.range``) set to `value`."""
    head, _, rest = dotted.partition(".")
    return dataclasses.replace(obj, **{head: _replaced(getattr(obj, head), rest, value) if rest else value})
