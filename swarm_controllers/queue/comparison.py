"""The queue paper's comparison (Zaman et al., queue_depot_traffic.md): Table II, Figs 8-10 and
independent two-sample t-tests, our runs next to the paper's numbers."""

from __future__ import annotations

import argparse
import math
from collections.abc import Sequence
from pathlib import Path

from swarm_controllers.queue.claims import (
    PAPER_TABLE_II,
    QUEUE_CLAIMS,
    QUEUE_LABELS,
    QUEUE_SIZES,
    QUEUE_STRATEGIES,
)
from swarm_sim.cli import scenario_fields
from swarm_sim.compare.comparison import Comparison, Rule
from swarm_sim.compare.report import (
    boxplot_figure,
    cell_text,
    fmt,
    fmt_p,
    label,
    md_table,
    reference_rows,
    reference_runs,
)
from swarm_sim.compare.stats import all_pairs, cells_of, describe, ordering, pair_test, pairwise_tests, stars, values_of
from swarm_sim.compare.sweep import RunPlan, frozen_fields
from swarm_sim.compare.verdicts import level_marks

PAPER_QUEUE_QUOTES = (
    "Given a total of 320 available resources, the average number of collected resources "
    "decreases from 49 with 48 robots to 37 with 112 robots. [CPFA]",
    "Among all strategies, Q_MT achieves the best performance, collecting 202 resources with 48 "
    "robots and 264 resources with 112 robots.",
    "As expected, CPFA exhibits the highest collision time (see Fig. 9). [...] Q_SE shows a "
    "notably faster increase in collision time as the number of robots grows.",
    "Among all strategies, Q_SE exhibits the highest resource drop-off time [...] its drop-off "
    "time is even higher than that of CPFA. In contrast, Q_MT consistently achieves the lowest "
    "drop-off time across all experiments (see Fig. 10).",
)

AUTHORS_LOG_COLLISION_MIN: dict[str, dict[int, float]] = {
    "queue_qse": {48: 0.768, 64: 1.417, 80: 1.903, 96: 2.221, 112: 2.072},
    "queue_qst": {48: 0.301, 64: 0.380, 80: 0.441, 96: 0.530, 112: 0.565},
}
"""THE AUTHORS' run logs, not ours: their printed "Collision Time" (minutes, all robots) divided
by the swarm size, mean over 20 runs of 18 min (``results_18_mins_<N>_robots.txt`` of
Tameem786/Collision_Free_CPFA: branch main = the single queue with entry-point joining, whose
collection matches Table II's Q_SE; branch CPFA-2.0 = tail joining, matching Q_ST).
``CPFA_loop_functions::PostExperiment`` divides the tick count by 2 x ticks per second, so
these are half the time their ring saw something ahead."""

COLLISION_MIN = "collision_time_per_robot_min"
"""Derived from ``collision_time_per_robot_s``: the paper plots collision time in minutes."""
AUTHORS_COLLISION_MIN = "authors_collision_time_per_robot_min"
"""Derived from ``authors_collision_time_per_robot_s`` (`swarm_controllers.queue.authors_count`)."""

QUEUE_METRICS: dict[str, str] = {
    "resources_collected_pct": "resources collected [%]",
    COLLISION_MIN: "collision time per robot [min]",
    AUTHORS_COLLISION_MIN: "collision time per robot, the authors' count [min]",
    "dropoff_time_mean_s": "drop-off time (per-run mean over deliveries) [s]",
}

PAPER_ORDER: tuple[str, ...] = QUEUE_STRATEGIES
"""Table II's order at every size, least to most collected: CPFA < Q_SE < Q_ST < Q_ME < Q_MT."""
ALPHA = 0.05


def with_minutes(rows: Sequence[dict]) -> list[dict]:
    """Rows with the collision times per robot in minutes added (`COLLISION_MIN`,
    `AUTHORS_COLLISION_MIN`), where they have them."""
    pairs = (("collision_time_per_robot_s", COLLISION_MIN),
             ("authors_collision_time_per_robot_s", AUTHORS_COLLISION_MIN))
    return [{**r, **{m: r[s] / 60.0 for s, m in pairs if isinstance(r.get(s), (int, float))}} for r in rows]


def queue_plans(
    sizes: Sequence[int],
    strategies: Sequence[str] = QUEUE_STRATEGIES,
    *,
    duration: float | None = None,
    overrides: Sequence[str] = (),
) -> list[RunPlan]:
    """Every strategy at every swarm size (sizes outer, so a cut sweep has whole columns)."""
    plans = []
    for n in sizes:
        fields = scenario_fields(argparse.Namespace(robots=n, duration=duration))
        plans.extend(RunPlan(s, n, tuple(overrides), frozen_fields(fields)) for s in strategies)
    return plans


