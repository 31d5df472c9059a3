"""The queue paper's factor groups (`swarm_sim.factor_sweeps`, run by ``scripts/factors``): at 48
and at 112 robots, the authors' robot against one factor changed at a time."""

from swarm_controllers.queue.claims import QUEUE_SIZES
from swarm_sim.factor_sweeps import Factor, FactorGroup


def _authors(*settings: str) -> tuple[str, ...]:
    """A factor's arguments: the authors' robot with these ``--set KEY=VALUE`` settings."""
    return ("--robot-model", "authors", *(a for s in settings for a in ("--set", s)))


# footbot_cpfa and the generic queue robot share body (0.17 m), speed (0.16 m/s) and turn rate
# (1.143 rad/s): they differ in the motion rule, the ring and planarity only.
BASELINE = Factor("baseline", "the authors' robot (footbot_cpfa: stop-turn-go, the CPFA lineage's collision turn, "
                  "the queue authors' path stop)", ("--robot-model", "authors"))
MOTION_GENERIC = Factor("motion_generic", "motion rule: today's generic robot (continuous steering, our avoidance "
                        "and brake), same body and speeds", ("--robot-model", "generic"))
TURN = Factor("turn_2.29", "turn rate: the wheels at RobotForwardSpeed (16 cm/s) when turning, 2.29 rad/s, instead "
              "of RobotRotationSpeed's 8 cm/s",
              _authors("robots.platform.max_angular_speed=2.2857"))
STEP = Factor("step_0.16", "collision step: SearchStepSize 0.16 m (BaseController's default) instead of the "
              "experiment files' 0.08 m",
              _authors("robots.stop_turn_go.collision_step=0.16"))
# The CPFA baseline's nest. Shipped (queue_cpfa.yaml, since 2026-11-29): one nest at the centre, 0.189 m,
# a delivery on arrival, as the plain CPFA in the authors' repositories (Artglz/Collision_Free_CPFA main). The
# paper's text has every robot unload at a dock (sec. III): four docks at the queue authors'
# NestPositions, 0.3 m from the centre, 5 s at each (shipped before). Our queue layouts need their docks
# one body outside the 0.5 m depot (0.585 m: four serpentines do not fit round 0.3 m docks with 0.2 m
# lanes), so cpfa_docks_0.585 moves the text's docks out to the queue strategies' (measured against the
# text's docks, before 2026-11-29).
CPFA_DOCKS_TEXT = ("--set", "depot.delivery=docks", "--set", "depot.radius=0.5",
                   "--set", "resources.min_depot_clearance=2.0")
CPFA_DOCKS = Factor("cpfa_docks_0.585", "dock distance: the text's CPFA docks 0.585 m from the centre (where our "
                    "queue strategies' are) instead of the authors' NestPosition 0.3 m",
                    ("--strategies", "queue_cpfa", "--robot-model", "authors",
                     *CPFA_DOCKS_TEXT, "--set", "docking.dock_distance=0.585"))
CPFA_DOCKS_03 = Factor("cpfa_docks_0.3", "the CPFA's nest: the paper's text, four docks at the queue authors' "
                       "NestPositions 0.3 m from the centre with a 5 s unload (sec. III), instead of the one 0.189 m "
                       "nest at the centre of the plain CPFA in their repositories",
                       ("--strategies", "queue_cpfa", "--robot-model", "authors", *CPFA_DOCKS_TEXT))
# Q_ST's join rule: the paper's text (join behind the last robot) against the authors' code (their
# Q_ST, Tameem786/Collision_Free_CPFA branch CPFA-2.0, boards the spiral's inner lanes ahead of
# whoever is queued there: controller.queue.join_order=anywhere).
QST_JOIN = Factor("qst_join_anywhere", "Q_ST's join rule: any free cell of the line (the authors' CPFA-2.0 code) "
                  "instead of only behind the tail (the paper's sec. V-B)",
                  ("--strategies", "queue_qst", "--robot-model", "authors", "--set",
                   "controller.queue.join_order=anywhere"))
