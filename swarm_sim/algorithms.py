"""The shipped algorithms and world tasks: one registry record each (`swarm_sim.registry`).

Adding an algorithm means adding its own modules and one `register` call here (or in a plug-in
module named by ``SWARMFORAGE_PLUGINS``); nothing else in the tree lists algorithms.
"""

from swarm_sim.registry import Algorithm, Metric, ServerSpec, TaskSpec, register, register_task

register_task(TaskSpec(
    name="foraging",
    core="swarm_sim.world.tasks.foraging:ForagingTask",
    sensing="swarm_msgs_py.foraging:SENSING",
    metrics="swarm_sim.analysis.metrics:foraging_metrics",
))

_CPFA_SECTION = ("cpfa", "swarm_controllers.config:CpfaConfig")
_SPIRAL_SECTION = ("spiral", "swarm_controllers.config:SpiralConfig")
_SPIRAL_METRICS = (Metric("resources_per_robot_per_min",
                          "swarm_controllers.spiral_metrics:resources_per_robot_per_min", None),)
_CENTER = ServerSpec(
    channel="center", core="swarm_controllers.center:CenterServer",
    node="swarm_controllers.center_node", script="swarm-center",
    family="swarm_msgs_py.center_protocol:CENTER",
)

register(Algorithm(
    name="cpfa",
    paper="Hecker & Moses 2015 (Beyond pheromones); the queue paper's baseline (queue_depot_traffic.md sec. VII)",
    behaviour="swarm_controllers.cpfa:CpfaBehaviour",
    config=(_CPFA_SECTION,),
    peers=("swarm_msgs_py.pheromone:PHEROMONES",),
    deliveries=("depot", "docks"),
    comparison="swarm_sim.compare.queue_paper:QUEUE_COMPARISON",
))

register(Algorithm(
    name="queue",
    paper="queue_depot_traffic.md secs. III-V: Q_SE, Q_ST, Q_ME, Q_MT",
    behaviour="swarm_controllers.queueing:QueueBehaviour",
    config=(_CPFA_SECTION, ("queue", "depot_manager.config:QueueConfig")),
    checks=("depot_manager.config:check_queue",),
    servers=(ServerSpec(
        channel="depot", core="depot_manager.server:DepotServer", node="depot_manager.node",
        script="swarm-depot-manager", family="swarm_msgs_py.depot_protocol:DEPOT",
        replay="swarm_msgs_py.server_state:replay_depot_state",
    ),),
    peers=("swarm_msgs_py.pheromone:PHEROMONES", "swarm_msgs_py.depot_protocol:RADIO"),
    deliveries=("docks",),
    metrics=(
        Metric("queue_length_mean", "depot_manager.metrics:queue_length_mean", 0.0),
        Metric("queue_length_max", "depot_manager.metrics:queue_length_max", 0),
    ),
    comparison="swarm_sim.compare.queue_paper:QUEUE_COMPARISON",
))

register(Algorithm(
    name="ddsa",
    paper="mdbsa_spiral_search.md sec. III (Lu & Luna 2023): DDSA",
    behaviour="swarm_controllers.ddsa:DdsaBehaviour",
    config=(_SPIRAL_SECTION,),
    checks=("swarm_controllers.config:check_spiral",),
    metrics=_SPIRAL_METRICS,
    paths="swarm_controllers.ddsa:planned_paths",
    comparison="swarm_sim.compare.spiral_paper:SPIRAL_COMPARISON",
))

for _name, _delivery in (("mdbsa_c", "depot"), ("mdbsa_d", "region_centers")):
    register(Algorithm(
        name=_name,
        paper=f"mdbsa_spiral_search.md sec. IV (Lu & Luna 2023): MDBSA-{_name[-1].upper()}",
        behaviour="swarm_controllers.mdbsa:MdbsaBehaviour",
        config=(_SPIRAL_SECTION,),
        checks=("swarm_controllers.config:check_spiral",),
        servers=(_CENTER,),
        deliveries=(_delivery,),
        metrics=(Metric("regions", "swarm_controllers.center:region_count", None), *_SPIRAL_METRICS),
        paths="swarm_controllers.center:planned_paths",
        comparison="swarm_sim.compare.spiral_paper:SPIRAL_COMPARISON",
    ))

