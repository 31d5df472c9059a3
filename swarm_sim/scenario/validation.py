"""Validating a scenario: impossible values and geometry refused with a ScenarioError naming the key.

`check_world` checks the generic world facts of `swarm_sim.scenario.schema`; `validate` adds what
the registry knows (each declared world section's own `check`, the delivery kind, its drop
zones, the kind's and the algorithm's checks). `swarm_sim.scenario.loading` calls `validate`
on every scenario it builds.
"""

from __future__ import annotations

import math
import re

from swarm_sim import registry
from swarm_sim.robots import depot_start_room
from swarm_sim.scenario.schema import Scenario, ScenarioError

START_RANDOM_COVERAGE = 0.45
"""`depot_random` start: robots may cover at most this fraction of the disc their centres
(widened by half the spacing) can use, so rejection sampling finds room (random sequential
addition of discs jams near 0.547; 20 foot-bots with their centres in a 1 m nest, the DRTM
paper's Sec. 4.4 on its ARGoS robots, cover 0.42: placed in 300 of 300 seeds)."""
MAX_DURATION = 1e7
"""[s] of sim time (about 116 days): a longer run is a typo, not an experiment."""
MIN_DT, MAX_DT = 1e-3, 10.0
"""[s] bounds of the control tick: the robots' controllers run at 1 kHz at most (a 1 ns tick
would make a one-second run a billion ticks), and a tick longer than 10 s is not control."""
MAX_SUBSTEPS = 1000
"""pybullet steps per tick."""
MAX_ROBOTS = 10_000
MAX_RESOURCES = 1_000_000
MAX_LINEAR_SPEED = 10.0
"""[m/s]: the papers' robots drive 0.05-0.34 m/s; faster is a typo (a 1e300 speed was accepted)."""
MAX_ANGULAR_SPEED = 100.0
"""[rad/s]."""
NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.+-]{0,99}")
"""A scenario's name: it names bag directories, so no path separators and no leading dot (a
``name: ../../x`` put the bag outside ``--out``)."""


def _require(condition: bool, message: str) -> None:
    if not condition:
        raise ScenarioError(message)


def _inside(point: tuple[float, float], half: float, clearance: float) -> bool:
    return abs(point[0]) + clearance <= half and abs(point[1]) + clearance <= half


def validate(s: Scenario) -> None:
    """Refuse impossible scenarios with a ScenarioError naming the key at fault: the generic world
    facts (`check_world`), then what the registry knows: every world section's own `check`, the
    delivery kind and the drop zones it implies, the kind's and the algorithm's checks
    (`swarm_sim.registry.check_scenario`)."""
    check_world(s)
    try:
        for _, section in s.sections:
            section.check()
        registry.delivery_kind(s.depot.delivery)
        names = [z.name for z in (*registry.delivery_zones(s), *s.drop_zones)]
        _require(len(set(names)) == len(names), "drop_zones: zone names must be unique ('depot' is taken)")
        registry.check_scenario(s)
    except ValueError as exc:  # a ScenarioError too: one type, one line, whoever raised it
        raise ScenarioError(str(exc)) from None


def check_world(s: Scenario) -> None:
    """The generic world facts: tick, arena, depot, robots and their start, sensors, resources,
    extra drop zones, obstacles, the shared controller settings."""
    _require(MIN_DT <= s.sim.dt <= MAX_DT, f"sim.dt: must be between {MIN_DT:g} and {MAX_DT:g} s")
    _require(1 <= s.sim.physics_substeps <= MAX_SUBSTEPS,
             f"sim.physics_substeps: must be between 1 and {MAX_SUBSTEPS}")
    _require(s.sim.duration >= s.sim.dt, "sim.duration: must be at least one tick (sim.dt)")
    _require(s.sim.duration <= MAX_DURATION, f"sim.duration: at most {MAX_DURATION:g} s of sim time")
    _require(0.0 <= s.sim.command_timeout <= MAX_DURATION, "sim.command_timeout: must be between 0 (never) and "
             f"{MAX_DURATION:g} s")
    _require(s.seed >= 0, "seed: must not be negative")
    _require(s.name == "" or NAME.fullmatch(s.name) is not None,
             f"name: {s.name[:40]!r} is not a plain name (letters, digits, _ . + -; it names the bag directory)")
    _require(s.arena.size > 0, "arena.size: must be positive")
    half = s.arena.size / 2
    _require(
        _inside(s.depot.center, half, s.depot.radius),
        f"depot: a disc of radius {s.depot.radius} m at {s.depot.center} is outside the arena",
    )
    r = s.robots
    _require(1 <= r.count <= MAX_ROBOTS, f"robots.count: need 1 to {MAX_ROBOTS} robots")
    _require(r.diameter > 0, "robots.diameter: must be positive")
    _require(0 < r.max_linear_speed <= MAX_LINEAR_SPEED,
             f"robots.max_linear_speed: must be positive and at most {MAX_LINEAR_SPEED:g} m/s")
    _require(0 < r.max_angular_speed <= MAX_ANGULAR_SPEED,
             f"robots.max_angular_speed: must be positive and at most {MAX_ANGULAR_SPEED:g} rad/s")
    _require(r.mass > 0, "robots.mass: must be positive")
    stg = r.stop_turn_go
    _require(stg.angle_tolerance > 0, "robots.stop_turn_go.angle_tolerance: must be positive")
    _require(stg.distance_tolerance > 0, "robots.stop_turn_go.distance_tolerance: must be positive")
    _require(stg.collision_step >= 0, "robots.stop_turn_go.collision_step: must not be negative")
    wt = r.wheel_turning
    _require(0 <= wt.no_turn_angle <= wt.soft_turn_angle <= wt.hard_turn_angle <= 180,
             "robots.wheel_turning: need 0 <= no_turn_angle <= soft_turn_angle <= hard_turn_angle <= 180 deg")
    _require(0 <= wt.go_straight_angle <= 180, "robots.wheel_turning.go_straight_angle: must be in [0, 180] deg")
    _require(wt.delta >= 0, "robots.wheel_turning.delta: must not be negative")
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
        room = depot_start_room(s)  # robot centres stay this close to the depot centre
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
    res = s.resources
    _require(0 <= res.count <= MAX_RESOURCES, f"resources.count: must be 0 to {MAX_RESOURCES}")
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
    for i, o in enumerate(s.obstacles):
        _require(min(o.size) > 0, f"obstacles[{i}].size: must be positive")
        _require(_inside(o.center, half, 0.0), f"obstacles[{i}].center: {o.center} is outside the arena")
    _require(s.controller.arrival_tolerance > 0, "controller.arrival_tolerance: must be positive")
    _require(r.radio_range > 0, "robots.radio_range: must be positive")
