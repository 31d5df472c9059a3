"""The spiral paper's factor groups (`swarm_sim.factor_sweeps`, run by ``scripts/factors``): its
experiments 1 and 2, the authors' robot against one factor changed at a time.

The committed spiral1 and spiral2 runs were made before the spiral scenarios took the authors'
cone, region order and DDSA turn (2026-11-27): their baseline is our earlier rules (-37.5..37.5
deg, row-major, clockwise), and cone_80, regions_nearest and ddsa_turn_away each move one of them
to the authors'. Run from scratch today, the baseline is the authors' rules and those three equal
it."""

from swarm_sim.factor_sweeps import Factor, FactorGroup

AUTHORS = ("--robot-model", "authors")
MDBSA = ("--strategies", "mdbsa_c", "mdbsa_d", *AUTHORS)
BASELINE = Factor("baseline", "the authors' robot (footbot_cpfa, the spiral authors' tolerances)", AUTHORS)
# The MDBSA authors' BaseController fires (and counts) a collision within -80..80 deg
# (MARSLab-UTRGV/Adaptive-Multiple-Distributed-Spiral-Search-Algorithm, luki-dev,
# {Centralized,Distributed}/source/Base/BaseController.cpp:38); their DDSA's within -37.5..37.5
# (DDSA repository, luki-dev, source/Base/BaseController.cpp:37), which our three spiral scenarios
# all use. MDBSA-C and MDBSA-D only, DDSA as in the baseline.
CONE = Factor("cone_80", "MDBSA's collision cone: -80..80 deg (the MDBSA authors' BaseController) instead of the "
              "DDSA's -37.5..37.5; DDSA unchanged (baseline)", (*MDBSA, "--set", "sensors.proximity_ring.ahead=80"))
# The MDBSA authors' calRegions hands regions out nearest the nest first (regions.order).
REGIONS = Factor("regions_nearest", "MDBSA's region order: nearest the nest first (the authors' calRegions) instead "
                 "of row-major; DDSA unchanged (baseline)", (*MDBSA, "--set", "regions.order=nearest_first"))
DDSA_TURN = Factor("ddsa_turn_away", "DDSA's collision turn: away from the readings by 37.5 deg more, always turning "
                   "(the DDSA authors' BaseController) instead of the MDBSA/CPFA clockwise turn; MDBSA unchanged "
                   "(baseline)",
                   ("--strategies", "ddsa", *AUTHORS, "--set", "robots.stop_turn_go.collision_turn=away"))
START = Factor("start_0.2", "start grid: 0.2 m apart (the authors' ARGoS distribute grids, luki-dev "
               "experiments/*.xml) instead of 0.4 m; the authors' rules (run after the 2026-11-27 defaults)",
               (*AUTHORS, "--set", "robots.start_spacing=0.2"))
# Issue 37's bisection of our DDSA against the authors' run here (it collects 13-64 % more at 8-32 robots):
# our lane rule (yield to a robot in the lane ahead, issue 4) off, so every robot avoids by the model's
# avoidance alone, as the authors' BaseController does.
LANE_YIELD = Factor("lane_yield_off", "the lane rule off: every state avoids by the robot model's avoidance alone "
                    "(the authors' BaseController::CollisionDetection, no yielding) instead of yielding to a robot "
                    "in the lane ahead; today's other rules", (*AUTHORS, "--set", "controller.spiral.lane_yield=false"))
# The lane rule's yielding chains (issue 37: 3 of 20 DDSA runs at 32 robots stood for good) are broken by
# controller.spiral.lane_unjam, the default since 2026-11-29; this factor is the rule before it.
LANE_UNJAM_OFF = Factor("lane_unjam_off", "the lane rule's timeout yields again (as shipped before 2026-11-29), "
                        "instead of starting the model's avoidance turn at the lane hit the model's detection "
                        "missed; today's other rules",
                        ("--strategies", "ddsa", "mdbsa_c", *AUTHORS, "--set", "controller.spiral.lane_unjam=false"))
# Issue 37's surplus of our DDSA over the authors' run here (12-99 % at 8-32 robots) was where the spirals start:
# their every robot starts at the nest centre (first target the nest, reached inside it) and walks its first leg
# out over the lower robots' first legs (generatePattern, ReachSpiralTargets: DDSA repository, luki-dev,
# source/DSA/), so the start, the shared stem and the carriers all meet in the 0.18 m nest. The default since
# 2026-11-29 (controller.spiral.ddsa_stem: shared); this factor is ours before. DDSA only (MDBSA has no such stem).
OWN_STEM = Factor("ddsa_own_stem", "DDSA's spirals start where the lower robot's first leg ends, centre + (0, (i-1) "
                  "g), no leg walked twice (ours before 2026-11-29) instead of all at the depot centre over one "
                  "another's first legs (the authors' code); today's other rules",
                  ("--strategies", "ddsa", *AUTHORS, "--set", "controller.spiral.ddsa_stem=own"))
# The MDBSA rules adopted on 2026-11-27 (afternoon), each switched off alone on today's defaults
# (5 seeds): compare with the main sweep's MDBSA runs, not with this group's older baseline.
MDBSA_RULES = (
    Factor("mdbsa_no_radio", "MDBSA without the partner radio: a walk ends at the stop the center last sent, "
           "instead of where the partner has been (paper Sec. IV: walkers of a region communicate and meet); "
           "today's other rules", (*MDBSA, "--set", "controller.spiral.partner_radio=false")),
    Factor("mdbsa_no_nest", "MDBSA: a new walk straight from where the robot asked, instead of by way of (0.1, 0.1) "
           "(the authors' ReachSpiralTargets); today's other rules",
           (*MDBSA, "--set", "controller.spiral.next_walk_at=center_range")),
    Factor("mdbsa_waypoints_1", "MDBSA's lane waypoints every gap (0.18 m, the DDSA authors') instead of every 3 "
           "gaps (the MDBSA authors' generateSpiralPath); today's other rules",
           (*MDBSA, "--set", "controller.spiral.waypoint_gaps=1")),
)

GROUPS = (
    # Experiment 1 (4, 16, 64 regions).
    FactorGroup("spiral1", ("spiral", "--experiment", "1"), "spiral/exp1/results.jsonl", "all", (
        BASELINE,
        Factor("motion_generic", "motion rule: today's generic robot, same body and speeds", ("--robot-model", "generic")),
        Factor("turn_2.29", "turn rate 2.29 rad/s (wheels at 16 cm/s) instead of 1.143",
               (*AUTHORS, "--set", "robots.platform.max_angular_speed=2.2857")),
        CONE, REGIONS, DDSA_TURN, START, *MDBSA_RULES, LANE_YIELD,
    ), baseline="baseline/exp1"),
    # Experiment 2 (8-32 robots, 16 regions), where MDBSA-C is to collect about 44 % less than DDSA.
    FactorGroup("spiral2", ("spiral", "--experiment", "2"), "spiral/exp2/results.jsonl", "all",
                (BASELINE, CONE, REGIONS, DDSA_TURN, START, *MDBSA_RULES, LANE_YIELD, LANE_UNJAM_OFF, OWN_STEM),
                baseline="baseline/exp2"),
)