def queue_table_md(rows: Sequence[dict], sizes: Sequence[int], strategies: Sequence[str]) -> str:
    """table.md: Table II layout (ours next to the paper's), then collision and drop-off times."""
    rows = with_minutes(rows)
    lines = ["# Queue paper comparison (Zaman et al.): tables", ""]
    n_runs = sorted({describe(values_of(rows, s, c, "resources_collected_pct")).n for s in strategies for c in sizes})
    lines += [f"Runs per cell: {', '.join(map(str, n_runs))} (the paper: 50). Cells: mean ± sample std (n).", ""]
    lines += ["## Resource collection [%] (Table II layout)", "",
              "`ours` = this simulator; `paper` = **the paper's Table II** (ARGoS, 50 runs), hard-coded "
              "reference data.", ""]
    header = ["Algorithm"] + [f"{c} {w}" for c in sizes for w in ("ours", "paper")]
    body = []
    for s in strategies:
        row = [label(s, QUEUE_LABELS)]
        for c in sizes:
            row.append(cell_text(describe(values_of(rows, s, c, "resources_collected_pct"))))
            row.append(fmt(PAPER_TABLE_II.get(s, {}).get(c)))
        body.append(row)
    lines += md_table(header, body) + [""]
    lines += ["### The paper's Table II (reference, not our data)", ""]
    lines += md_table(["Algorithm"] + [str(c) for c in QUEUE_SIZES],
                      [[label(s, QUEUE_LABELS)] + [fmt(PAPER_TABLE_II[s][c]) for c in QUEUE_SIZES]
                       for s in QUEUE_STRATEGIES]) + [""]
    lines += ["The paper's text (quoted):", ""] + [f"> {q}" for q in PAPER_QUEUE_QUOTES] + [""]
    lines += ["## Collision time per robot [min] (Fig. 9)", "",
              "Time each robot's proximity ring saw something ahead (what the authors' controllers "
              "count as collision; `swarm_sim/world/proximity.py`), in minutes as the paper plots it. "
              "`log` = **the authors' own run logs** (their printed total / robots; their print is half "
              "the time, see `AUTHORS_LOG_COLLISION_MIN`), where published.", ""]
    header = ["Algorithm"] + [f"{c} {w}" for c in sizes for w in ("ours", "log")]
    lines += md_table(header, [[label(s, QUEUE_LABELS)] + [
        x for c in sizes for x in (cell_text(describe(values_of(rows, s, c, COLLISION_MIN))),
                                   fmt(AUTHORS_LOG_COLLISION_MIN.get(s, {}).get(c), 3))]
        for s in strategies]) + [""]
    for metric, title, note in (
            ("contact_time_per_robot_s", "Contact time per robot [s]",
             "Time bodies touched (pybullet contacts); not a metric of the paper."),
            ("dropoff_time_mean_s", "Resource drop-off time [s] (Fig. 10)",
             "Per run: the mean over its deliveries of the time from entering the perimeter to "
             "reaching the dock (before T_unload); runs without a delivery are left out of n.")):
        lines += [f"## {title}", "", note, ""]
        lines += md_table(["Algorithm"] + [str(c) for c in sizes],
                          [[label(s, QUEUE_LABELS)] + [cell_text(describe(values_of(rows, s, c, metric)))
                                                       for c in sizes] for s in strategies]) + [""]
    return "\n".join(lines)


