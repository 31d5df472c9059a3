"""The MDBSA paper's comparison (Lu & Luna 2023, mdbsa_spiral_search.md): experiments 1-3, Figs
6-10 and two-sided Mann-Whitney U tests, our runs next to the differences the paper reports."""

from __future__ import annotations

import argparse
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from swarm_controllers.spiral.claims import SPIRAL_CLAIMS
from swarm_sim.compare.comparison import Comparison, Rule
from swarm_sim.compare.report import boxplot_figure, cell_text, fmt, fmt_p, fmt_pct, label, md_table, save_figure
from swarm_sim.compare.stats import (
    cells_of,
    describe,
    mean_series,
    pairwise_tests,
    pct_change,
    stars,
    values_of,
)
from swarm_sim.compare.sweep import RunPlan, frozen_fields
from swarm_sim.compare.verdicts import relation_marks

SPIRAL_STRATEGIES: tuple[str, ...] = ("ddsa", "mdbsa_c", "mdbsa_d")
SPIRAL_LABELS: dict[str, str] = {"ddsa": "DDSA", "mdbsa_c": "MDBSA-C", "mdbsa_d": "MDBSA-D"}
REGION_FREE: frozenset[str] = frozenset({"ddsa"})
"""Strategies that do not use regions: run once in experiment 1 and shown in every regions
column (the paper: "DDSA's results remained the same as the algorithm does not utilize regions")."""
SPIRAL_PAIRS: tuple[tuple[str, str], ...] = (("ddsa", "mdbsa_c"), ("ddsa", "mdbsa_d"), ("mdbsa_c", "mdbsa_d"))

SPIRAL_METRICS: dict[str, str] = {
    "resources_per_robot": "resources collected per robot",
    "collision_time_per_robot_s": "collision time per robot [s]",
    "foraging_rate_per_min": "foraging rate [resources / min, whole swarm]",
}
SPIRAL_TABLE_EXTRA: dict[str, str] = {"resources_collected_pct": "resources collected [%]"}
PER_MINUTE = "resources_per_robot_per_min"
"""The per-minute series field (`swarm_controllers.spiral.metrics`): Figs. 7 and 9."""
PER_MINUTE_FIGURES: dict[int, str] = {1: "Fig. 7", 2: "Fig. 9"}
"""The paper's per-minute figure of each experiment (experiment 3 has none)."""

POWERLAW_LEVELS = 3
"""`powerlaw` layout: piles of 16 (one 4 x 4), 4 (four 2 x 2) and 1 (sixteen), 48 resources in
piles; the rest of the count is scattered uniformly (see `resource_layout`)."""
LAYOUTS: tuple[str, ...] = ("tiers", "powerlaw", "clustered")
"""`resource_layout` names; the first is the default."""


@dataclass(frozen=True)
class SpiralExperiment:
    """One of the MDBSA paper's experiments (its Tables I-III); `vary` names the swept setting."""

    number: int
    vary: str
    """`regions`, `robots` or `resources`."""
    values: tuple[int, ...]
    robots: int
    resources: int
    regions: int
    duration_s: float
    figures: str


SPIRAL_EXPERIMENTS: dict[int, SpiralExperiment] = {
    # Table I: 8 x 8 m, 8 robots, 160 resources, regions 4/16/64, 12 min, 100 runs.
    1: SpiralExperiment(1, "regions", (4, 16, 64), 8, 160, 16, 720.0, "Figs 6-7"),
    # Table II: 8 robots ... 32 robots in steps of 6, 200 resources, 16 regions, 16 min.
    2: SpiralExperiment(2, "robots", (8, 14, 20, 26, 32), 8, 200, 16, 960.0, "Figs 8-9"),
    # Table III: 16 robots, 100 ... 300 resources in steps of 50, 16 regions, 12 min.
    3: SpiralExperiment(3, "resources", (100, 150, 200, 250, 300), 16, 200, 16, 720.0, "Fig 10"),
}