QST_NO_GIVE_UP = Factor("qst_no_give_up", "Q_ST's searcher never gives up (controller.queue.seek_timeout beyond "
                        "the run; the paper and the authors' code have no give-up) instead of falling back to entry "
                        "joining after our 120 s",
                        ("--strategies", "queue_qst", "--robot-model", "authors", "--set",
                         "controller.queue.seek_timeout=100000"))

# Q_ST at 48 robots bisected against the authors' own code run here (issue 37, item 4;
# results/reference/queue/results.jsonl: 37.6 % against our 18.4 %): the shipped Q_ST on the authors'
# robot, then one rule, parameter or set-up fact at a time switched to the authors' (or, for the
# motion layer as a whole, to the generic robot's, the lead to narrow down). 10 seeds a step.
QST_BASELINE = Factor("baseline", "the shipped Q_ST on the authors' robot (footbot_cpfa, join_order anywhere: "
                      "queue_qst.yaml)", ("--robot-model", "authors"))
QST_MOTION_GENERIC = Factor("motion_generic", "motion rule: the generic robot's (continuous steering, our avoidance "
                            "and brake) instead of the foot-bot's stop-turn-go, same body and speeds",
                            ("--robot-model", "generic"))
QST_DEPARTURE = Factor("cell_release_departure", "moving along the line: a robot's entry-line cell goes to the "
                       "robot behind once it holds a grant beyond it, which closes up to its path stop "
                       "(controller.queue.cell_release=departure: the authors' robots follow waypoints with no cells, "
                       "CPFA-2.0 CPFA_controller::FollowingEntryPath) instead of on its arrival at the next cell",
                       _authors("controller.queue.cell_release=departure"))
QST_INNERMOST = Factor("boarding_innermost", "where a carrier boards: straight in, at the innermost arc's nearest "
                       "cell, no radio (controller.queue.boarding=innermost: the authors' CPFA-2.0 "
                       "CPFA_controller::Returning boards the fifth arc, r = 1.0 m) instead of by the queued "
                       "robots' radio replies on the way in (sec. V-B)",
                       _authors("controller.queue.boarding=innermost"))
QST_QUEUED_CONTINUOUS = Factor("queued_motion_continuous", "the motion lead narrowed: the generic robot's continuous "
                               "steering and brake on the queue's lines only, the foot-bot's stop-turn-go while "
                               "foraging and seeking (controller.queue.queued_motion=continuous; a diagnostic, not "
                               "the authors' rule)",
                               _authors("controller.queue.queued_motion=continuous"))
# Inside the motion lead (2026-11-29): the queue authors' robots on their path never swerve, and their lines have no
# cells (their robots stand about a ring's reach apart, 0.27 m centre to centre).
QST_NEVER_SWERVE = Factor("never_swerve", "a robot braked on the queue's lines stands until the way is clear "
                          "(controller.queue.brake_patience beyond the run: the authors' CPFA_controller::"
                          "CollisionDetection only calls Stop() on the path) instead of swerving after 3 s (ours)",
                          _authors("controller.queue.brake_patience=100000"))
QST_PITCH = Factor("slot_pitch_0.3", "the lines' cells 0.3 m apart (controller.queue.slot_pitch; about the 0.27 m at "
                   "which the authors' robots stop behind one another by their proximity ring) instead of 0.2 m (the "
                   "lane spacing; the paper gives none)",
                   _authors("controller.queue.slot_pitch=0.3"))
QST_RETURN_RIM = Factor("return_leg_rim", "a carrier's blind return leg ends 0.1 m outside the perimeter "
                        "(controller.queue.return_leg=rim: the authors' CPFA_controller::Returning, safeDistance = "
                        "redCircleRadius + 0.1) instead of at the depot centre, across the lanes",
                        _authors("controller.queue.return_leg=rim"))
QST_ENTRY_REACH = Factor("entry_reach_0.1", "an entry-line cell counts as reached within 0.1 m (controller.queue."
                         "entry_reach: the authors' FollowingEntryPath waypoint threshold) instead of 0.05 m",
                         _authors("controller.queue.entry_reach=0.1"))