register_task(TaskSpec(
    name="nest",
    core="swarm_sim.world.tasks.nest:NestTask",
    sensing="swarm_msgs_py.nest:SENSING",
    metrics="swarm_sim.analysis.metrics:foraging_metrics",
))

_NEST_SECTIONS = (("nest", "swarm_controllers.nest_config:NestConfig"),
                  ("threshold", "swarm_controllers.nest_config:ThresholdConfig"))
_NEST_SERVER = ServerSpec(
    channel="nest", core="swarm_controllers.nest:NestServer", node="swarm_controllers.nest_node",
    script="swarm-nest", family="swarm_msgs_py.nest_protocol:NEST",
    replay="swarm_controllers.nest:replay_nest_state",
)
_NEST_METRICS = tuple(
    Metric(name, f"swarm_controllers.nest_metrics:{function}", None)
    for name, function in (
        ("food_deviation", "food_deviation"), ("energy_efficiency", "energy_efficiency"),
        ("oae_total", "oae_total"), ("food_collected", "food_collected"),
        ("nest_food_final", "nest_food_final"), ("nest_food_series", "nest_food_series"),
        ("active_robots_series", "active_robots_series"), ("oae_series", "oae_series"),
    )
)

for _name, _class, _what in (("drtm", "DrtmBehaviour", "DRTM, eqs. (2)-(7)"),
                             ("artm", "ArtmBehaviour", "ARTM (Castello et al.), the baseline")):
    register(Algorithm(
        name=_name,
        paper=f"drtm_task_allocation.md (Pang et al. 2023) secs. 2-4: {_what}",
        behaviour=f"swarm_controllers.drtm:{_class}",
        task="nest",
        config=_NEST_SECTIONS,
        checks=("swarm_controllers.nest_config:check_nest",),
        servers=(_NEST_SERVER,),
        metrics=_NEST_METRICS,
        comparison="swarm_sim.compare.drtm_paper:DRTM_COMPARISON",
    ))

register_task(TaskSpec(
    name="transport",
    core="swarm_sim.world.tasks.transport:TransportTask",
    sensing="swarm_msgs_py.transport:SENSING",
    state="swarm_msgs_py.transport:STATE",
))

register(Algorithm(
    name="caging",
    paper="caging_transport.md (Cardoso, Nedjah & Mourelle): Algs. 1-6, eqs. (1), (2), (5)",
    behaviour="swarm_controllers.caging.behaviour:CagingBehaviour",
    task="transport",
    config=(("caging", "swarm_controllers.caging.config:CagingConfig"),),
    checks=("swarm_controllers.caging.config:check_caging",),
    peers=("swarm_msgs_py.caging_protocol:CAGING",),
    trace_peers=True,
    metrics=tuple(Metric(name, f"swarm_controllers.caging.metrics:{function}") for name, function in (
        ("search_time_s", "search_time_s"), ("recruitment_time_s", "recruitment_time_s"),
        ("transport_time_s", "transport_time_s"), ("total_time_s", "total_time_s"),
        ("planned_path_m", "planned_path_m"), ("object_path_m", "object_path_m"),
        ("trajectory_error_m", "trajectory_error_m"), ("trajectory_error_pct", "trajectory_error_pct"),
        ("cage_held", "cage_held"), ("max_path_deviation_m", "max_path_deviation_m"),
        ("landmarks", "landmark_count"), ("cage_size", "cage_size"),
    )),
    figures="swarm_controllers.caging.figures:transport_figure",
    comparison="swarm_sim.compare.caging_paper:CAGING_COMPARISON",
))
