"""The caging paper's registry records (caging_transport.md, Cardoso, Nedjah & Mourelle): the
transport task (landmarks, the object: its ``transport`` world section) and the caging algorithm."""

from swarm_sim.registry import Algorithm, Measure, Metric, Panel, TaskSpec, register, register_task

register_task(TaskSpec(
    name="transport",
    core="swarm_controllers.caging.task:TransportTask",
    sensing="swarm_controllers.caging.sensing:SENSING",
    state="swarm_controllers.caging.sensing:STATE",
    bodies="swarm_controllers.caging.figures:bodies",
    world=(("transport", "swarm_controllers.caging.world_config:TransportConfig"),),
))

_NOT_REACHED = "not reached"
_HEADLINE = (
    Measure("search_time_s", "s", "search", missing=_NOT_REACHED),
    Measure("recruitment_time_s", "s", "recruitment", missing=_NOT_REACHED),
    Measure("transport_time_s", "s", "transport", missing=_NOT_REACHED),
    Measure("total_time_s", "s", "execution time", missing=_NOT_REACHED),
    Measure("object_delivered"),
    Measure("cage_held", missing=_NOT_REACHED),
    Measure("planned_path_m", "m", "path minimum length", missing=_NOT_REACHED),
    Measure("trajectory_error_m", "m", "error", missing=_NOT_REACHED),
    Measure("trajectory_error_pct", "%", "normalised error", missing=_NOT_REACHED),
    Measure("landmarks", symbol="Lambda"),
    Measure("cage_size", "robots", missing=_NOT_REACHED),
)
"""Sec. 5: the stage times, whether the object was delivered, the path error (Table 2)."""
_FIGURES = "swarm_controllers.caging.figures"
_STAGES = f"{_FIGURES}:stage_ends"
_PANELS = (
    Panel("the object's position", "position [m]", "object", legend=("x", "y"), marks=_STAGES),
    Panel("the object's path so far", "path length [m]", f"{_FIGURES}:object_path",
          references=f"{_FIGURES}:planned_length", marks=_STAGES),
    Panel("the object's distance from the planned path", "distance [m]", f"{_FIGURES}:path_deviation",
          marks=_STAGES, empty="the transport did not start in this run"),
)
"""The transport over time, the stages' ends marked (search, recruitment, transport)."""

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
        ("landmarks", "landmark_count"), ("cage_size", "cage_size"), ("object_delivered", "object_delivered"),
    )),
    figures="swarm_controllers.caging.figures:transport_figure",
    comparison="swarm_controllers.caging.comparison:CAGING_COMPARISON",
    headline=_HEADLINE,
    progress="swarm_controllers.caging.stages:progress",
    panels=_PANELS,
    backdrop=f"{_FIGURES}:landmark_grid",
    states=("search", "approach", "wait_summon", "to_cage", "summoning", "placed", "spin", "wait_oriented", "move",
            "wait_reached", "done"),  # `Phase` values, in the order of the protocol
))