# The motion lead split in two (2026-11-29): the steering on the lines and the rule that halts a robot there.
QST_LINE_BRAKE = Factor("line_stop_brake", "stop-turn-go on the lines with our brake (the scan within 0.08 m ahead, "
                        "+-25 deg) instead of the authors' path stop (any ring reading within +-30 deg; "
                        "controller.queue.line_stop=brake; a diagnostic)",
                        _authors("controller.queue.line_stop=brake"))
QST_CONTINUOUS_RING = Factor("continuous_ring_stop", "the generic robot's continuous steering on the lines with the "
                             "authors' path stop kept (controller.queue.queued_motion=continuous, "
                             "controller.queue.line_stop=ring; a diagnostic)",
                             _authors("controller.queue.queued_motion=continuous", "controller.queue.line_stop=ring"))

# The CPFA's local resource density as the authors' code counts it (2026-11-29): a trace of their Q_ST
# (CPFA-2.0, 48 robots) has 95 % of their deliveries go back to the find's site (ResourceDensity 1 + the food
# within sqrt(2) x 4 x FoodRadius = 0.283 m, median 4 at a pickup, so POIS(c, 1.376) ~ 0.96), ours 24 % (c = the
# others within the 0.13 m detection radius: 0 at 92 of 98 pickups).
DENSITY_SETS = ("sensors.resource_detection_radius=0.2828", "controller.cpfa.density_counts_find=true")
DENSITY = Factor("density_authors", "the CPFA's local resource density counted as the authors' code does: 1 + the "
                 "food within 0.283 m of the find (CPFA_controller::SetLocalResourceDensity; sensors."
                 "resource_detection_radius=0.2828, controller.cpfa.density_counts_find=true) instead of the other "
                 "food within the 0.13 m detection radius", _authors(*DENSITY_SETS))
DENSITY_LINES = Factor("density_authors_lines_continuous", "the authors' density count (density_authors) and the "
                       "generic robot's continuous steering and brake on the queue's lines (queued_motion_continuous) "
                       "together", _authors(*DENSITY_SETS, "controller.queue.queued_motion=continuous"))
# The informed search as the authors' code turns it, with their density count: the CPFA as their code runs it.
CPFA_SETS = (*DENSITY_SETS, "controller.cpfa.informed_walk=turn")
CPFA_CODE = Factor("cpfa_authors", "the CPFA's density count (density_authors) and its informed search turning as the "
                   "authors' code does (controller.cpfa.informed_walk=turn: CPFA_controller::Searching, "
                   "GetExponentialDecay) instead of H&M's N(0, sigma(t))", _authors(*CPFA_SETS))
CPFA_CODE_LINES = Factor("cpfa_authors_lines_continuous", "the CPFA as the authors' code runs it (cpfa_authors) and "
                         "the generic robot's continuous steering and brake on the queue's lines together",
                         _authors(*CPFA_SETS, "controller.queue.queued_motion=continuous"))

# Q_SE at 48 robots against the authors' branch main run here (17.7 %; ours 12.5 %): the same motion steps.
QSE_BASELINE = Factor("baseline", "the shipped Q_SE on the authors' robot (footbot_cpfa: queue_qse.yaml)",
                      ("--robot-model", "authors"))

