"""The queue paper's results as claims (`swarm_sim.compare.verdicts`): every cell of Table II, the
pairwise order Table II implies with its sizes, the trends of Sec. VIII-A, the collision times of
Sec. VIII-B and the drop-off times of Sec. VIII-C.

Merged, not repeated: "Q_MT collects the most" and "Q_SE < Q_ST < Q_ME < Q_MT" are the pairs of
Table II's order; "Q_ST = 2 Q_SE" is the pair Q_SE < Q_ST with Table II's sizes (x1.9-2.4); "CPFA
has the highest collision time" is "all four queue strategies have significantly lower collision
time than CPFA"; the text's resource counts (CPFA 49 -> 37, Q_MT 202 -> 264 of 320) are Table II's
cells (noted there). "Q_SE's collision time grows fastest" is Q_SE's rise next to the others'
stable times (no two-sample test compares growths).
"""

from __future__ import annotations

from swarm_sim.compare.verdicts import CODE, LEVEL, MEASURED, OPEN, PARTIAL, RELATION, TREND, Cause, Claim

QUEUE_STRATEGIES: tuple[str, ...] = ("queue_cpfa", "queue_qse", "queue_qst", "queue_qme", "queue_qmt")
"""Scenario names of the queue paper's five strategies, in the paper's Table II row order."""
QUEUE_LABELS: dict[str, str] = {
    "queue_cpfa": "CPFA", "queue_qse": "Q_SE", "queue_qst": "Q_ST", "queue_qme": "Q_ME", "queue_qmt": "Q_MT",
}
QUEUE_SIZES: tuple[int, ...] = (48, 64, 80, 96, 112)
"""The paper's swarm sizes (Table I)."""

PAPER_TABLE_II: dict[str, dict[int, float]] = {
    "queue_cpfa": {48: 15.17, 64: 13.33, 80: 12.17, 96: 11.47, 112: 11.39},
    "queue_qse": {48: 17.39, 64: 18.09, 80: 17.36, 96: 16.63, 112: 18.06},
    "queue_qst": {48: 37.98, 64: 38.88, 80: 42.45, 96: 37.44, 112: 34.60},
    "queue_qme": {48: 46.61, 64: 54.29, 80: 59.19, 96: 61.42, 112: 64.22},
    "queue_qmt": {48: 62.94, 64: 71.93, 80: 76.39, 96: 82.31, 112: 82.39},
}
"""THE PAPER'S numbers, not ours: queue paper Table II, "Resource Collection (%)", mean over 50
ARGoS runs of 18 min, 12 x 12 m arena, 320 resources in five 8 x 8 clusters."""

PCT, COLLISION, DROPOFF = "resources_collected_pct", "collision_time_per_robot_s", "dropoff_time_mean_s"
AUTHORS_COLLISION = "authors_collision_time_per_robot_s"
"""Collision time as the queue authors' controllers count it (`swarm_controllers.queue.authors_count`):
Fig. 9 against their runs is judged on it (`Claim.code_measure`)."""
TEXT_COUNTS = {("queue_cpfa", 48): "text: 49 of 320 (15.3 %)", ("queue_cpfa", 112): "text: 37 of 320 (11.6 %)",
               ("queue_qmt", 48): "text: 202 of 320 (63.1 %)", ("queue_qmt", 112): "text: 264 of 320 (82.5 %)"}
"""Sec. VIII-A's resource counts, the same cells as Table II's."""

_MOTION = Cause(PARTIAL, "the foot-bot's stop-turn-go motion rule: with the generic robot's motion on the same "
                         "body, speed and turn rate every queue strategy collects 1.4-3.9x more (factor "
                         "`motion_generic`, queue48 / queue112, 2 seeds; FACTORS.md)", "motion_generic", 2)
