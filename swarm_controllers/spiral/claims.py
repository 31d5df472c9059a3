"""The MDBSA paper's results as claims (`swarm_sim.compare.verdicts`): every difference Sec. VI
states, with its size, and the Discussion's "MDBSA-D has the lowest collision time and collects the
most in all scenarios"; the paper prints no table, so its one level is experiment 3's "almost 100 %
collection rate". Each claim's `note` is the paper's sentence.

Merged, not repeated: the foraging rate (Fig. 7's "MDBSA-D outperforms both consistently") is the
resources per robot over the run's minutes, the same numbers as Fig. 6's claims (+101 %, +112 %);
Fig. 9's "≈ 24 % fewer [...] in MDBSA-C" (16 robots or more) and Fig. 8's "≈ 44 % fewer" (14 to 32)
are one quantity with two stated sizes: one claim whose band spans both. "MDBSA-C's collision time
is the highest" is MDBSA-C above DDSA and above MDBSA-D. Experiment 2's "growing with robots" of
MDBSA-D's margin is not a two-sample test: its band (+100 … +200 %) is checked cell by cell.
"""

from __future__ import annotations

from swarm_sim.compare.verdicts import CODE, LEVEL, MEASURED, OPEN, PARTIAL, RELATION, TREND, Cause, Claim

RES, COL, PCT = "resources_per_robot", "collision_time_per_robot_s", "resources_collected_pct"
_C, _D = "MDBSA_{Centralized}", "MDBSA_{Distributed}"

_CEILING = Cause(OPEN, "MDBSA-D collects 92-100 % of all resources (a ceiling), so its margin over DDSA is set by "
                       "DDSA's collection; why DDSA collects more than the paper's is not measured")
_D_MARGIN_CODE = Cause(CODE, "the authors' code run here misses the paper's range the same way (20 runs a cell; "
                             "experiment 2: +95 % at 14 robots, +212 % at 32; experiment 3: +50 % at 100 resources, "
                             "+354 % at 300), and ours holds against its runs in every cell. With every DDSA spiral "
                             "starting at the nest, as theirs (`controller.spiral.ddsa_stem: shared`, 2026-11-29), "
                             "our DDSA collects within -7 … +15 % of theirs (CAUSES.md)", "reference/spiral", 20)
_D_COLLISION_CODE = Cause(CODE, "the authors' code run here misses it at 8 and 14 robots too (-59 / -61 %, past the "
                                "paper's -58 %; 20 runs a cell), ours at 8 (-66 %); against their runs ours holds at "
                                "8-20 robots and is direction only at 26-32 (-53 % where theirs is -25 … -27 %: our "
                                "DDSA's collision time is twice theirs, by our lane rule: exp1.col.C>DDSA)",
                          "reference/spiral", 20)
_LANE_RULE = ("our lane rule (a searcher yields to what is in its own lane ahead; this project's, not the authors'): "
              "with it off (factor `lane_yield_off`, 10 seeds) our DDSA's collision time per robot is 27 s in "
              "experiment 1 (on: 48; the authors' code here: 22) and 36 / 48 / 56 / 60 / 66 s at 8-32 robots in "
              "experiment 2 (on: 56-140; theirs 30 / 45 / 57 / 61 / 65), while MDBSA's hardly moves; but with it off "
              "our DDSA collects 11 % more than theirs in experiment 1 and 11-83 % more in experiment 2, so what "
              "their DDSA loses without a lane rule is not isolated (CAUSES.md)")
_DDSA_COLLISION = Cause(MEASURED, f"{_LANE_RULE}; with it off MDBSA-C's collision time is 87-210 % above DDSA's "
                                  "(theirs 158-345 %)", "spiral1/lane_yield_off", 10)
_DDSA_COLLISION_D = Cause(PARTIAL, f"{_LANE_RULE}; with it off MDBSA-D's margin is -7.5 / -51 % at 4 / 64 regions "
                                   "(on: -63 / -63 %; theirs -28 / -10 %; the paper -33 %)",
                          "spiral1/lane_yield_off", 10)
_C_SURPLUS = Cause(OPEN, "our MDBSA-C collects more than the authors' run here (experiment 1, 64 regions: 61 against "
                         "56; experiment 3: 57-60 against 42-47, +21-37 %) where our DDSA is within 2 % (experiment 1) "
                         "and -2 … +15 % (experiment 3) of theirs, so its margin under DDSA is narrower; the cone, the "
                         "region order and the partner radio are the authors' already. Traced in their code (6 seeds): "
                         "their robots drive 23 m per delivery against our 15-18, the extra near the nest; their "
                         "pickup rules, return to the find and start grid, switched on their side, move nothing; "
                         "not isolated (CAUSES.md)")
_IDLE = Cause(PARTIAL, "generic robot: idle partners never settle within the region centre's radius and push on "
                       "(20 seeds, traced at seed 0; not a one-factor sweep)")
