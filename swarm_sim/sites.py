"""Sites: where the scenario's world facts put the drop zones.

The zones ``depot.delivery`` implies come from its registered delivery kind
(`swarm_sim.registry.DeliveryKind`): the depot disc from the shared core (`depot_zones`), the
others from the papers that provide them. The world's foraging task, the metrics, the views and
the behaviours take their drop zones from here, so each is computed in one place.
"""

from __future__ import annotations

from swarm_sim import registry
from swarm_sim.scenario.schema import DropZoneConfig, Scenario


def depot_zones(scenario: Scenario) -> tuple[DropZoneConfig, ...]:
    """The ``depot`` delivery kind's one zone: anywhere in the depot disc, no dwell."""
    d = scenario.depot
    return (DropZoneConfig("depot", d.center, d.radius, 0.0, "depot"),)


def drop_zones(scenario: Scenario) -> tuple[DropZoneConfig, ...]:
    """Every zone the world drops resources in: the ones ``depot.delivery`` implies, then the
    scenario's own ``drop_zones``."""
    return (*registry.delivery_zones(scenario), *scenario.drop_zones)


def zones_clear_of_resources(scenario: Scenario) -> tuple[DropZoneConfig, ...]:
    """The drop zones resources are placed clear of (`swarm_sim.world.resources`): every one but
    those of a delivery kind that lets resources lie inside its zones
    (`swarm_sim.registry.DeliveryKind.resources_inside`)."""
    if registry.delivery_kind(scenario.depot.delivery).resources_inside:
        return scenario.drop_zones
    return drop_zones(scenario)