def queue_ttests_md(rows: Sequence[dict], sizes: Sequence[int], strategies: Sequence[str]) -> str:
    """ttests.md: scipy ttest_ind (equal variances, as its default) for every pair and size, and
    the ordering of the strategies by mean collection against the paper's."""
    from scipy.stats import kendalltau

    rows = with_minutes(rows)
    lines = ["# Queue paper comparison: independent two-sample t-tests", "",
             "scipy.stats.ttest_ind (default: equal variances, two-sided), as the paper. "
             "Stars: *** p<0.001, ** p<0.01, * p<0.05, ns otherwise; n/a: fewer than two runs "
             "or no variance.", ""]
    pairs = all_pairs(strategies)
    for metric, title in QUEUE_METRICS.items():
        lines += [f"## {title}", ""]
        for cell in sizes:
            lines += [f"### {cell} robots", ""]
            body = [[label(t.a, QUEUE_LABELS), label(t.b, QUEUE_LABELS), cell_text(t.stats_a),
                     cell_text(t.stats_b), fmt(t.statistic, 3), fmt_p(t.p), stars(t.p)]
                    for t in pairwise_tests(rows, metric, [cell], pairs, "t")]
            lines += md_table(["A", "B", "A mean ± std", "B mean ± std", "t", "p", "sig"], body) + [""]
    lines += ["## ordering", "",
              "Strategies ascending by mean resources collected [%]: ours vs the paper's Table II. "
              "Kendall's tau over the strategies both have.", ""]
    body = []
    for cell in sizes:
        ours = ordering(rows, cell, strategies, "resources_collected_pct")
        paper = sorted((s for s in strategies if cell in PAPER_TABLE_II.get(s, {})),
                       key=lambda s: PAPER_TABLE_II[s][cell])
        common = [s for s in ours if s in paper]
        if len(common) >= 2:
            tau = kendalltau([ours.index(s) for s in common], [paper.index(s) for s in common]).statistic
            same = "yes" if [s for s in ours if s in paper] == [s for s in paper if s in ours] else "no"
        else:
            tau, same = math.nan, "—"
        body.append([str(cell), " < ".join(label(s, QUEUE_LABELS) for s in ours) or "—",
                     " < ".join(label(s, QUEUE_LABELS) for s in paper) or "— (size not in the paper)",
                     same, fmt(tau)])
    lines += md_table(["robots", "ours", "paper", "same order", "Kendall tau"], body) + [""]
    lines += ["## Table II's ordering, pair by pair", "",
              f"The paper ranks {' < '.join(label(s, QUEUE_LABELS) for s in PAPER_ORDER)} at every size. "
              f"A pair holds at a size when our means are in the paper's order and the t-test gives "
              f"p < {ALPHA}; `reversed` when ours are the other way round with p < {ALPHA}; `ns` "
              "otherwise. Q_ST = 2 Q_SE: the ratio of our means, and the t-test of Q_ST's runs "
              f"against twice Q_SE's (holds when p >= {ALPHA}: not distinguishable from twice).", ""]
    checks = ordering_checks(rows, sizes, strategies)
    lines += md_table(["pair (paper: A < B)"] + [str(c) for c in sizes],
                      [[name] + [text for _, text, _ in cells] for name, cells in checks]) + [""]
    return "\n".join(lines)


def ordering_checks(rows: Sequence[dict], sizes: Sequence[int], strategies: Sequence[str]
                    ) -> list[tuple[str, list[tuple[int, str, bool | None]]]]:
    """For every pair of Table II's order (and Q_ST = 2 Q_SE): per size (size, text, holds)."""
    pct = "resources_collected_pct"
    out = []
    order = [s for s in PAPER_ORDER if s in strategies]
    for a, b in all_pairs(order):
        cells = []
        for c in sizes:
            va, vb = values_of(rows, a, c, pct), values_of(rows, b, c, pct)
            _, p = pair_test(va, vb, "t")
            ma, mb = describe(va).mean, describe(vb).mean
            if not math.isfinite(p):
                direction = 'in order' if mb > ma else 'tied' if mb == ma else 'reversed'
                means = f": means {direction}" if va and vb else ""
                cells.append((c, f"n/a{means}", None))
                continue
            holds = mb > ma and p < ALPHA
            text = "holds" if holds else "reversed" if ma > mb and p < ALPHA else "ns"
            cells.append((c, f"{text} (p={fmt_p(p)})", holds))
        out.append((f"{label(a, QUEUE_LABELS)} < {label(b, QUEUE_LABELS)}", cells))
    if "queue_qse" in strategies and "queue_qst" in strategies:
        cells = []
        for c in sizes:
            va, vb = values_of(rows, "queue_qse", c, pct), values_of(rows, "queue_qst", c, pct)
            _, p = pair_test(vb, [2.0 * v for v in va], "t")
            ma, mb = describe(va).mean, describe(vb).mean
            if not (math.isfinite(p) and ma > 0):
                cells.append((c, "n/a", None))
                continue
            holds = p >= ALPHA
            cells.append((c, f"{'holds' if holds else 'no'}: x{fmt(mb / ma, 2)} (p={fmt_p(p)})", holds))
        out.append(("Q_ST = 2 Q_SE (Table II: x1.9-2.4)", cells))
    return out