_GENERIC_CONE = Cause(OPEN, "generic robot: the cone changes only what it counts, its avoidance steers by "
                            "`controller.avoidance`, so MDBSA-C's carriers are not held at the nest; not a "
                            "one-factor sweep")


def _claims() -> dict[int, tuple[Claim, ...]]:
    e1, e2, e3 = (4, 16, 64), (8, 14, 20, 26, 32), (100, 150, 200, 250, 300)
    avg = (f"On average, {_D} collected around 101% more resources than DDSA and around 112% more resources "
           f"than {_C}.")
    col1 = (f"When using 4 and 64 regions, {_D} has approximately 33% less time in collisions than DDSA, and "
            "around 72% less time when using 16 regions.")
    c_col1 = (f"The collision time in {_C} increased as the number of regions increased, with both collision time "
              "and standard deviation being the highest among all algorithms.")
    lowest = (f"Our results show that in all simulated scenarios, {_D} outperformed the other two algorithms in "
              "terms of the number of collected resources and collision time. (Sec. VII)")
    c_cone = (("generic", _GENERIC_CONE),)
    idle = (("generic", _IDLE),)
    exp1 = (
        Claim("exp1.C~DDSA", RELATION, "MDBSA-C collects about as DDSA at 4 and 16 regions", "Sec. VI, Fig. 6",
              RES, "ddsa", (4, 16), b="mdbsa_c", sign=0, causes=c_cone,
              note=f"When using 4 and 16 regions, {_C} achieved similar performance to DDSA regarding the number "
                   "of collected resources."),
        Claim("exp1.C<DDSA.64", RELATION, "MDBSA-C collects about 25 % less than DDSA at 64 regions",
              "Sec. VI, Fig. 6", RES, "ddsa", (64,), b="mdbsa_c", sign=-1, size=-25.0,
              causes=(("authors", _C_SURPLUS), *c_cone),
              note="However, we observed a decrease of approximately 25% in the number of collected resources "
                   "using 64 regions. [baseline not stated; compared here with DDSA]"),
        Claim("exp1.D>DDSA", RELATION, "MDBSA-D collects about 101 % more than DDSA (average over regions)",
              "Sec. VI, Fig. 6", RES, "ddsa", e1, b="mdbsa_d", size=101.0, pooled=True,
              causes=(("*", _CEILING),), note=avg),
        Claim("exp1.D>C", RELATION, "MDBSA-D collects about 112 % more than MDBSA-C (average over regions)",
              "Sec. VI, Fig. 6", RES, "mdbsa_c", e1, b="mdbsa_d", size=112.0, pooled=True,
              causes=(("*", _CEILING),), note=avg),
        Claim("exp1.col.D<DDSA.4,64", RELATION, "MDBSA-D spends about 33 % less time in collisions than DDSA "
              "(4, 64 regions)", "Sec. VI, Fig. 6", COL, "ddsa", (4, 64), b="mdbsa_d", sign=-1, size=-33.0,
              causes=(("authors", _DDSA_COLLISION_D), *idle), note=col1),
        Claim("exp1.col.D<DDSA.16", RELATION, "MDBSA-D spends about 72 % less time in collisions than DDSA "
              "(16 regions)", "Sec. VI, Fig. 6", COL, "ddsa", (16,), b="mdbsa_d", sign=-1, size=-72.0,
              causes=idle, note=col1),
        Claim("exp1.col.C>DDSA", RELATION, "MDBSA-C's collision time is above DDSA's", "Sec. VI, Fig. 6", COL,
              "ddsa", e1, b="mdbsa_c", causes=(("authors", _DDSA_COLLISION), *c_cone), note=c_col1),
        Claim("exp1.col.C>D", RELATION, "MDBSA-C's collision time is above MDBSA-D's (the highest of all)",
              "Sec. VI, Fig. 6; Sec. VII", COL, "mdbsa_d", e1, b="mdbsa_c", causes=c_cone, note=c_col1),
        Claim("exp1.col.C.rises", TREND, "MDBSA-C's collision time increases with the regions", "Sec. VI, Fig. 6",
              COL, "mdbsa_c", (4, 64), causes=c_cone, note=c_col1),
    )
    exp2 = (
        Claim("exp2.D>DDSA", RELATION, "MDBSA-D collects ≈100 % to ≈200 % more per robot than DDSA",
              "Sec. VI, Fig. 8", RES, "ddsa", e2, b="mdbsa_d", band=(100.0, 200.0),
              causes=(("authors", _D_MARGIN_CODE), ("*", _CEILING)),
              note=f"Specifically, {_D} outperforms DDSA by ≈100% to ≈200% in terms of the number of resources "
                   "collected per robot as the number of robots increases."),
        Claim("exp2.C<DDSA", RELATION, "MDBSA-C collects ≈44 % (Fig. 8) / ≈24 % (Fig. 9) fewer than DDSA, "
              "14-32 robots", "Sec. VI, Figs. 8-9", RES, "ddsa", (14, 20, 26, 32), b="mdbsa_c", sign=-1,
              band=(-44.0, -24.0), pooled=True,
              causes=c_cone,
              note=f"On the other hand, {_C} collects ≈44% fewer resources than DDSA as the number of robots "
                   f"increases from 14 to 32. / In simulations with 16 or more robots, robots collect ≈24% fewer "
                   f"resources than DDSA in {_C}."),
        Claim("exp2.D>C", RELATION, "MDBSA-D collects more than MDBSA-C", "Sec. VII", RES, "mdbsa_c", e2,
              b="mdbsa_d", causes=(("*", _CEILING),), note=lowest),
        Claim("exp2.col.D<DDSA", RELATION, "MDBSA-D has ≈21 % to ≈58 % less collision time than DDSA",
              "Sec. VI, Fig. 8", COL, "ddsa", e2, b="mdbsa_d", sign=-1, band=(-58.0, -21.0),
              causes=(("authors", _D_COLLISION_CODE), *idle),
              note=f"As the number of robots increases, {_D} spends the least amount of time in collisions, "
                   "achieving ≈21% to ≈58% less collision time than DDSA."),
        Claim("exp2.col.C>DDSA", RELATION, "MDBSA-C's collision time is above DDSA's", "Sec. VI, Fig. 8", COL,
              "ddsa", e2, b="mdbsa_c", causes=c_cone,
              note=f"Increasing the number of robots has a significant effect on the collision times for {_C}, "
                   "with the collision time increasing sharply compared to DDSA."),
        Claim("exp2.col.C.rises", TREND, "MDBSA-C's collision time rises sharply with the robots", "Sec. VI, Fig. 8",
              COL, "mdbsa_c", (8, 32), causes=c_cone),
        Claim("exp2.col.D<C", RELATION, "MDBSA-D's collision time is below MDBSA-C's", "Sec. VII", COL, "mdbsa_c",
              e2, b="mdbsa_d", sign=-1, causes=idle, note=lowest),
    )
    exp3 = (
        Claim("exp3.C<DDSA", RELATION, "MDBSA-C collects ≈30.4 % fewer than DDSA", "Sec. VI, Fig. 10", RES, "ddsa",
              e3, b="mdbsa_c", sign=-1, size=-30.4, pooled=True, causes=(("authors", _C_SURPLUS), *c_cone),
              note=f"Lastly, Fig. 10 displays the results for Experiment 3. {_C} collects ≈30.4% fewer resources "
                   "than DDSA."),
        Claim("exp3.D>DDSA", RELATION, "MDBSA-D collects ≈60 % to ≈350 % more than DDSA", "Sec. VI, Fig. 10", RES,
              "ddsa", e3, b="mdbsa_d", band=(60.0, 350.0), causes=(("authors", _D_MARGIN_CODE), ("*", _CEILING)),
              note=f"As the total number of resources increases, {_D} demonstrates an almost 100% collection rate "
                   "on average with a ≈60% to ≈350% improvement in the number of collected resources [...] in "
                   "comparison to DDSA."),
        Claim("exp3.D.100", LEVEL, "MDBSA-D collects almost 100 % of the resources (on average)", "Sec. VI, Fig. 10",
              PCT, "mdbsa_d", e3, value=100.0, pooled=True, unit="%",
              note=f"{_D} demonstrates an almost 100% collection rate on average"),
        Claim("exp3.D>C", RELATION, "MDBSA-D collects more than MDBSA-C", "Sec. VII", RES, "mdbsa_c", e3,
              b="mdbsa_d", note=lowest),
        Claim("exp3.col.C>DDSA", RELATION, "MDBSA-C's collision time is above DDSA's", "Sec. VI, Fig. 10", COL,
              "ddsa", e3, b="mdbsa_c", causes=c_cone,
              note=f"{_C} [...] contains the highest collision time per bot in comparison to the others."),
        Claim("exp3.col.C>D", RELATION, "MDBSA-C's collision time is above MDBSA-D's", "Sec. VI, Fig. 10", COL,
              "mdbsa_d", e3, b="mdbsa_c", causes=c_cone),
        Claim("exp3.col.C.rises", TREND, "MDBSA-C's collision time rises with the resources (decreasing momentum)",
              "Sec. VI, Fig. 10", COL, "mdbsa_c", (100, 300), causes=c_cone),
        Claim("exp3.col.D<DDSA", RELATION, "MDBSA-D's collision time is below DDSA's", "Sec. VII", COL, "ddsa", e3,
              b="mdbsa_d", sign=-1, causes=idle, note=lowest),
    )
    return {1: exp1, 2: exp2, 3: exp3}


SPIRAL_CLAIMS: dict[int, tuple[Claim, ...]] = _claims()
"""The claims each experiment's sweep decides."""
