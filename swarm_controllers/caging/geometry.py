"""The caging paper's geometry: eqs. (1), (2) and (5), Delta, and the way to a cage position.

Plain `math` (these run for every robot every tick).
"""

from __future__ import annotations

import math

Point = tuple[float, float]


def rho_min(object_mass: float, robot_mass: float, acceleration_ratio: float = 1.0) -> float:
    """Eq. (1): rho_min = M A / (m a), the least number of robots that can move the object
    (`acceleration_ratio` = A / a)."""
    return object_mass * acceleration_ratio / robot_mass


def theta_min(width: float, radius: float, min_gap: float) -> float:
    """Eq. (2) [rad]: the least angle, seen from the object's centre, between two adjacent robots
    of width w touching an object of radius r with at least epsilon between them.

    The paper prints arctan(theta_min / 2) = (w/2 + eps/2) / sqrt((w/2 + r)^2 - (w/2 + eps/2)^2);
    its right-hand side is the tangent of the half angle (opposite over adjacent side of the
    right triangle the robot's half width makes), so theta_min = 2 arctan(right-hand side).
    """
    half = width / 2 + min_gap / 2
    return 2.0 * math.atan(half / math.sqrt((width / 2 + radius) ** 2 - half**2))


def max_robots(width: float, radius: float, min_gap: float) -> int:
    """The most robots a cage holds: phi = 360 deg / rho must stay >= theta_min."""
    return int(math.floor(2.0 * math.pi / theta_min(width, radius, min_gap) + 1e-9))


def cage_angle(rho: int) -> float:
    """phi = 360 deg / rho [rad]: the angle between adjacent cage positions."""
    return 2.0 * math.pi / rho


def cage_radius(radius: float, width: float, clearance: float) -> float:
    """(r + w) + c: how far eq. (5) puts a robot's centre from the object's centre [m]."""
    return radius + width + clearance


def cage_position(center: Point, i: int, rho: int, radius: float, width: float, clearance: float) -> Point:
    """Eq. (5): robot i's place in the cage around `center` [m, world frame], at angle i phi."""
    a = i * cage_angle(rho)
    R = cage_radius(radius, width, clearance)
    return (center[0] + R * math.cos(a), center[1] + R * math.sin(a))


def approach_distance(radius: float, width: float, margin: float) -> float:
    """Delta = r + w/2 + 0.6 m (Table 1): where recruited robots wait to be summoned [m]."""
    return radius + width / 2 + margin


def travel_radius(radius: float, width: float, clearance: float) -> float:
    """The ring a robot follows around the object to reach its cage position [m]: one and a
    half robot widths outside the cage, so it passes robots already placed (a robot width
    inside) and robots waiting at Delta (well outside) without touching them."""
    return cage_radius(radius, width, clearance) + 1.5 * width


MAX_ARC = math.pi / 6
"""Largest angle between waypoints on the travel ring [rad] (chords stay near the ring)."""


def cage_route(position: Point, center: Point, slot_angle: float, ring: float, max_arc: float = MAX_ARC) -> list[Point]:
    """Waypoints from `position` to the cage position at `slot_angle` around `center`.

    The paper moves a robot straight to its cage position, which would run it through the
    object when that position lies across it. Ours: radially to the travel ring, along the ring
    the shorter way in steps of at most `max_arc`, and (the caller's last waypoint) radially in
    to the cage position. Returns the ring waypoints only.
    """
    a0 = math.atan2(position[1] - center[1], position[0] - center[0])
    delta = math.remainder(slot_angle - a0, 2.0 * math.pi)
    steps = max(1, math.ceil(abs(delta) / max_arc - 1e-9))
    return [(center[0] + ring * math.cos(a0 + delta * k / steps), center[1] + ring * math.sin(a0 + delta * k / steps))
            for k in range(steps + 1)]
