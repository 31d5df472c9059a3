"""The spiral paper's registry records (mdbsa_spiral_search.md, Lu & Luna 2023): DDSA, and
MDBSA with centralized (C) and distributed (D) delivery, both served by the center and both
declaring the ``regions`` world section; MDBSA-D's ``region_centers`` delivery kind."""

from swarm_sim.registry import Algorithm, DeliveryKind, Measure, Metric, Panel, ServerSpec, register, register_delivery

_SECTION = ("spiral", "swarm_controllers.spiral.config:SpiralConfig")
_CHECKS = ("swarm_controllers.spiral.config:check_spiral",)
_METRICS = tuple(Metric(name, f"swarm_controllers.spiral.metrics:{name}")
                 for name in ("resources_per_robot_per_min", "resources_per_robot_per_min_mean"))
_HEADLINE = (Measure("resources_per_robot", "resources", "collected per robot"),
             Measure("resources_per_robot_per_min_mean", "resources/min", "foraging rate per robot"),
             Measure("resources_collected_pct", "%"),
             Measure("collision_time_per_robot_s", "s", "collision time per robot"))
"""The spiral paper's measures (Figs. 6-10): resources per robot, their rate per minute (the
per-minute series itself is in the JSON), collision time per robot."""
_COMPARISON = "swarm_controllers.spiral.comparison:SPIRAL_COMPARISON"
_PANELS = (Panel("foraging rate per minute", "collected per robot [resources/min]",
                 "swarm_controllers.spiral.figures:rate_per_minute"),)
"""Figs. 7 and 9: resources collected per robot in each minute."""
_REGIONS = ("regions", "swarm_controllers.spiral.regions:RegionConfig")
_CENTER = ServerSpec(
    channel="center", core="swarm_controllers.spiral.center:CenterServer",
    family="swarm_controllers.spiral.codec:CENTER", outputs="swarm_controllers.spiral.codec:OUTPUTS",
)

register_delivery(DeliveryKind(
    name="region_centers",
    zones="swarm_controllers.spiral.regions:region_center_zones",
    resources_inside=True,
))

_AUTHORS_ROBOT = "footbot_cpfa"
"""MARSLab-UTRGV's spiral code drives the foot-bot with the CPFA lineage's BaseController."""

register(Algorithm(
    name="ddsa",
    authors_robot=_AUTHORS_ROBOT,
    paper="mdbsa_spiral_search.md sec. III (Lu & Luna 2023): DDSA",
    behaviour="swarm_controllers.spiral.ddsa:DdsaBehaviour",
    config=(_SECTION,),
    checks=_CHECKS,
    metrics=_METRICS,
    paths="swarm_controllers.spiral.ddsa:planned_paths",
    comparison=_COMPARISON,
    headline=_HEADLINE,
    panels=_PANELS,
    states=("SEARCHING", "RETURNING", "RESUMING", "DONE"),
))

for _name, _delivery in (("mdbsa_c", "depot"), ("mdbsa_d", "region_centers")):
    register(Algorithm(
        name=_name,
        authors_robot=_AUTHORS_ROBOT,
        paper=f"mdbsa_spiral_search.md sec. IV (Lu & Luna 2023): MDBSA-{_name[-1].upper()}",
        behaviour="swarm_controllers.spiral.mdbsa:MdbsaBehaviour",
        config=(_SECTION,),
        checks=_CHECKS,
        world=(_REGIONS,),
        servers=(_CENTER,),
        peers=("swarm_controllers.spiral.codec:WALKERS",),
        deliveries=(_delivery,),
        metrics=(Metric("regions", "swarm_controllers.spiral.center:region_count"), *_METRICS),
        paths="swarm_controllers.spiral.center:planned_paths",
        comparison=_COMPARISON,
        headline=(*_HEADLINE, Measure("regions", symbol="N_regions")),
        panels=_PANELS,
        backdrop="swarm_controllers.spiral.figures:regions",
        states=("TO_CENTER", "WAITING", "IDLE", "TRAVELING", "SEARCHING", "DELIVERING", "RESUMING"),
    ))