_EXP3_COLLECTION_QUOTE = (
    "As the total number of resources increases, MDBSA_{Distributed} demonstrates an almost 100% collection rate "
    "on average with a ≈60% to ≈350% improvement in the number of collected resources as the number "
    "of robots increases in comparison to DDSA."
)
def resource_layout(count: int, layout: str = LAYOUTS[0]) -> tuple[str, ...]:
    """``--set`` overrides placing `count` resources in "clusters of different sizes".

    The MDBSA paper only says "randomly distributed [...] as clusters of various sizes".
    `tiers` (default): what the authors ran, their ``PowerLawFoodDistribution``
    (``FoodDistribution = "2"`` in every experiment file of MARSLab-UTRGV/DDSA-Distributed-
    Deterministic-Spiral-Search-Algorithm and MARSLab-UTRGV/Adaptive-Multiple-Distributed-
    Spiral-Search-Algorithm, branch luki-dev): `swarm_sim.world.resources.powerlaw_tiers`,
    e.g. 200 -> 50 each in an 8 x 8 pile, 4 x 4 piles, 2 x 2 piles and singles; 300 takes a
    fifth tier (16 x 16 down to singles, 60 each). The scenario's pitch and nest clearance
    apply. The earlier alternatives, kept by name: `powerlaw`, Hecker & Moses piles with
    `POWERLAW_LEVELS` = 3 (one pile of 16, four of 4, sixteen of 1; 48 resources) and the rest
    scattered uniformly; `clustered`, equal square clusters with clusters * side^2 == count,
    the largest side of 5, 4, 3, 2, 1 that divides (5 x 5 for 100-300 in steps of 50, ten
    4 x 4 for 160).
    """
    if layout == "tiers":
        return ("resources.distribution=powerlaw_tiers", f"resources.count={count}")
    if layout == "powerlaw":
        return ("resources.distribution=powerlaw", f"resources.powerlaw_levels={POWERLAW_LEVELS}",
                f"resources.count={count}")
    if layout == "clustered":
        side = next(s for s in (5, 4, 3, 2, 1) if count % (s * s) == 0)
        return ("resources.distribution=clustered", f"resources.clusters={count // (side * side)}",
                f"resources.cluster_side={side}", f"resources.count={count}")
    raise ValueError(f"unknown resource layout {layout!r} ({', '.join(LAYOUTS)})")


def spiral_plans(
    experiment: int,
    strategies: Sequence[str] = SPIRAL_STRATEGIES,
    *,
    values: Sequence[int] | None = None,
    layout: str = LAYOUTS[0],
    duration: float | None = None,
    overrides: Sequence[str] = (),
) -> list[RunPlan]:
    """The paper's settings for `experiment` as overrides, one plan per strategy and cell."""
    exp = SPIRAL_EXPERIMENTS[experiment]
    extra = (("experiment", experiment), ("layout", layout))
    fields = frozen_fields({"sim__duration": duration})
    plans = []
    for value in values or exp.values:
        setting = {"robots": exp.robots, "resources": exp.resources, "regions": exp.regions, exp.vary: value}
        base = (
            f"robots.count={setting['robots']}",
            f"regions.count={setting['regions']}",
            f"sim.duration={exp.duration_s}",
            *resource_layout(setting["resources"], layout),
        )
        for s in strategies:
            if exp.vary == "regions" and s in REGION_FREE:
                continue
            plans.append(RunPlan(s, value, (*base, *overrides), fields, extra))
    if exp.vary == "regions":  # region-free strategies once, at the experiment's default regions
        base = (f"robots.count={exp.robots}", f"sim.duration={exp.duration_s}",
                *resource_layout(exp.resources, layout))
        plans.extend(RunPlan(s, None, (*base, *overrides), fields, extra)
                     for s in strategies if s in REGION_FREE)
    return plans


