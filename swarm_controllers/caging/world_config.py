"""The transport task's world facts (caging_transport.md sec. 3): the scenario's ``transport``
section, declared by the transport task's registry record (`swarm_controllers.caging.registration`):
the target object, the landmark grid and how far from the object the robots start."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import ClassVar

from swarm_sim.scenario.schema import WorldSection


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
class TransportConfig(WorldSection):
    """World facts of the transport task (`swarm_controllers.caging.task`)."""

    object: TargetObjectConfig = field(default_factory=TargetObjectConfig)
    landmarks: LandmarkConfig = field(default_factory=LandmarkConfig)
    swarm_distance: float = 0.0
    """The least distance [m] from the object's centre C_object to every robot's start p_i^0
    (Alg. 2 places both "randomly"; sec. 5 ties the recruitment and execution times to "the
    distance between the swarm and the object"). 0 (the default): no bound beyond the object's
    sensor reach, robots anywhere in the landmark rectangle.

    A value from Table 2 (`swarm_controllers.caging.factors.SWARM_DISTANCE`): its path lengths are
    shortest 8-connected paths of 7 grid steps, 2, 4 or 6 of them diagonal, between landmarks 7
    cells apart along one axis and 2, 4 or 6 along the other: (3.5, 1), (3.5, 2), (3.5, 3) m, at
    least 3.64 m in a straight line. Sec. 4 ends that path at the recruiter's start p_r*^0, so the
    start is read as its far end. Its near end, the detection landmark, is the last landmark the
    recruiter reached before its sensors saw the object on the way to the next one: its centre
    was then within r + w/2 + sensor range of C_object (0.565 m for r = 0.3 m), about half a grid
    step (0.25 m) past that landmark. So the recruiter started about 3.64 - 0.815 = 2.8 m or more
    from C_object (the least over the five runs: the others span 4.03-4.61 m)."""

    SECTION: ClassVar[str] = "transport"

    def check(self) -> None:
        for ok, message in (
            (self.object.radius > 0, "transport.object.radius: must be positive"),
            (self.object.mass > 0, "transport.object.mass: must be positive"),
            (self.object.floor_friction >= 0, "transport.object.floor_friction: must not be negative"),
            (self.landmarks.step > 0, "transport.landmarks.step: must be positive"),
            (min(self.landmarks.extent) >= 0, "transport.landmarks.extent: must not be negative"),
            (self.swarm_distance >= 0, "transport.swarm_distance: must not be negative"),
        ):
            if not ok:
                raise ValueError(message)
        width, height = self.landmarks.extent
        if self.swarm_distance >= math.hypot(width, height) / 2:
            raise ValueError(
                f"transport.swarm_distance: {self.swarm_distance:g} m from an object at the centre of the "
                f"{width:g} x {height:g} m landmark rectangle leaves no start in it (its corners are "
                f"{math.hypot(width, height) / 2:.2f} m away)")
