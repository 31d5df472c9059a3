"""``controller.caging``: the caging paper's parameters (Table 1) and the few it leaves open."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, ClassVar, Literal

from swarm_controllers.caging.geometry import cage_radius, max_robots, rho_min, theta_min
from swarm_controllers.caging.world_config import TransportConfig
from swarm_sim.scenario.schema import Section

if TYPE_CHECKING:
    from swarm_sim.scenario import Scenario


@dataclass(frozen=True)
class PidGains:
    kp: float
    ki: float
    kd: float


@dataclass(frozen=True)
class CagingConfig(Section):
    """Table 1 of the caging paper (PID gains, d, sigma, c, Delta) plus what it does not give.

    The PIDs' inputs are errors in metres or radians; their outputs are speeds [m/s] (distance
    PIDs, and the angle PIDs theta_ell, theta_r, which move a robot along the cage) or turn
    rates [rad/s] (the heading PID alpha_p).
    """

    heading: PidGains = field(default_factory=lambda: PidGains(1.0, 0.01, 0.01))
    """alpha_p: the robot's heading error toward where it goes."""
    distance: PidGains = field(default_factory=lambda: PidGains(1.0, 0.01, 0.01))
    """D_lambda (and D_object, D* while approaching): distance to the target."""
    neighbour_distance: PidGains = field(default_factory=lambda: PidGains(0.3, 0.01, 0.1))
    """D_ell, D_r: distance to the left and right neighbours in the cage."""
    neighbour_angle: PidGains = field(default_factory=lambda: PidGains(0.3, 0.01, 0.1))
    """theta_ell, theta_r: angle around the object between the robot and each neighbour."""
    object_distance: PidGains = field(default_factory=lambda: PidGains(1.0, 0.01, 0.1))
    """D_object during transport: distance to the object's centre."""
    distance_tolerance: float = 0.05
    """d [m]: a target is reached within d; transport keeps distances within +-d."""
    angle_tolerance: float = 3.0
    """sigma [deg]: heading and neighbour-angle tolerance."""
    clearance: float = 0.01
    """c [m] of eq. (5): cage positions are r + w + c from the object's centre."""
    approach_margin: float = 0.6
    """Recruited robots wait at Delta = r + w/2 + approach_margin [m] from the object."""
    min_gap: float = 0.01
    """epsilon [m] of eq. (2), the least space between adjacent robots; the paper gives no value."""
    acceleration_ratio: float = 1.0
    """A / a of eq. (1): the object's acceleration over the robots'. The paper gives neither; the
    cage moves as one, so 1."""
    plan: Literal["search_to_start", "search", "shortest"] = "search_to_start"
    """The transport's planned path from T_r* (`swarm_controllers.caging.plan`): T_r* reversed then
    p_r*^0 (sec. 4's prose), T_r* reversed alone (Alg. 6's loop), or a shortest 8-connected grid
    path between T_r*'s two ends (sec. 5's "path minimum length" read as the grid's shortest)."""
    call_timeout: float = 120.0
    """Beyond the paper: the recruiter calls the next robot of mu if the one it summoned has not
    answered with a type-2 message within this many sim seconds (a dead robot)."""
    barrier_timeout: float = 120.0
    """Beyond the paper: a robot waiting for everyone's type-3 or type-4 message of a landmark
    goes on without the robots still silent after this many sim seconds, and stops waiting for
    them."""

    SECTION: ClassVar[str] = "caging"


def check_caging(scenario: Scenario) -> None:
    """Refuse a caging scenario the paper's conditions rule out, with the numbers: fewer robots
    than rho_min (eq. 1), more than the cage fits (phi = 360 deg / rho < theta_min, eq. 2), a
    landmark grid whose edge cages would hit the walls, sensors that cannot see what they must."""
    cfg = CagingConfig.of(scenario)
    for key in ("distance_tolerance", "angle_tolerance", "clearance", "approach_margin", "min_gap",
                "acceleration_ratio", "call_timeout", "barrier_timeout"):
        if not getattr(cfg, key) > 0:
            raise ValueError(f"controller.caging.{key}: must be positive")
    obj, robots = TransportConfig.of(scenario).object, scenario.robots
    rho = robots.count
    need = rho_min(obj.mass, robots.mass, cfg.acceleration_ratio)
    if rho < math.ceil(need - 1e-9):
        raise ValueError(f"robots.count: {rho} robots cannot move the object: eq. (1) needs rho_min = "
                         f"M A / (m a) = {obj.mass} x {cfg.acceleration_ratio:g} / {robots.mass} = {need:.3f}")
    most = max_robots(robots.diameter, obj.radius, cfg.min_gap)
    if rho > most:
        raise ValueError(
            f"robots.count: {rho} robots do not fit around the object: phi = 360/{rho} = {360 / rho:.2f} deg "
            f"< theta_min = {math.degrees(theta_min(robots.diameter, obj.radius, cfg.min_gap)):.2f} deg "
            f"(eq. 2; at most {most} robots)")
    half = scenario.arena.size / 2
    reach = cage_radius(obj.radius, robots.diameter, cfg.clearance) + robots.diameter / 2
    extent = TransportConfig.of(scenario).landmarks.extent
    if max(extent) / 2 + reach > half:
        raise ValueError(f"transport.landmarks.extent: a cage around an edge landmark of the {list(extent)} m "
                         f"grid reaches {max(extent) / 2 + reach:.2f} m from the centre, past the walls at {half} m")
    seen = obj.radius + robots.diameter / 2 + scenario.sensors.proximity.range
    if scenario.sensors.position_range < seen:
        raise ValueError(f"sensors.position_range: {scenario.sensors.position_range} m is less than "
                         f"{seen:.3f} m, so a robot could detect the object without knowing where it is")