_QST48_MOTION = Cause(MEASURED, "the foot-bot's stop-turn-go motion rule on our queue's lines: Q_ST at 48 robots "
                               "collects 18.1 % on it, 31.8 % with the generic robot's continuous steering on the "
                               "queue's lines only (factor `queued_motion_continuous`, qst48, 10 seeds) and 33.6 % "
                               "with it everywhere (`motion_generic`); the authors' code run here, 37.6 %, moves its "
                               "foot-bots by the same rule, so it costs ours this only together with something else of "
                               "our queue, not isolated yet (its cells released on departure, boarding at the "
                               "innermost arc, no give-up, the return leg ending at the rim, cells 0.3 m apart, a "
                               "cell reached within 0.1 m: none closes it; never swerving, their path rule, halves "
                               "ours). Of the 13.7 points, the steering is about 8 and the stop rule about 6 "
                               "(`continuous_ring_stop` 26.6 %, `line_stop_brake` 24.1 %); with their CPFA's density "
                               "count on top (1 + the food within 0.283 m, `density_authors_lines_continuous`) 33.8 %, "
                               "-10 % of theirs (FACTORS.md, CAUSES.md)",
                      "qst48/queued_motion_continuous", 10)
LINE_MOTION_STEPS: tuple[tuple[str, int, float, float, float], ...] = (
    ("queue_qse", 48, 13.1, 19.9, 17.7), ("queue_qse", 64, 11.6, 22.2, 18.3), ("queue_qse", 80, 9.5, 24.1, 16.3),
    ("queue_qse", 96, 9.8, 22.8, 16.9), ("queue_qse", 112, 8.2, 21.9, 21.4),
    ("queue_qst", 64, 18.9, 33.7, 41.3), ("queue_qst", 80, 19.4, 34.5, 41.1), ("queue_qst", 96, 17.6, 35.2, 36.8),
    ("queue_qst", 112, 19.3, 33.0, 34.8),
)
"""Issue 37's bisection step at each Table II size (group ``qse<n>`` / ``qst<n>``, seeds 0-9):
(strategy, robots, ours [%], ours with `queued_motion_continuous` [%], the authors' code run here,
20 seeds [%]). Q_ST at 48 robots: `_QST48_MOTION`."""


def _line_motion(s: str, n: int, base: float, cont: float, ref: float) -> Cause:
    """The motion on our lines as the cause of a level cell's gap to the authors' code: measured
    where switching it alone closes at least half the gap, partial where it moves ours past theirs
    by more (the rule is in the gap, not all of it)."""
    group = f"{'qse' if s == 'queue_qse' else 'qst'}{n}"
    closes = abs(cont - ref) <= abs(base - ref) / 2
    text = (f"the foot-bot's stop-turn-go motion rule on our queue's lines: {QUEUE_LABELS[s]} at {n} robots collects "
            f"{base} % on it and {cont} % with the generic robot's continuous steering on the queue's lines only "
            f"(factor `queued_motion_continuous`, {group}, 10 seeds), where the authors' code run here collects "
            f"{ref} %" + ("" if closes else ": past theirs by more than ours fell short, so it is in the gap but "
                          "something else of ours offsets it") + "; their foot-bots move by the same rule, so it costs "
            "ours this only together with something else of our queue, not isolated yet (FACTORS.md, CAUSES.md)")
    return Cause(MEASURED if closes else PARTIAL, text, f"{group}/queued_motion_continuous", 10)