GROUPS = (
    FactorGroup("queue48", ("queue", "--robots", "48"), "queue/results.jsonl", "48",
                (BASELINE, MOTION_GENERIC, TURN, STEP, CPFA_DOCKS, CPFA_DOCKS_03, QST_JOIN, QST_NO_GIVE_UP)),
    # At 112 robots, where the strategies' order is the paper's headline.
    FactorGroup("queue112", ("queue", "--robots", "112"), "queue/results.jsonl", "112",
                (BASELINE, MOTION_GENERIC, TURN, CPFA_DOCKS_03, QST_JOIN, QST_NO_GIVE_UP)),
    # The CPFA baseline at 48 robots (10 seeds; queue48 has it at 2).
    FactorGroup("cpfa48", ("queue", "--robots", "48", "--strategies", "queue_cpfa"), "queue/results.jsonl", "48",
                (Factor("baseline", "the shipped CPFA on the authors' robot (footbot_cpfa: queue_cpfa.yaml)",
                        ("--robot-model", "authors")), DENSITY, CPFA_CODE), strategies=("queue_cpfa",)),
    FactorGroup("qst48", ("queue", "--robots", "48", "--strategies", "queue_qst"), "queue/results.jsonl", "48",
                (QST_BASELINE, QST_MOTION_GENERIC, QST_NO_GIVE_UP, QST_DEPARTURE, QST_INNERMOST,
                 QST_QUEUED_CONTINUOUS, QST_NEVER_SWERVE, QST_PITCH, QST_RETURN_RIM, QST_ENTRY_REACH, QST_LINE_BRAKE,
                 QST_CONTINUOUS_RING, DENSITY, DENSITY_LINES, CPFA_CODE, CPFA_CODE_LINES),
                strategies=("queue_qst",)),
    FactorGroup("qse48", ("queue", "--robots", "48", "--strategies", "queue_qse"), "queue/results.jsonl", "48",
                (QSE_BASELINE, QST_MOTION_GENERIC, QST_QUEUED_CONTINUOUS, QST_RETURN_RIM, DENSITY, DENSITY_LINES,
                 CPFA_CODE, CPFA_CODE_LINES), strategies=("queue_qse",)),
    # Q_SE at 112 robots, where ours is furthest from the authors' code run here (21.4 %; ours 7.9 %).
    FactorGroup("qse112", ("queue", "--robots", "112", "--strategies", "queue_qse"), "queue/results.jsonl", "112",
                (QSE_BASELINE, QST_QUEUED_CONTINUOUS, QST_RETURN_RIM, DENSITY, DENSITY_LINES),
                strategies=("queue_qse",)),
    # Q_ST at 112 robots (the authors' CPFA-2.0 run here: 34.8 %; ours 17.2 %): the motion step of qst48.
    FactorGroup("qst112", ("queue", "--robots", "112", "--strategies", "queue_qst"), "queue/results.jsonl", "112",
                (QST_BASELINE, QST_QUEUED_CONTINUOUS, QST_RETURN_RIM, DENSITY, DENSITY_LINES),
                strategies=("queue_qst",)),
    # Q_ME and Q_MT (no code of the authors has them, so the gap is to the paper): the motion steps of qst48 at
    # 10 seeds, where queue48 / queue112 had the whole motion rule at 2; the lines' motion alone at both ends only.
    *(FactorGroup(f"{label}{n}", ("queue", "--robots", str(n), "--strategies", strategy), "queue/results.jsonl",
                  str(n), (Factor("baseline", f"the shipped {name} on the authors' robot (footbot_cpfa: "
                                          f"{strategy}.yaml)", ("--robot-model", "authors")), QST_MOTION_GENERIC,
                           *((QST_QUEUED_CONTINUOUS,) if n in (48, 112) else ()),
                           *((DENSITY,) if n == 48 else ())),
                  strategies=(strategy,))
      for n in QUEUE_SIZES
      for label, strategy, name in (("qme", "queue_qme", "Q_ME"), ("qmt", "queue_qmt", "Q_MT"))),
    # The same step at the sizes between (Table II's other cells); for Q_SE, where it carries ours past
    # the authors' code, also the cells released on departure (their robots follow waypoints, no cells).
    *(FactorGroup(f"{label}{n}", ("queue", "--robots", str(n), "--strategies", strategy), "queue/results.jsonl",
                  str(n), (base, QST_QUEUED_CONTINUOUS, *extra), strategies=(strategy,))
      for n in (64, 80, 96)
      for label, strategy, base, extra in (("qse", "queue_qse", QSE_BASELINE, (QST_DEPARTURE,)),
                                           ("qst", "queue_qst", QST_BASELINE, ()))),
)
