"""The DRTM paper's registry records (drtm_task_allocation.md, Pang et al. 2023): its nest task,
DRTM and the ARTM baseline, both served by the nest, and the ARGoS foraging example's rule
(``foraging_example``), the rule of the DRTM reference run, on the same nest."""

from swarm_sim.registry import Algorithm, Measure, Metric, Panel, ServerSpec, TaskSpec, register, register_task

register_task(TaskSpec(
    name="nest",
    core="swarm_controllers.drtm.task:NestTask",
    sensing="swarm_controllers.drtm.sensing:SENSING",
    metrics="swarm_sim.analysis.metrics:foraging_metrics",
    extends="foraging",
    panels=(Panel("food tokens delivered, F_t", "F_t [tokens]", "swarm_sim.analysis.metrics:delivered_series",
                  integer=True),),
))

_SECTIONS = (("nest", "swarm_controllers.drtm.config:NestConfig"),
             ("threshold", "swarm_controllers.drtm.config:ThresholdConfig"))
_SERVER = ServerSpec(
    channel="nest", core="swarm_controllers.drtm.nest:NestServer", family="swarm_controllers.drtm.codec:NEST",
    outputs="swarm_controllers.drtm.codec:OUTPUTS",
)
_METRICS = tuple(
    Metric(name, f"swarm_controllers.drtm.metrics:{name}")
    for name in ("food_deviation", "energy_efficiency", "oae_total", "food_collected", "nest_food_final",
                 "nest_food_series", "active_robots_series", "oae_series", "oae_by_state", "oae_returning_total")
)

_HEADLINE = (Measure("food_deviation", "tokens", "V_f"), Measure("energy_efficiency", "%", "E_e", scale=100.0),
             Measure("oae_total", "events", "M_T"), Measure("oae_per_robot", "events/robot", "M_v"),
             Measure("food_collected", "tokens", "F_t"), Measure("nest_food_final", "tokens", "F(T)"))
"""The paper's V_f [tokens], E_e, M_T, M_v, F_t [tokens] and F(T) [tokens] (Sec. 3, eqs. (8)-(9))."""
_FIGURES = "swarm_controllers.drtm.figures"
_PANELS = (
    Panel("food in the nest, F(t)", "F(t) [tokens]", "nest_food", references=f"{_FIGURES}:desired_food"),
    Panel("robots foraging, N_r - N_W", "robots foraging [robots]", f"{_FIGURES}:foraging_robots", integer=True),
    Panel("obstacle-avoidance events so far, M_T(t)", "OAEs [events]", "nest_oaes", integer=True),
    Panel("obstacle-avoidance events per robot", "OAEs [events]", "oae_by_robot", integer=True),
)
"""Figs. 5-6 (food and robots foraging over time) and the OAE counts behind M_T and M_v."""

for _name, _class, _what in (("drtm", "DrtmBehaviour", "DRTM, eqs. (2)-(7)"),
                             ("artm", "ArtmBehaviour", "ARTM (Castello et al.), the baseline")):
    register(Algorithm(
        name=_name,
        authors_robot="footbot_foraging",  # the ARGoS foraging example's set-up (see swarm_sim.robots)
        paper=f"drtm_task_allocation.md (Pang et al. 2023) secs. 2-4: {_what}",
        behaviour=f"swarm_controllers.drtm.behaviour:{_class}",
        task="nest",
        config=_SECTIONS,
        checks=("swarm_controllers.drtm.config:check_nest",),
        servers=(_SERVER,),
        metrics=_METRICS,
        comparison="swarm_controllers.drtm.comparison:DRTM_COMPARISON",
        headline=_HEADLINE,
        panels=_PANELS,
        states=("waiting", "searching", "returning"),
        trace_status=True,
    ))

register(Algorithm(
    name="foraging_example",
    authors_robot="footbot_foraging",
    paper="drtm_task_allocation.md (Pang et al. 2023) sec. 3.1's set-up with the ARGoS foraging example's rule "
          "(ilpincy/argos3-examples, controllers/footbot_foraging; its social rule relayed by the nest): the DRTM "
          "reference run's rule, not the paper's",
    behaviour="swarm_controllers.drtm.foraging_example:ForagingExampleBehaviour",
    task="nest",
    config=(_SECTIONS[0], ("example", "swarm_controllers.drtm.config:ExampleRuleConfig")),
    checks=("swarm_controllers.drtm.config:check_nest", "swarm_controllers.drtm.config:check_example"),
    servers=(_SERVER,),
    metrics=_METRICS,
    headline=_HEADLINE,
    panels=_PANELS,
    states=("resting", "exploring", "returning"),
    trace_status=True,
))
