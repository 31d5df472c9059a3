"""The caging paper's registry records (caging_transport.md, Cardoso, Nedjah & Mourelle): the
transport task (landmarks, the object: its ``transport`` world section) and the caging algorithm."""

from swarm_sim.registry import Algorithm, Measure, Metric, TaskSpec, register, register_task

register_task(TaskSpec(
    name="transport",
    core="swarm_controllers.caging.task:TransportTask",
    sensing="swarm_controllers.caging.sensing:SENSING",
    state="swarm_controllers.caging.sensing:STATE",
    world=(("transport", "swarm_controllers.caging.world_config:TransportConfig"),),
))

register(Algorithm(
    name="caging",
    authors_robot="khepera3",  # the paper's CoppeliaSim Khepera III
    paper="caging_transport.md (Cardoso, Nedjah & Mourelle): Algs. 1-6, eqs. (1), (2), (5)",
    behaviour="swarm_controllers.caging.behaviour:CagingBehaviour",
    task="transport",
    config=(("caging", "swarm_controllers.caging.config:CagingConfig"),),
    checks=("swarm_controllers.caging.config:check_caging",),
    peers=("swarm_controllers.caging.codec:CAGING",),
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
    comparison="swarm_controllers.caging.comparison:CAGING_COMPARISON",
    headline=(Measure("search_time_s", "s"), Measure("recruitment_time_s", "s"), Measure("transport_time_s", "s"),
              Measure("total_time_s", "s"), Measure("cage_held"), Measure("trajectory_error_pct", "%"),
              Measure("landmarks"), Measure("cage_size")),
))