_STEP_CAUSES = {(s, n): _line_motion(s, n, *values) for s, n, *values in LINE_MOTION_STEPS}
"""A level cell's cause by its measured motion step: `LINE_MOTION_STEPS`, then `WHOLE_MOTION_STEPS`."""
WHOLE_MOTION_STEPS: tuple[tuple[str, int, float, tuple[tuple[str, float], ...]], ...] = (
    ("queue_qme", 48, 33.28, (("motion_generic", 50.34), ("queued_motion_continuous", 36.31))),
    ("queue_qme", 64, 40.94, (("motion_generic", 62.69),)),
    ("queue_qme", 80, 45.75, (("motion_generic", 74.25),)),
    ("queue_qme", 96, 44.25, (("motion_generic", 81.72),)),
    ("queue_qme", 112, 44.75, (("motion_generic", 84.16), ("queued_motion_continuous", 54.72))),
    ("queue_qmt", 48, 40.09, (("motion_generic", 60.81), ("queued_motion_continuous", 52.16))),
    ("queue_qmt", 64, 47.34, (("motion_generic", 75.5),)),
    ("queue_qmt", 80, 47.31, (("motion_generic", 85.69),)),
    ("queue_qmt", 96, 51.38, (("motion_generic", 90.09),)),
    ("queue_qmt", 112, 55.34, (("motion_generic", 88.19), ("queued_motion_continuous", 78.25))),
)
"""Q_ME and Q_MT, which no code of the authors has, against the paper (groups ``qme<n>`` / ``qmt<n>``,
seeds 0-9): (strategy, robots, ours [%], ((factor, ours with it alone switched [%]), ...)):
`motion_generic`, the generic robot's motion everywhere on the foot-bot's body and speeds;
`queued_motion_continuous`, on the queue's lines only."""
_MOTION_WORDS = {"motion_generic": "with the generic robot's continuous steering, avoidance and brake on the same "
                                   "body, speed and turn rate",
                 "queued_motion_continuous": "with it on the queue's lines only"}


def _whole_motion(s: str, n: int, base: float, steps: tuple[tuple[str, float], ...]) -> Cause:
    """The foot-bot's motion as the cause of a Q_ME or Q_MT level's gap to the paper: measured by the
    factors that alone close at least half of it; partial where none does (they carry ours past
    the paper's by more than ours fell short: the rule is in the gap, not all of it)."""
    paper = PAPER_TABLE_II[s][n]
    group = f"{'qme' if s == 'queue_qme' else 'qmt'}{n}"
    closing = [f for f, v in steps if abs(v - paper) <= abs(base - paper) / 2]
    detail = ", ".join(f"{v} % {_MOTION_WORDS[f]} (`{f}`)" for f, v in steps)
    verdict = (f"`{'` and `'.join(closing)}` close{'s' if len(closing) == 1 else ''} at least half the gap" if closing
               else "past the paper's by more than ours fell short, so it is in the gap but not all of it")
    text = (f"the foot-bot's stop-turn-go motion rule: {QUEUE_LABELS[s]} at {n} robots collects {base} % on it, "
            f"{detail} ({group}, 10 seeds), where the paper has {paper} %: {verdict}; no code of the authors has "
            "Q_ME or Q_MT to run (FACTORS.md, CAUSES.md)")
    return Cause(MEASURED if closing else PARTIAL, text, f"{group}/{(closing or [steps[0][0]])[0]}", 10)


_STEP_CAUSES.update({(s, n): _whole_motion(s, n, base, steps) for s, n, base, steps in WHOLE_MOTION_STEPS})
_CPFA_REF = Cause(PARTIAL, "ours is 10-12 % under the authors' CPFA run here (the plain CPFA in their "
                           "repositories, one nest at the centre; results/reference/queue/): -10 / -10 / -12 / -11 / -12 % "
                           "at 48-112 robots, 20 runs each, every 95 % interval inside the ±25 % band (holds at 48 "
                           "and 80 robots; at 64, 96 and 112 the Holm-corrected test does not clear it); that code itself collects 11-17 % less than Table II "
                           "(12.7 / 11.6 / 10.9 / 10.0 / 9.6 %), so the rest of the gap lies between the paper and the authors' "
                           "code as run here, whose Table II set-up for the CPFA is not published. With the text's "
                           "four docks instead (factor `cpfa_docks_0.3`, queue48 / queue112, 10 seeds) ours collects 35.9 / 14.3 % at 48 / 112 robots (11.8 / 8.9 % on the same seeds). With the local "
                           "resource density counted as their code counts it (1 + the food within 0.283 m; factor "
                           "`density_authors`, cpfa48, 10 seeds) ours collects 12.8 % at 48 robots (11.8 % on the same "
                           "seeds), theirs 12.7 %")
_CPFA_GENERIC = Cause(OPEN, "generic robot: its CPFA jams harder at the 0.19 m nest as robots are added (17.5 % at 48 "
                            "robots, 5.0 % at 112: -71 %, where the foot-bot's falls by 24 % and the authors' code's by "
                            "24 %); what in its continuous steering and avoidance does it is not measured")
