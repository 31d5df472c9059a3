"""The shared core's registry records, loaded through the ``swarmforage.algorithms`` entry point
like every paper's: the foraging task (resources, drop zones, pick-up and delivery), the world
logic that most algorithms run in, and the ``depot`` delivery kind (anywhere in the depot disc)."""

from swarm_sim.registry import DeliveryKind, Measure, Panel, TaskSpec, register_delivery, register_task

DELIVERIES = Panel("resources delivered", "resources delivered [resources]",
                   "swarm_sim.analysis.metrics:delivered_series", integer=True)

register_task(TaskSpec(
    name="foraging",
    core="swarm_sim.world.tasks.foraging:ForagingTask",
    sensing="swarm_sim.world.tasks.foraging_sensing:SENSING",
    metrics="swarm_sim.analysis.metrics:foraging_metrics",
    headline=(Measure("resources_delivered", "resources"), Measure("total_resources", "resources")),
    panels=(DELIVERIES,
            Panel("collision time per robot", "collision time [s]", "collision_time_s_by_robot"),
            Panel("trips per robot", "resources delivered [resources]", "trips_by_robot", integer=True)),
))

register_delivery(DeliveryKind(name="depot", zones="swarm_sim.sites:depot_zones"))
