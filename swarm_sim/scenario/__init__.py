"""The scenario: the one place where every world fact and every parameter lives.

- `schema`: the generic world facts (sim, arena, robots, sensors, resources, depot, drop zones,
  obstacles) and the controller as frozen dataclasses, and the bases of the sections tasks and
  algorithms declare (`WorldSection` at the top level, `Section` under ``controller``);
- `loading`: YAML, overrides, building the dataclasses (declared sections included),
  `load_scenario`, `resolve_path`, the plain-data form of bag metadata;
- `validation`: impossible values and geometry refused, naming the key.

Layers: the schema imports nothing of the project; `swarm_sim.registry` imports the schema for
annotations only; validation and loading import the registry. The names other modules use are
re-exported here.
"""

from swarm_sim.scenario.loading import (
    load_scenario,
    parse_override,
    read_yaml,
    resolve_path,
    scenario_from_dict,
    scenario_to_dict,
)
from swarm_sim.scenario.schema import (
    ArenaConfig,
    AvoidanceConfig,
    ControllerConfig,
    DepotConfig,
    DropZoneConfig,
    NoiseConfig,
    ObstacleConfig,
    ProximityConfig,
    ProximityRingConfig,
    ResourceConfig,
    RobotConfig,
    ScanConfig,
    Scenario,
    ScenarioError,
    Section,
    SensorConfig,
    SimConfig,
    WorldSection,
)
from swarm_sim.scenario.validation import validate

__all__ = [
    "ArenaConfig",
    "AvoidanceConfig",
    "ControllerConfig",
    "DepotConfig",
    "DropZoneConfig",
    "NoiseConfig",
    "ObstacleConfig",
    "ProximityConfig",
    "ProximityRingConfig",
    "ResourceConfig",
    "RobotConfig",
    "ScanConfig",
    "Scenario",
    "ScenarioError",
    "Section",
    "SensorConfig",
    "SimConfig",
    "WorldSection",
    "load_scenario",
    "parse_override",
    "read_yaml",
    "resolve_path",
    "scenario_from_dict",
    "scenario_to_dict",
    "validate",
]