def spiral_tables_md(rows: Sequence[dict], experiment: int, cells: Sequence[int],
                     strategies: Sequence[str]) -> str:
    exp = SPIRAL_EXPERIMENTS[experiment]
    lines = [f"# MDBSA paper comparison (Lu & Luna 2023): experiment {experiment} ({exp.figures})", "",
             f"Swept: {exp.vary} = {', '.join(map(str, cells))}. Cells: mean ± sample std "
             "(median, n). The paper gives no tables (box plots of 100 runs only).", ""]
    layouts = sorted({str(r.get("layout")) for r in rows})
    lines += [f"Resource layout: {', '.join(layouts)} (see `swarm_sim.compare.resource_layout`).", ""]
    if exp.vary == "regions":
        lines += ["DDSA does not use regions: the same DDSA runs appear in every column.", ""]
    for metric, title in {**SPIRAL_METRICS, **SPIRAL_TABLE_EXTRA}.items():
        lines += [f"## {title}", ""]
        lines += md_table([f"Algorithm \\ {exp.vary}"] + [str(c) for c in cells],
                          [[label(s, SPIRAL_LABELS)] + [cell_text(describe(values_of(rows, s, c, metric)), median=True)
                                                        for c in cells] for s in strategies]) + [""]
    if experiment == 3:
        lines += [f"> {_EXP3_COLLECTION_QUOTE} (the paper, Fig. 10: compare MDBSA-D's collected %)", ""]
    lines += ["`foraging_rate.png` is the whole-run rate (deliveries / run minutes); the paper's "
              "per-minute curves (Figs. 7 and 9: resources per robot per minute) are "
              "`foraging_rate_per_minute.png` and `per_minute.md`.", ""]
    return "\n".join(lines)


def spiral_per_minute_md(rows: Sequence[dict], experiment: int, cells: Sequence[int],
                         strategies: Sequence[str]) -> str:
    """The data of `foraging_rate_per_minute.png`: resources collected per robot in each minute,
    mean ± sample std over the seeds, one table per cell."""
    exp = SPIRAL_EXPERIMENTS[experiment]
    fig = PER_MINUTE_FIGURES.get(experiment, "no per-minute figure in the paper")
    lines = [f"# MDBSA paper comparison: foraging rate per robot per minute, experiment {experiment} ({fig})", "",
             "Resources delivered per robot in each whole minute (the authors' loop functions count "
             "deliveries per minute and drop a last partial one): mean ± sample std over the seeds.", ""]
    for cell in cells:
        lines += [f"## {exp.vary} = {cell}", ""]
        series = {s: mean_series(rows, s, cell, PER_MINUTE) for s in strategies}
        minutes = max((len(t) for t, _, _ in series.values()), default=0)
        body = []
        for s, (t, mean, std) in series.items():
            n = sum(1 for r in rows if r.get("strategy") == s and r.get("cell") in (cell, None) and r.get(PER_MINUTE))
            body.append([f"{label(s, SPIRAL_LABELS)} (n={n})"]
                        + [f"{fmt(m)} ± {fmt(d)}" for m, d in zip(mean, std)] + [""] * (minutes - len(t)))
        lines += md_table(["minute"] + [str(k + 1) for k in range(minutes)], body) + [""]
    return "\n".join(lines)