def write_queue_report(rows: Sequence[dict], out: Path, sizes: Sequence[int] | None = None,
                       strategies: Sequence[str] = QUEUE_STRATEGIES) -> list[Path]:
    """table.md, ttests.md and the Fig. 8-10 box plots from result rows."""
    sizes = list(sizes or cells_of(rows))
    rows = with_minutes(rows)  # the box plots' too
    out.mkdir(parents=True, exist_ok=True)
    written = [out / "table.md", out / "ttests.md"]
    written[0].write_text(queue_table_md(rows, sizes, strategies))
    written[1].write_text(queue_ttests_md(rows, sizes, strategies))

    paper = {"resources_collected_pct": level_marks(QUEUE_CLAIMS, "resources_collected_pct")}
    with reference_runs(with_minutes(reference_rows())):  # their collision count in minutes too
        for name, metrics, fig in (
                ("collected.png", ("resources_collected_pct",), "Fig. 8; paper: Table II"),
                ("collision_time.png", (COLLISION_MIN, AUTHORS_COLLISION_MIN), "Fig. 9; the paper prints no number"),
                ("dropoff_time.png", ("dropoff_time_mean_s",), "Fig. 10; the paper prints no number")):
            written.append(boxplot_figure([(m, QUEUE_METRICS[m]) for m in metrics], rows, sizes, strategies,
                                          QUEUE_LABELS, "number of robots",
                                          f"{QUEUE_METRICS[metrics[0]]} (cf. queue paper {fig})", out / name,
                                          paper=paper, paper_text="paper (Table II) and its ±25 % band"))
    return written


def _add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--robots", type=int, nargs="+", default=list(QUEUE_SIZES),
                        help=f"swarm sizes (default: the paper's {' '.join(map(str, QUEUE_SIZES))})")


def _plans(args: argparse.Namespace, strategies: list[str]) -> list[RunPlan]:
    return queue_plans(args.robots, strategies, duration=args.duration, overrides=args.overrides)


def _write_report(rows: Sequence[dict], out: Path, args: argparse.Namespace, strategies: list[str]) -> list[Path]:
    return write_queue_report(rows, out, args.robots, strategies)


def _claims(args: argparse.Namespace) -> tuple:
    return QUEUE_CLAIMS


QUEUE_RULES: tuple[Rule, ...] = (
    Rule("queue_qst", "controller.queue.join_order",
         "Sec. V-B: a seeker that finds the tail \"will simply join the queue behind it\" (`behind_tail`)",
         "Tameem786/Collision_Free_CPFA branch CPFA-2.0, `CPFA_controller::Returning`: a carrier boards the spiral "
         "at the innermost lane it crossed once blocked (`anywhere`); its logged runs match Table II's Q_ST",
         "code", "the text's reading: `--set controller.queue.join_order=behind_tail`; the committed Q_ST runs "
                 "on both robot models use the code's rule"),
    Rule("queue_qst", "controller.queue.seek_timeout",
         "no give-up", "no give-up", "neither",
         "ours: a seeker falls back to the entry point after 120 s (factor `qst_no_give_up`)"),
    Rule("queue_cpfa, queue_qse, queue_qst, queue_qme, queue_qmt", "controller.cpfa.density_counts_find",
         "the CPFA by citation (Hecker & Moses): c, the resources in the find's neighbourhood; read here as the "
         "other food within the detection radius, 0.13 m (`false`)",
         "`CPFA_controller::SetLocalResourceDensity` (Tameem786 and Artglz/Collision_Free_CPFA): 1 + every food "
         "within sqrt(2) x 4 x FoodRadius = 0.283 m (`true` with `sensors.resource_detection_radius=0.2828`)",
         "text", "pending: their count sends 95 % of their deliveries back to the site, ours 24 % (CAUSES.md); the "
                 "shipped runs (1000) are not yet rerun with it; factor `density_authors`"),
    Rule("queue_cpfa, queue_qse, queue_qst, queue_qme, queue_qmt", "controller.cpfa.informed_walk",
         "Hecker & Moses: each informed step turns by a draw of N(0, sigma), sigma = omega + (4 pi - omega) "
         "exp(-lambda_id t) (`sigma`)",
         "`CPFA_controller::Searching`, `GetExponentialDecay`: by w + (2 pi - w) exp(-lambda_id t), w ~ N(0, "
         "omega), a loop about the site (`turn`)",
         "text", "pending, as the row above; factor `cpfa_authors` (both)"),
)


QUEUE_COMPARISON = Comparison(
    name="queue",
    help="queue paper: Table II, Figs 8-10, t-tests",
    default_out="results/queue",
    strategies=QUEUE_STRATEGIES,
    add_arguments=_add_arguments,
    plans=_plans,
    write_report=_write_report,
    claims=_claims,
    rules=QUEUE_RULES,
)
