"""The DRTM paper's factor groups (`swarm_sim.factor_sweeps`, run by ``scripts/factors``): Sec. 3.1,
Secs. 4.1 and 4.2, and Secs. 4.3 and 4.4, the authors' robot against one factor changed at a time.

footbot_foraging against the generic (e-puck-sized) robot of drtm.yaml: body 0.17 vs 0.07 m, turn
rate 1.43 vs 3.8 rad/s, ring 0.1 m vs 0.1 m beyond the body (24 rays each), light everywhere vs
within 2 m, food seen under the ground sensors vs within 0.2 m."""

from swarm_sim.factor_sweeps import Factor, FactorGroup

AUTHORS = ("--robot-model", "authors")
BASELINE = Factor("baseline", "the authors' robot (footbot_foraging: wheel_turning, diffusion, ground and light "
                  "sensors)", AUTHORS)
MOTION_GENERIC = Factor("motion_generic", "motion rule and sensors: today's generic (e-puck-sized) robot",
                        ("--robot-model", "generic"))
BODY = Factor("body_0.07", "body size: the generic robot's 0.07 m (e-puck) on the foot-bot's motion and sensors",
              (*AUTHORS, "--set", "robots.platform.diameter=0.07"))
ARTM_GAIN = Factor("artm_gain_0", "ARTM's rule reading: a fixed threshold (gain 0) instead of one token per token",
                   (*AUTHORS, "--set", "controller.threshold.artm_gain=0.0"))
_BOUNDED = (*AUTHORS, "--set", "controller.threshold.drtm_bounded=true")
_LIGHT = (*AUTHORS, "--set", "robots.platform.light_range=2.0")
_MT2 = (*AUTHORS, "--set", "controller.nest.oae_window_states=returning")

GROUPS = (
    FactorGroup("drtm31", ("drtm", "--conditions", "3.1"), "drtm/results.jsonl", "0", (
        BASELINE, MOTION_GENERIC, BODY,
        Factor("drtm_bounded", "DRTM's rule reading: eq. (6) clipped to [1, 10] from theta_t0 = 3.3 (Sec. 3.1's "
               "\"following the ARTM\") instead of theta = 0 while k and M_A are 0 (Sec. 3.2)", _BOUNDED),
        ARTM_GAIN,
        Factor("light_2.0", "sensor range: the light seen within 2 m (drtm.yaml's, the generic robot's) instead of "
               "everywhere in the arena", _LIGHT),
        Factor("food_0.2", "sensor range: food seen within 0.2 m (drtm.yaml's, the generic robot's) instead of under "
               "the ground sensors (0.164 m)", (*AUTHORS, "--set", "robots.platform.resource_detection_radius=0.2")),
        Factor("mt2_returning", "DRTM's rule reading: M_T2 counts the OAEs of robots in S_R only (Sec. 2.2: \"the "
               "number of OAEs due to robots within state S_R can well reflect the traffic conditions\") instead of "
               "every forager's", _MT2),
    )),
    # Secs. 4.1 and 4.2 (25 tokens; E_a = 20): the two factors that carry the relations elsewhere, so that
    # every condition has them at 10 seeds (issue 37).
    FactorGroup("drtm41", ("drtm", "--conditions", "4.1", "4.2"), "drtm/results.jsonl", "1,2", (
        BASELINE, BODY,
        Factor("mt2_returning", "DRTM's rule reading: M_T2 counts the OAEs of robots in S_R only instead of every "
               "forager's", _MT2),
    )),
    # Secs. 4.3 and 4.4 (30 robots; the 3 m arena), where V_f fails on foot-bots: the same factors.
    FactorGroup("drtm43", ("drtm", "--conditions", "4.3", "4.4"), "drtm/results.jsonl", "3,4", (
        BASELINE, MOTION_GENERIC, BODY,
        Factor("drtm_bounded", "DRTM's rule reading: eq. (6) clipped to [1, 10] from theta_t0 = 3.3 instead of "
               "theta = 0 while k and M_A are 0", _BOUNDED),
        ARTM_GAIN,
        Factor("light_2.0", "sensor range: the light seen within 2 m (drtm.yaml's) instead of everywhere in the "
               "arena", _LIGHT),
        Factor("mt2_returning", "DRTM's rule reading: M_T2 counts the OAEs of robots in S_R only instead of every "
               "forager's", _MT2),
    )),
)
