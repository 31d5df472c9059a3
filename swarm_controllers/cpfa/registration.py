"""The CPFA's registry record (Hecker & Moses 2015), loaded through the ``swarmforage.algorithms``
entry point: the queue paper's baseline, and the search its queue strategies build on."""

from swarm_sim.registry import Algorithm, Measure, register, register_default_scenario

SECTION = ("cpfa", "swarm_controllers.cpfa.config:CpfaConfig")
"""``controller.cpfa``: also declared by the algorithms that search as the CPFA does."""
PHEROMONES = "swarm_controllers.cpfa.codec:PHEROMONES"
HEADLINE = (Measure("resources_collected_pct", "%", "resource collection"),
            Measure("collision_time_total_min", "min", "collision time, all robots"),
            Measure("collision_time_per_robot_s", "s", "collision time per robot"),
            Measure("dropoff_time_mean_s", "s", "resource drop-off time"))
"""The queue paper's three metrics (sec. VII: resources collected; the cumulative collision time
in minutes, and per robot as its Fig. 9; the drop-off time), which it reports for the CPFA too."""
STATES = ("DEPARTING", "SEARCHING", "RETURNING")
"""What a CPFA robot's status says (`CpfaState` names)."""

register(Algorithm(
    name="cpfa",
    authors_robot="footbot_cpfa",  # CPFA-ARGoS's BaseController on the foot-bot (the queue paper's baseline)
    paper="Hecker & Moses 2015 (Beyond pheromones); the queue paper's baseline (queue_depot_traffic.md sec. VII)",
    behaviour="swarm_controllers.cpfa.behaviour:CpfaBehaviour",
    config=(SECTION,),
    peers=(PHEROMONES,),
    deliveries=("depot", "docks", "perimeter_depot"),
    comparison="swarm_controllers.queue.comparison:QUEUE_COMPARISON",
    headline=HEADLINE,
    states=STATES,
))

register_default_scenario("cpfa")  # what scripts/run and every command run unless told otherwise
