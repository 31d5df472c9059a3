"""The caging paper's factor group (`swarm_sim.factor_sweeps`, run by ``scripts/factors``): its
cells 2 and 3 (6 and 7 robots, 0.3 m object) on the Khepera III (0.298 m/s regulated, 6.73 rad/s,
planar) against the generic robot of caging.yaml (0.341 m/s, 7.7 rad/s, not planar; same 0.13 m
body), one factor changed at a time; the group ``cagingplan``: Table 2's five runs (cells 0, 2-5) on the
Khepera III under each reading of the planned path (`swarm_controllers.caging.plan`); and the group
``cagingdistance``: the same runs with every robot starting as far from the object as Table 2's paths
say the recruiter did (``transport.swarm_distance``), alone and with the shortest-path plan."""

from swarm_sim.factor_sweeps import Factor, FactorGroup

AUTHORS = ("--robot-model", "authors")

SWARM_DISTANCE = 2.8
"""[m] Table 2's reading of how far from the object the robots start (``transport.swarm_distance``,
whose docstring derives it): the least grid displacement of a 7-step shortest path there, 7 by 2 cells
of 0.5 m (3.64 m), less r + w/2 + sensor range + half a grid step (0.3 + 0.065 + 0.2 + 0.25 m) from
the detection landmark to the object's centre; test_start_distance recomputes it."""
DISTANCE = ("--set", f"transport.swarm_distance={SWARM_DISTANCE}")

GROUPS = (
    FactorGroup("caging", ("caging", "--cells", "2", "3"), "caging/results.jsonl", "2,3", (
        Factor("baseline", "the authors' robot (khepera3)", AUTHORS),
        Factor("motion_generic", "today's generic robot (0.341 m/s, 7.7 rad/s, not planar)",
               ("--robot-model", "generic")),
        Factor("planar_off", "planarity: the Khepera III left to tilt as the generic robot is (robots.planar=false)",
               (*AUTHORS, "--set", "robots.planar=false")),
        Factor("speed_0.341", "speed: the generic robot's 0.341 m/s on the Khepera III",
               (*AUTHORS, "--set", "robots.platform.max_linear_speed=0.341")),
    ),
        # The path error by the planned path's corners (not a robot factor: where the error comes
        # from). Ten seeds of cells 1 and 3 (steps 1 and 0.5 m), whatever --seeds says: the fit
        # needs plans of every shape.
        then=("swarm_controllers.caging.corners", "--cells", "1", "3", "--seeds", "10")),
    FactorGroup("cagingplan", ("caging", "--cells", "0", "2", "3", "4", "5"), "caging/results.jsonl", "0,2,3,4,5", (
        Factor("baseline", "the authors' robot; plan: T_r* reversed, then p_r*^0 (sec. 4's prose; the default)",
               AUTHORS),
        Factor("plan_search", "plan: T_r* reversed alone, ending at its first landmark (Alg. 6's loop, "
               "for j := n-1 -> 0: lambda := T_ij) (controller.caging.plan=search)",
               (*AUTHORS, "--set", "controller.caging.plan=search")),
        Factor("plan_shortest", "plan: a shortest 8-connected grid path between T_r*'s ends (sec. 5's "
               "'path minimum length' as the grid's shortest; Table 2's lengths are such 7-step paths) "
               "(controller.caging.plan=shortest)",
               (*AUTHORS, "--set", "controller.caging.plan=shortest")),
    )),
    FactorGroup("cagingdistance", ("caging", "--cells", "0", "2", "3", "4", "5"), "caging/results.jsonl",
                "0,2,3,4,5", (
        Factor("baseline", "the authors' robot; every robot starts anywhere in the landmark rectangle out of the "
               "object's sensor reach (Alg. 2's 'randomly'; the default)", AUTHORS),
        Factor(f"distance_{SWARM_DISTANCE:g}", f"every robot starts at least {SWARM_DISTANCE:g} m from the object's "
               "centre (Table 2's 7-step paths: the recruiter started >= 3.64 m from its detection landmark, that "
               f"landmark ~0.8 m from the object) (transport.swarm_distance={SWARM_DISTANCE:g})", (*AUTHORS, *DISTANCE)),
        Factor(f"distance_{SWARM_DISTANCE:g}_shortest", "both of Table 2's facts: the starts as distance_"
               f"{SWARM_DISTANCE:g} and the plan as cagingplan's plan_shortest (transport.swarm_distance="
               f"{SWARM_DISTANCE:g}, controller.caging.plan=shortest)",
               (*AUTHORS, *DISTANCE, "--set", "controller.caging.plan=shortest")),
    )),
)