_ORDER_CPFA = Cause(PARTIAL, "our CPFA is 10-12 % under the authors' CPFA run here (T2.CPFA), so these margins "
                             "are set by our queue strategies' levels: our Q_SE and Q_ST collect about half of what "
                             "the authors' code does (the foot-bot's motion on our queue's lines, measured: T2.Q_SE, "
                             "T2.Q_ST), and our Q_MT at 48 robots less than the paper's (T2.Q_MT)")
_QST_COLL_CODE = Cause(CODE, "the authors' code run here (CPFA-2.0, 20 runs a size) contradicts it too: by its own "
                            "count Q_ST's collision time per robot rises 36 -> 68 s from 48 to 112 robots (+89 %). "
                            "Ours by the same count rises 96 -> 229 s (+138 %; the world's ring: +74 %), more than "
                            "theirs (direction only against their runs) and 2.7-3.4x as high, as our foot-bots stand "
                            "longer in line (drop-off time: ours 268-349 s, theirs 121-167 s; CAUSES.md)",
                      "reference/queue", 20)
_NO_CODE = "not measured: the authors' repositories hold no Q_ME or Q_MT, so there is no run of their code to put it to"
_COLL_OPEN = Cause(OPEN, f"{_NO_CODE}; their Q_ST, the one strategy they have that the paper calls stable, rises by "
                         "89 % (collision.Q_ST.stable); ours rises by 135 / 74 % (Q_ME / Q_MT; the world's ring), "
                         "198 / 107 % by the authors' count")


_CPFA_CAUSES = (("authors", _CPFA_REF), ("generic", _CPFA_GENERIC))


def _on(cause: Cause) -> tuple[tuple[str, Cause], ...]:
    """The models a cause applies to: the motion rule is the foot-bot's only."""
    return (("authors", cause),) if cause in (_MOTION, _QST48_MOTION, *_STEP_CAUSES.values()) else (("*", cause),)


def _pair_sizes(a: str, b: str) -> tuple[tuple[int, float], ...]:
    pa, pb = PAPER_TABLE_II[a], PAPER_TABLE_II[b]
    return tuple((n, round(100.0 * (pb[n] - pa[n]) / pa[n], 1)) for n in QUEUE_SIZES)


def _levels() -> list[Claim]:
    out = []
    for s in QUEUE_STRATEGIES:
        for n in QUEUE_SIZES:
            causes = (_CPFA_CAUSES if s == "queue_cpfa" else
                      _on(_QST48_MOTION if (s, n) == ("queue_qst", 48) else _STEP_CAUSES.get((s, n), _MOTION)))
            out.append(Claim(f"T2.{QUEUE_LABELS[s]}.{n}", LEVEL, f"{QUEUE_LABELS[s]} collects {PAPER_TABLE_II[s][n]} % "
                             f"with {n} robots", "Table II", PCT, s, (n,), value=PAPER_TABLE_II[s][n], unit="%",
                             note=TEXT_COUNTS.get((s, n), ""), causes=causes))
    return out


def _order() -> list[Claim]:
    out = []
    order = list(QUEUE_STRATEGIES)  # Table II: least to most at every size
    for i, a in enumerate(order):
        for b in order[i + 1:]:
            causes = ((("authors", _ORDER_CPFA), ("generic", _CPFA_GENERIC)) if a == "queue_cpfa"
                      else _on(_MOTION))
            out.append(Claim(f"order.{QUEUE_LABELS[a]}<{QUEUE_LABELS[b]}", RELATION,
                             f"{QUEUE_LABELS[b]} collects more than {QUEUE_LABELS[a]}",
                             "Table II (every size)" + ("; Sec. VIII-A: Q_ST about 2 Q_SE" if b == "queue_qst" and
                                                       a == "queue_qse" else ""),
                             PCT, a, QUEUE_SIZES, b=b, sizes=_pair_sizes(a, b), causes=causes))
    return out


