"""The shared core's one registry record, loaded through the ``swarmforage.algorithms`` entry
point like every paper's: the foraging task (resources, drop zones, pick-up and delivery), the
world logic that most algorithms run in."""

from swarm_sim.registry import Measure, TaskSpec, register_task

register_task(TaskSpec(
    name="foraging",
    core="swarm_sim.world.tasks.foraging:ForagingTask",
    sensing="swarm_msgs_py.foraging:SENSING",
    metrics="swarm_sim.analysis.metrics:foraging_metrics",
    headline=(Measure("resources_delivered"), Measure("total_resources")),
))