def per_minute_figure(rows: Sequence[dict], experiment: int, cells: Sequence[int], strategies: Sequence[str],
                      path: Path) -> Path:
    """One panel per cell: resources per robot per minute, mean over the seeds with a ±1 std
    band, one colour per algorithm (the paper's Figs. 7 and 9)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    exp = SPIRAL_EXPERIMENTS[experiment]
    fig, axes = plt.subplots(1, len(cells), figsize=(3.6 * len(cells), 3.4), squeeze=False, sharey=True)
    for ax, cell in zip(axes[0], cells):
        for j, s in enumerate(strategies):
            t, mean, std = mean_series(rows, s, cell, PER_MINUTE)
            if len(t):
                ax.plot(t / 60.0, mean, color=f"C{j}", marker="o", markersize=3, label=label(s, SPIRAL_LABELS))
                ax.fill_between(t / 60.0, mean - std, mean + std, color=f"C{j}", alpha=0.2)
        ax.set(title=f"{cell} {exp.vary}", xlabel="minute")
        ax.grid(alpha=0.3)
    axes[0][0].set_ylabel("resources per robot per minute")
    if axes[0][0].get_legend_handles_labels()[0]:
        axes[0][0].legend(fontsize="small")
    fig.suptitle(f"Experiment {experiment}: foraging rate per minute "
                 f"(cf. MDBSA paper {PER_MINUTE_FIGURES.get(experiment, 'Fig. 10 setting')})")
    fig.tight_layout()
    save_figure(fig, path)
    plt.close(fig)
    return path


def spiral_mannwhitney_md(rows: Sequence[dict], experiment: int, cells: Sequence[int],
                          strategies: Sequence[str]) -> str:
    exp = SPIRAL_EXPERIMENTS[experiment]
    claims = [c for c in SPIRAL_CLAIMS[experiment] if c.b]
    pairs = [(a, b) for a, b in SPIRAL_PAIRS if a in strategies and b in strategies]
    lines = [f"# MDBSA paper comparison: Mann-Whitney U, experiment {experiment}", "",
             "scipy.stats.mannwhitneyu, two-sided, between each pair per cell. Marks as in the paper: "
             "*** p<0.001, ** p<0.01, * p<0.05, - otherwise (n/a: a group is empty). "
             "`diff` = 100 (mean B − mean A) / mean A. `paper` = what **the paper** reports for that "
             "pair and cell (quotes below), not our data.", ""]
    if experiment == 3:
        lines += ["(The paper ran its tests for experiments 1 and 2 only.)", ""]
    for metric, title in SPIRAL_METRICS.items():
        lines += [f"## {title}", ""]
        body = []
        for t in pairwise_tests(rows, metric, cells, pairs, "u"):
            paper = "; ".join(c.paper_text() for c in claims
                              if c.measure == metric and (c.a, c.b) == (t.a, t.b) and t.cell in c.cells)
            body.append([str(t.cell), label(t.a, SPIRAL_LABELS), label(t.b, SPIRAL_LABELS),
                         fmt(t.stats_a.median), fmt(t.stats_b.median),
                         fmt_pct(pct_change(t.stats_a.mean, t.stats_b.mean)),
                         fmt(t.statistic, 1), fmt_p(t.p), stars(t.p, ns="-"), paper or ""])
        lines += md_table([exp.vary, "A", "B", "median A", "median B", "diff", "U", "p", "sig", "paper"], body)
        lines += [""]
    lines += ["## The paper's reported differences, and ours", ""]
    for c in claims:
        covered = [cell for cell in cells if cell in c.cells]
        ours = []
        for cell in covered:
            a = describe(values_of(rows, c.a, cell, c.measure)).mean
            b = describe(values_of(rows, c.b, cell, c.measure)).mean
            ours.append(pct_change(a, b))
        finite = [x for x in ours if math.isfinite(x)]
        per_cell = ", ".join(f"{cell}: {fmt_pct(x)}" for cell, x in zip(covered, ours)) or "no cell covered"
        avg = f"; mean over these cells {fmt_pct(float(np.mean(finite)))}" if len(finite) > 1 else ""
        lines += [f"- **{SPIRAL_METRICS.get(c.measure, c.measure)}, {label(c.b, SPIRAL_LABELS)} vs "
                  f"{label(c.a, SPIRAL_LABELS)}** — paper: {c.paper_text()}; ours ({exp.vary}) {per_cell}{avg}."]
        lines += [f"  > {c.note}"] if c.note else []
    lines += [""]
    return "\n".join(lines)


def write_spiral_report(rows: Sequence[dict], out: Path, experiment: int, cells: Sequence[int] | None = None,
                        strategies: Sequence[str] = SPIRAL_STRATEGIES) -> list[Path]:
    """tables.md, mannwhitney.md, per_minute.md, the Fig. 6-10 style box plots and the Figs.
    7/9 per-minute curves from result rows."""
    exp = SPIRAL_EXPERIMENTS[experiment]
    cells = list(cells or cells_of(rows))
    out.mkdir(parents=True, exist_ok=True)
    written = [out / "tables.md", out / "mannwhitney.md", out / "per_minute.md"]
    written[0].write_text(spiral_tables_md(rows, experiment, cells, strategies))
    written[1].write_text(spiral_mannwhitney_md(rows, experiment, cells, strategies))
    written[2].write_text(spiral_per_minute_md(rows, experiment, cells, strategies))
    xlabel = f"number of {exp.vary}"
    panels = [(m, SPIRAL_METRICS[m]) for m in ("resources_per_robot", "collision_time_per_robot_s")]
    fig = {1: "Fig. 6", 2: "Fig. 8", 3: "Fig. 10"}[experiment]
    paper = {m: relation_marks(SPIRAL_CLAIMS[experiment], m, rows) for m, _ in panels}
    written.append(boxplot_figure(panels, rows, cells, strategies, SPIRAL_LABELS, xlabel,
                                  f"Experiment {experiment} (cf. MDBSA paper {fig})",
                                  out / "resources_collision.png", notch=True, paper=paper,
                                  paper_text="paper: our A's mean x (1 + its stated difference), band"))
    written.append(boxplot_figure([("foraging_rate_per_min", SPIRAL_METRICS["foraging_rate_per_min"])], rows,
                                  cells, strategies, SPIRAL_LABELS, xlabel,
                                  f"Experiment {experiment}: whole-run foraging rate",
                                  out / "foraging_rate.png", notch=True))
    written.append(per_minute_figure(rows, experiment, cells, strategies, out / "foraging_rate_per_minute.png"))
    return written


def _add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--experiment", type=int, choices=sorted(SPIRAL_EXPERIMENTS), required=True,
                        help="the paper's experiment: 1 (regions, Figs. 6-7), 2 (robots, Figs. 8-9), 3 (resources, Fig. 10)")
    parser.add_argument("--values", type=int, nargs="+",
                        help="the swept setting's values (default: the paper's; regions, robots or resources)")
    parser.add_argument("--layout", choices=LAYOUTS, default=LAYOUTS[0],
                        help="resource layout for 'clusters of different sizes' (default: tiers, "
                             "the authors' power law)")


def _plans(args: argparse.Namespace, strategies: list[str]) -> list[RunPlan]:
    return spiral_plans(args.experiment, strategies, values=args.values, layout=args.layout,
                        duration=args.duration, overrides=args.overrides)


def _out_dir(args: argparse.Namespace) -> Path:
    """One directory per experiment under ``--out``."""
    return args.out / f"exp{args.experiment}"


def _write_report(rows: Sequence[dict], out: Path, args: argparse.Namespace, strategies: list[str]) -> list[Path]:
    exp = SPIRAL_EXPERIMENTS[args.experiment]
    return write_spiral_report(rows, out, args.experiment, args.values or exp.values, strategies)


def _claims(args: argparse.Namespace) -> tuple:
    return SPIRAL_CLAIMS[args.experiment]


SPIRAL_RULES: tuple[Rule, ...] = (
    Rule("mdbsa_c, mdbsa_d", "sensors.proximity_ring.ahead", "not stated",
         "-80..80 deg (`BaseController.cpp:38`, Centralized and Distributed)", "code"),
    Rule("mdbsa_c, mdbsa_d", "regions.order", "not stated",
         "nearest the nest first (`DSA_loop_functions::calRegions`): `nearest_first`", "code"),
    Rule("ddsa", "robots.stop_turn_go.collision_turn", "not stated",
         "away from the readings by 37.5 deg plus their angle (DDSA `BaseController.cpp`): `away`", "code"),
    Rule("mdbsa_c, mdbsa_d", "controller.spiral.partner_radio",
         "Sec. IV: a robot \"can communicate with another robot in the same region\"; they meet (Fig. 5)",
         "partners compare their next points in shared memory (`DSA_controller::ReachSpiralTargets`): `true`",
         "code"),
    Rule("mdbsa_c, mdbsa_d", "controller.spiral.waypoint_gaps", "not stated",
         "a point every 3 search gaps (`generateSpiralPath`): `3`", "code"),
    Rule("mdbsa_c, mdbsa_d", "controller.spiral.next_walk_at", "not stated",
         "a new walk by way of (0.1, 0.1) (`SetTarget(CVector2(0.1, 0.1))`): `depot`", "code"),
    Rule("ddsa", "controller.spiral.ddsa_stem",
         "Sec. III: spirals \"starting from the central collection zone\"; \"each robot moves to its designated "
         "path\"", "every robot's first target is the nest, then its first leg of i gaps out from it over the lower "
         "robots' (DDSA `ReachSpiralTargets`, `generatePattern`): `shared`", "code",
         "ours before 2026-11-29: `own`, robot i starting where robot i-1's first leg ends (factor `ddsa_own_stem`)"),
)


SPIRAL_COMPARISON = Comparison(
    name="spiral",
    help="MDBSA paper: experiments 1-3, Figs 6-10, Mann-Whitney U",
    default_out="results/spiral",
    strategies=SPIRAL_STRATEGIES,
    add_arguments=_add_arguments,
    plans=_plans,
    write_report=_write_report,
    out_dir=_out_dir,
    reproduce=tuple(("--experiment", str(n)) for n in sorted(SPIRAL_EXPERIMENTS)),
    claims=_claims,
    rules=SPIRAL_RULES,
)