def _trends() -> list[Claim]:
    def pct(s: str) -> float:
        t = PAPER_TABLE_II[s]
        return round(100.0 * (t[112] - t[48]) / t[48], 1)

    ends = (QUEUE_SIZES[0], QUEUE_SIZES[-1])
    return [
        Claim("trend.CPFA", TREND, "CPFA collects less with more robots (49 -> 37 resources)", "Sec. VIII-A, Table II",
              PCT, "queue_cpfa", ends, size=pct("queue_cpfa"), sign=-1, causes=_CPFA_CAUSES),
        Claim("trend.Q_ME", TREND, "Q_ME collects more with more robots", "Sec. VIII-A, Table II", PCT, "queue_qme",
              ends, size=pct("queue_qme"), causes=_on(_MOTION)),
        Claim("trend.Q_MT", TREND, "Q_MT collects more with more robots (202 -> 264 resources)",
              "Sec. VIII-A, Table II", PCT, "queue_qmt", ends, size=pct("queue_qmt"), causes=_on(_MOTION)),
    ]


def _collision() -> list[Claim]:
    ends = (QUEUE_SIZES[0], QUEUE_SIZES[-1])
    out = [Claim(f"collision.{QUEUE_LABELS[s]}<CPFA", RELATION,
                 f"{QUEUE_LABELS[s]} has significantly lower collision time than CPFA", "Sec. VIII-B, Fig. 9",
                 COLLISION, "queue_cpfa", QUEUE_SIZES, b=s, sign=-1, scale=1 / 60, unit="min",
                 causes=_CPFA_CAUSES, code_measure=AUTHORS_COLLISION)
           for s in QUEUE_STRATEGIES[1:]]
    out.append(Claim("collision.Q_SE.rises", TREND, "Q_SE's collision time increases notably with the robots",
                     "Sec. VIII-B, Fig. 9", COLLISION, "queue_qse", ends, sign=1, scale=1 / 60, unit="min",
                     code_measure=AUTHORS_COLLISION))
    out += [Claim(f"collision.{QUEUE_LABELS[s]}.stable", TREND,
                  f"{QUEUE_LABELS[s]}'s collision time stays relatively stable (slight increases)",
                  "Sec. VIII-B, Fig. 9", COLLISION, s, ends, sign=0, scale=1 / 60, unit="min",
                  causes=(("*", _QST_COLL_CODE if s == "queue_qst" else _COLL_OPEN),), code_measure=AUTHORS_COLLISION)
            for s in ("queue_qst", "queue_qme", "queue_qmt")]
    return out


def _dropoff() -> list[Claim]:
    ends = (QUEUE_SIZES[0], QUEUE_SIZES[-1])
    no_qmt = Cause(OPEN, _NO_CODE)
    out = [Claim(f"dropoff.Q_SE>{QUEUE_LABELS[s]}", RELATION,
                 f"Q_SE's drop-off time is higher than {QUEUE_LABELS[s]}'s", "Sec. VIII-C, Fig. 10", DROPOFF, s,
                 QUEUE_SIZES, b="queue_qse", unit="s", causes=(("*", Cause(OPEN, "not measured")),))
           for s in QUEUE_STRATEGIES if s != "queue_qse"]
    out += [Claim(f"dropoff.Q_MT<{QUEUE_LABELS[s]}", RELATION,
                  f"Q_MT's drop-off time is lower than {QUEUE_LABELS[s]}'s", "Sec. VIII-C, Fig. 10", DROPOFF, s,
                  QUEUE_SIZES, b="queue_qmt", sign=-1, unit="s", causes=(("*", no_qmt),))
            for s in ("queue_cpfa", "queue_qst", "queue_qme")]
    out.append(Claim("dropoff.Q_MT.stable", TREND, "Q_MT's drop-off time remains remarkably stable",
                     "Sec. VIII-C, Fig. 10", DROPOFF, "queue_qmt", ends, sign=0, unit="s", causes=(("*", no_qmt),)))
    return out


QUEUE_CLAIMS: tuple[Claim, ...] = (*_levels(), *_order(), *_trends(), *_collision(), *_dropoff())
