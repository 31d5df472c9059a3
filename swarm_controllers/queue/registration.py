"""The queue paper's registry records (queue_depot_traffic.md): the perimeter probe, the ``docks``
delivery kind (its docks in `depot_manager.docks`, its world section ``docking``, its runs
measured by the perimeter probe), the ``perimeter_depot`` kind of its CPFA baseline and the queue
strategies, the robots' side here, the depot
manager's server in the top-level `depot_manager` package."""

from swarm_controllers.cpfa.registration import HEADLINE, PHEROMONES, STATES
from swarm_controllers.cpfa.registration import SECTION as CPFA_SECTION
from swarm_sim.registry import (
    Algorithm,
    DeliveryKind,
    Measure,
    Metric,
    Panel,
    Probe,
    ServerSpec,
    register,
    register_delivery,
    register_probe,
)

register_probe(Probe(
    name="perimeter",
    observer="swarm_controllers.queue.perimeter:PerimeterLog",
    metrics="swarm_controllers.queue.perimeter:perimeter_metrics",
    details=(("dropoff_times_s", "dropoff_count"),),
))

register_delivery(DeliveryKind(
    name="docks",
    zones="depot_manager.docks:dock_zones",
    checks=("depot_manager.docks:check_docks",),
    world=(("docking", "depot_manager.config:DockingConfig"),),
    probes=("perimeter",),  # the queue strategies (and the text's reading of the CPFA baseline) deliver here
))

register_delivery(DeliveryKind(
    name="perimeter_depot",
    zones="swarm_sim.sites:depot_zones",
    checks=("depot_manager.docks:check_perimeter",),
    world=(("docking", "depot_manager.config:DockingConfig"),),
    probes=("perimeter",),  # the CPFA baseline (queue_cpfa.yaml): the authors' one nest, the paper's perimeter
))

register(Algorithm(
    name="queue",
    authors_robot="footbot_cpfa",  # Tameem786/ and Artglz/Collision_Free_CPFA
    paper="queue_depot_traffic.md secs. III-V: Q_SE, Q_ST, Q_ME, Q_MT",
    behaviour="swarm_controllers.queue.behaviour:QueueBehaviour",
    config=(CPFA_SECTION, ("queue", "depot_manager.config:QueueConfig")),
    checks=("depot_manager.geometry:check_queue",),
    servers=(ServerSpec(
        channel="depot", core="depot_manager.server:DepotServer", family="depot_manager.codec:DEPOT",
        outputs="depot_manager.codec:OUTPUTS", name="depot_manager",
    ),),
    peers=(PHEROMONES, "depot_manager.codec:RADIO"),
    deliveries=("docks",),
    metrics=(
        Metric("queue_length_mean", "depot_manager.metrics:queue_length_mean"),
        Metric("queue_length_max", "depot_manager.metrics:queue_length_max"),
        Metric("authors_collision_time_per_robot_s",
               "swarm_controllers.queue.authors_count:authors_collision_time_per_robot_s"),
        Metric("authors_collision_time_total_min",
               "swarm_controllers.queue.authors_count:authors_collision_time_total_min"),
    ),
    collision_rule="swarm_controllers.queue.authors_count:collision_rule",
    comparison="swarm_controllers.queue.comparison:QUEUE_COMPARISON",
    headline=(*HEADLINE, Measure("perimeter_delay_mean_s", "s", "time delay"),
              Measure("queue_length_mean", "robots"), Measure("queue_length_max", "robots")),
    panels=(Panel("robots queued on each entry line", "robots queued [robots]", "queue_lengths",
                  legend=("entry line {i}",), integer=True),),
    backdrop="swarm_controllers.queue.figures:layout",
    states=(*STATES, "TO_ENTRY", "SEEKING", "JOINING", "QUEUED", "LEAVING"),
    # foraging: the CPFA's states; at the depot: its `Phase` names
))
