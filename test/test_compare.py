"""swarm-compare: run plans, the resumable results file, the tests and reports on synthetic rows,
and one tiny real run through the CLI."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from swarm_controllers.queue.comparison import (
    PAPER_TABLE_II,
    QUEUE_STRATEGIES,
    queue_plans,
    queue_ttests_md,
    write_queue_report,
)
from swarm_controllers.spiral.comparison import (
    SPIRAL_EXPERIMENTS,
    SPIRAL_STRATEGIES,
    resource_layout,
    spiral_mannwhitney_md,
    spiral_plans,
    write_spiral_report,
)
from swarm_controllers.spiral.regions import RegionConfig
from swarm_sim.compare import comparisons
from swarm_sim.compare.cli import main
from swarm_sim.compare.commands import build_parser
from swarm_sim.compare.comparison import Comparison
from swarm_sim.compare.report import fmt_p
from swarm_sim.compare.stats import pair_test, pairwise_tests, stars, values_of
from swarm_sim.compare.sweep import RunPlan, read_results, run_sweep, slim
from swarm_sim.scenario import load_scenario
from swarm_sim.world.resources import place_resources

QUEUE_KEYS = ("resources_collected_pct", "collision_time_per_robot_s", "dropoff_time_mean_s")
SPIRAL_KEYS = ("resources_per_robot", "collision_time_per_robot_s", "foraging_rate_per_min",
               "resources_collected_pct")


def rows_for(strategy, cell, values, keys=QUEUE_KEYS, **extra):
    """One synthetic result row per value, every metric in `keys` set to it."""
    return [{"strategy": strategy, "cell": cell, "seed": i, **{k: float(v) for k in keys}, **extra}
            for i, v in enumerate(values)]


def fake_summary(name, overrides, fields, seed):
    return {
        "scenario": name, "seed": seed, "robots": fields.get("robots__count", 8),
        "resources_delivered": seed, "total_resources": 100, "resources_collected_pct": float(seed),
        "collision_time_per_robot_s": 1.0 + seed, "dropoff_time_mean_s": 2.0,
        "dropoff_times_s": [1.5, 2.5], "collision_time_s_by_robot": {"robot_0": 1.0},
        "oae_by_robot": {"robot_0": 3}, "trips_by_robot": {"robot_0": 1},
        "resources_per_robot": 1.0, "foraging_rate_per_min": 0.5,
    }


def fake_run(job):
    """A run function for the sweep (module level: executors pickle it)."""
    return fake_summary(*job)


class FakeRunner:
    """A run function that records every call (in this process: `LocalExecutor(1)`); raises
    KeyboardInterrupt after `stop_after` results if set, and `fail[name]` for that strategy."""

    def __init__(self, stop_after=None, fail=None):
        self.calls, self.done, self.stop_after, self.fail = [], 0, stop_after, fail or {}

    def __call__(self, job):
        name, overrides, fields, seed = job
        if self.stop_after is not None and self.done >= self.stop_after:
            raise KeyboardInterrupt
        self.calls.append((name, tuple(overrides), dict(fields), seed))
        if name in self.fail:
            raise self.fail[name]
        self.done += 1
        return fake_summary(name, overrides, fields, seed)

    def grouped(self):
        """Calls as (strategy, robots field, seeds) in call order."""
        out = []
        for name, _, fields, seed in self.calls:
            key = (name, fields.get("robots__count"))
            if out and out[-1][:2] == key:
                out[-1] = (*key, out[-1][2] + (seed,))
            else:
                out.append((*key, (seed,)))
        return out


# --------------------------------------------------------------------------- stars and tests


@pytest.mark.parametrize("p, mark", [(0.0, "***"), (0.0009, "***"), (0.001, "**"), (0.0099, "**"),
                                     (0.01, "*"), (0.049, "*"), (0.05, "ns"), (0.9, "ns"),
                                     (math.nan, "n/a")])
def test_stars_thresholds(p, mark):
    assert stars(p) == mark


@given(st.floats(0, 1), st.floats(0, 1))
def test_stars_are_monotone_in_p(p, q):
    rank = {"***": 3, "**": 2, "*": 1, "ns": 0}
    if p <= q:
        assert rank[stars(p)] >= rank[stars(q)]


def test_clearly_different_groups_are_highly_significant_and_identical_ones_are_not():
    rng = np.random.default_rng(1)
    low, high = rng.normal(10, 1, 10), rng.normal(30, 1, 10)
    rows = rows_for("a", 48, low) + rows_for("b", 48, high) + rows_for("c", 48, low)
    for test in ("t", "u"):
        ab, ac = pairwise_tests(rows, "resources_collected_pct", [48], [("a", "b"), ("a", "c")], test)
        assert ab.p < 0.001 and stars(ab.p) == "***"
        assert ac.p > 0.5 and stars(ac.p) == "ns"
        assert ab.stats_a.n == ab.stats_b.n == 10


def test_t_test_needs_two_runs_per_group():
    rows = rows_for("a", 48, [1.0]) + rows_for("b", 48, [2.0, 3.0])
    (t,) = pairwise_tests(rows, "resources_collected_pct", [48], [("a", "b")], "t")
    assert math.isnan(t.p) and stars(t.p) == "n/a"


def test_runs_without_a_dropoff_time_are_left_out():
    rows = rows_for("a", 48, [1.0, 2.0]) + [{"strategy": "a", "cell": 48, "dropoff_time_mean_s": None}]
    assert values_of(rows, "a", 48, "dropoff_time_mean_s") == [1.0, 2.0]


def test_ttests_md_marks_pairs_and_orders_against_the_paper():
    # Synthetic means in the paper's order at 48 robots, CPFA and Q_MT swapped at 64.
    rng = np.random.default_rng(2)
    rows = []
    for i, s in enumerate(QUEUE_STRATEGIES):
        rows += rows_for(s, 48, 10 + 15 * i + rng.normal(0, 1, 8))
        j = {0: 4, 4: 0}.get(i, i)
        rows += rows_for(s, 64, 10 + 15 * j + rng.normal(0, 1, 8))
    text = queue_ttests_md(rows, [48, 64], QUEUE_STRATEGIES)
    assert "| CPFA | Q_MT |" in text and "| *** |" in text and "| ns |" not in text
    order = text.split("## ordering")[1]
    assert "| 48 | CPFA < Q_SE < Q_ST < Q_ME < Q_MT | CPFA < Q_SE < Q_ST < Q_ME < Q_MT | yes | 1.00 |" in order
    assert "| 64 | Q_MT < Q_SE < Q_ST < Q_ME < CPFA |" in order and "| no |" in order


def test_identical_strategies_give_ns_in_the_report():
    rng = np.random.default_rng(3)
    same = rng.normal(40, 3, 10)
    rows = rows_for("queue_qme", 80, same) + rows_for("queue_qmt", 80, same)
    text = queue_ttests_md(rows, [80], ["queue_qme", "queue_qmt"])
    assert text.count("| ns |") == 3 and "| *** |" not in text  # three metrics, one pair


# --------------------------------------------------------------------------- reports


def test_queue_report_writes_tables_plots_and_the_papers_numbers(tmp_path):
    rows = []
    for i, s in enumerate(QUEUE_STRATEGIES):
        rows += rows_for(s, 48, [10.0 * i + 1, 10.0 * i + 3])  # mean 10i+2, std sqrt(2)
    written = write_queue_report(rows, tmp_path, [48, 112], QUEUE_STRATEGIES)
    assert {p.name for p in written} == {"table.md", "ttests.md", "collected.png", "collision_time.png",
                                         "dropoff_time.png"}
    assert all(p.stat().st_size > 0 for p in written)
    table = (tmp_path / "table.md").read_text()
    assert "| Q_MT | 42.00 ± 1.41 (n=2) | 62.94 | — | 82.39 |" in table
    for s in QUEUE_STRATEGIES:
        assert all(f"{v:.2f}" in table for v in PAPER_TABLE_II[s].values())


def test_spiral_report_shows_region_free_ddsa_in_every_cell_and_the_papers_claims(tmp_path):
    rows = rows_for("ddsa", None, [2.0, 2.2, 1.8, 2.1], SPIRAL_KEYS, layout="powerlaw")
    for cell in (4, 16, 64):
        rows += rows_for("mdbsa_c", cell, [2.0, 2.1, 1.9, 2.2], SPIRAL_KEYS, layout="powerlaw")
        rows += rows_for("mdbsa_d", cell, [4.0, 4.4, 3.6, 4.2], SPIRAL_KEYS, layout="powerlaw")
    for r in rows:  # per-minute series: DDSA 1.0 then 0.5 per robot, MDBSA twice the seed's value
        r["resources_per_robot_per_min"] = ([[60.0, 1.0], [120.0, 0.5]] if r["strategy"] == "ddsa"
                                            else [[60.0, 2.0 * r["seed"]], [120.0, 0.0]])
    written = write_spiral_report(rows, tmp_path, 1, [4, 16, 64])
    assert {p.name for p in written} == {"tables.md", "mannwhitney.md", "per_minute.md", "resources_collision.png",
                                         "foraging_rate.png", "foraging_rate_per_minute.png"}
    per_minute = (tmp_path / "per_minute.md").read_text()
    assert per_minute.count("| DDSA (n=4) | 1.00 ± 0.00 | 0.50 ± 0.00 |") == 3  # served in every cell
    assert per_minute.count("| MDBSA-D (n=4) | 3.00 ± 2.58 | 0.00 ± 0.00 |") == 3  # seeds 0-3: 0, 2, 4, 6
    tables = (tmp_path / "tables.md").read_text()
    assert tables.count("2.02 ± 0.17 (median 2.05, n=4)") == 3 * 4  # DDSA, 3 cells, 4 metrics
    mw = (tmp_path / "mannwhitney.md").read_text()
    assert "+101.0 %" in mw and "On average, MDBSA_{Distributed} collected around 101%" in mw
    # MDBSA-D has twice DDSA's mean: +100 % in every cell; U = 16 (all of B above A) for n=4+4.
    assert "| 16 | DDSA | MDBSA-D | 2.05 | 4.10 | +100.0 % | 0.0 |" in mw
    assert "16: +100.0 %" in mw


def test_mann_whitney_marks_separated_groups_and_uses_dash_for_negligible():
    rows = (rows_for("ddsa", 8, np.arange(10.0), SPIRAL_KEYS)
            + rows_for("mdbsa_c", 8, np.arange(10.0), SPIRAL_KEYS)
            + rows_for("mdbsa_d", 8, 100 + np.arange(10.0), SPIRAL_KEYS))
    text = spiral_mannwhitney_md(rows, 2, [8], SPIRAL_STRATEGIES)
    section = text.split("## resources collected per robot")[1].split("##")[0]
    lines = [ln for ln in section.splitlines() if ln.startswith("| 8 |")]
    assert len(lines) == 3
    ddsa_c, ddsa_d, c_d = lines
    assert "| - |" in ddsa_c and "| *** |" in ddsa_d and "| *** |" in c_d


def test_claims_cover_the_cells_they_name():
    from swarm_controllers.spiral.claims import SPIRAL_CLAIMS

    by = {c.id: c for claims in SPIRAL_CLAIMS.values() for c in claims}
    assert by["exp1.C<DDSA.64"].cells == (64,) and by["exp1.C~DDSA"].cells == (4, 16)
    assert 8 not in by["exp2.C<DDSA"].cells and {14, 32} <= set(by["exp2.C<DDSA"].cells)
    assert by["exp2.C<DDSA"].limits() == (-44.0, -24.0)  # Figs. 8 and 9 state both sizes: one claim
    assert len(by) == sum(len(c) for c in SPIRAL_CLAIMS.values())  # ids unique over the experiments


# --------------------------------------------------------------------------- plans


def test_queue_plans_pass_the_swarm_size_as_robots_count_field():
    plans = queue_plans([48, 112], ["queue_cpfa", "queue_qmt"], duration=60.0, overrides=["a.b=1"])
    assert [(p.strategy, p.cell) for p in plans] == [
        ("queue_cpfa", 48), ("queue_qmt", 48), ("queue_cpfa", 112), ("queue_qmt", 112)]
    assert dict(plans[2].fields) == {"robots__count": 112, "sim__duration": 60.0}
    assert plans[0].overrides == ("a.b=1",)
    assert plans[0].settings != plans[2].settings


@pytest.mark.parametrize("experiment", [1, 2, 3])
@pytest.mark.parametrize("layout", ["tiers", "powerlaw", "clustered"])
def test_spiral_plans_load_with_the_papers_settings(experiment, layout):
    exp = SPIRAL_EXPERIMENTS[experiment]
    plans = spiral_plans(experiment, layout=layout)
    distribution = {"tiers": "powerlaw_tiers"}.get(layout, layout)
    for plan in plans:
        # the mdbsa scenarios are written elsewhere; the overrides must hold on the ddsa file
        s = load_scenario("ddsa", plan.overrides, **dict(plan.fields))
        assert s.arena.size == 8.0 and s.resources.distribution == distribution
        assert (s.depot.radius, s.resources.spacing) == (0.18, 0.15)  # the authors' nest, pitch
        setting = {"regions": RegionConfig.of(s).count, "robots": s.robots.count,
                   "resources": s.resources.count}
        if plan.cell is None:
            assert plan.strategy == "ddsa" and experiment == 1
        else:
            assert setting[exp.vary] == plan.cell
        assert (s.robots.count, s.sim.duration) == (
            plan.cell if exp.vary == "robots" else exp.robots, exp.duration_s)
        if exp.vary != "resources":
            assert s.resources.count == exp.resources
        xy = place_resources(s.resources, s.arena, s.depot, np.random.default_rng(0))
        assert xy.shape == (s.resources.count, 2)
    strategies = {(p.strategy, p.cell) for p in plans}
    assert len(strategies) == len(plans)
    if experiment == 1:
        assert ("ddsa", None) in strategies and ("ddsa", 16) not in strategies
        assert {c for s, c in strategies if s == "mdbsa_d"} == {4, 16, 64}


def test_experiment_settings_match_the_papers_tables():
    e = SPIRAL_EXPERIMENTS
    assert (e[1].robots, e[1].resources, e[1].values, e[1].duration_s) == (8, 160, (4, 16, 64), 720.0)
    assert (e[2].values, e[2].resources, e[2].regions, e[2].duration_s) == ((8, 14, 20, 26, 32), 200, 16, 960.0)
    assert (e[3].robots, e[3].values, e[3].regions, e[3].duration_s) == (16, (100, 150, 200, 250, 300), 16, 720.0)


def test_user_set_overrides_win_over_the_experiment():
    (plan, *_) = spiral_plans(2, ["mdbsa_d"], values=[8], overrides=["sim.duration=5"])
    assert load_scenario("ddsa", plan.overrides).sim.duration == 5.0


@given(st.integers(1, 400))
def test_clustered_layout_satisfies_the_cluster_count_rule(count):
    opts = dict(o.split("=") for o in resource_layout(count, "clustered"))
    assert int(opts["resources.clusters"]) * int(opts["resources.cluster_side"]) ** 2 == count
    assert int(opts["resources.count"]) == count


def test_unknown_layout_is_refused():
    with pytest.raises(ValueError, match="layout"):
        resource_layout(100, "spiral")


# --------------------------------------------------------------------------- results file and resume


@given(st.dictionaries(st.sampled_from(["a_by_robot", "collision_time_s_by_robot", "seed", "robots",
                                        "dropoff_times_s", "collision_time_per_robot_s"]),
                       st.integers(0, 5)))
def test_slim_drops_per_robot_and_per_delivery_data_only(summary):
    summary = {k: ([1.0] * v if k == "dropoff_times_s" else v) for k, v in summary.items()}
    row = slim(summary)
    assert not any(k.endswith("_by_robot") for k in row) and "dropoff_times_s" not in row
    for k in ("seed", "robots", "collision_time_per_robot_s"):
        assert row.get(k) == summary.get(k)
    if "dropoff_times_s" in summary:
        assert row["dropoff_count"] == len(summary["dropoff_times_s"])


def test_sweep_appends_each_run_and_resume_skips_finished_runs(tmp_path):
    path = tmp_path / "results.jsonl"
    plans = [RunPlan("queue_cpfa", 48, (), (("robots__count", 48),)),
             RunPlan("queue_qmt", 48, (), (("robots__count", 48),))]
    with pytest.raises(KeyboardInterrupt):
        run_sweep(plans, range(4), path, run=FakeRunner(stop_after=5), log=lambda _: None)
    kept = read_results(path)
    assert [(r["strategy"], r["seed"]) for r in kept] == [("queue_cpfa", s) for s in range(4)] + [("queue_qmt", 0)]
    assert all("oae_by_robot" not in r and r["settings"] == plans[0].settings for r in kept)
    with pytest.raises(FileExistsError):
        run_sweep(plans, range(4), path, run=FakeRunner(), log=lambda _: None)
    again = FakeRunner()
    result = run_sweep(plans, range(4), path, run=again, resume=True, log=lambda _: None)
    assert again.grouped() == [("queue_qmt", 48, (1, 2, 3))]
    assert len(result.rows) == len(read_results(path)) == 8 and not result.failed
    # other settings are other runs: nothing skipped, and the old rows are not reported
    other = [RunPlan("queue_cpfa", 48, ("sim.duration=5",), (("robots__count", 48),))]
    result = run_sweep(other, range(2), path, run=(r := FakeRunner()), resume=True, log=lambda _: None)
    assert len(r.calls) == 2 and len(result.rows) == 2


def test_a_line_cut_short_is_skipped_and_not_glued_to_the_next(tmp_path):
    path = tmp_path / "results.jsonl"
    plan = RunPlan("ddsa", 8)
    good = {"strategy": "ddsa", "settings": plan.settings, "seed": 0, "cell": 8}
    path.write_text(json.dumps(good) + "\n" + '{"strategy": "dd')
    assert read_results(path) == [good]
    run_sweep([plan], range(2), path, run=(r := FakeRunner()), resume=True, log=lambda _: None)
    assert [c[3] for c in r.calls] == [1]
    assert [x["seed"] for x in read_results(path)] == [0, 1]


def test_cli_interrupt_then_resume_then_report(tmp_path, capsys):
    argv = ["queue", "--robots", "48", "64", "--seeds", "3", "--strategies", "queue_cpfa", "queue_qmt",
            "--out", str(tmp_path)]
    assert main(argv, run=FakeRunner(stop_after=4)) == 130
    assert len(read_results(tmp_path / "results.jsonl")) == 4
    assert main(argv, run=FakeRunner()) == 2  # refuses to mix into an existing file
    runner = FakeRunner()
    assert main([*argv, "--resume"], run=runner) == 0
    assert runner.grouped() == [("queue_qmt", 48, (1, 2)), ("queue_cpfa", 64, (0, 1, 2)), ("queue_qmt", 64, (0, 1, 2))]
    assert len(read_results(tmp_path / "results.jsonl")) == 12
    assert (tmp_path / "ttests.md").exists() and (tmp_path / "collision_time.png").exists()
    assert main([*argv, "--overwrite"], run=(r := FakeRunner())) == 0 and len(r.calls) == 12
    assert len(read_results(tmp_path / "results.jsonl")) == 12


def test_cli_refuses_an_unknown_strategy(tmp_path):
    with pytest.raises(SystemExit):
        main(["queue", "--strategies", "queue_xyz", "--out", str(tmp_path)], run=FakeRunner())


def test_one_tiny_real_run_through_the_cli(tmp_path):
    """The real runner end to end: ddsa, 2 robots, 5 s, one seed (about a second)."""
    code = main(["spiral", "--experiment", "2", "--values", "2", "--strategies", "ddsa", "--seeds", "1",
                 "--set", "sim.duration=5", "--out", str(tmp_path)])
    assert code == 0
    (row,) = read_results(tmp_path / "exp2" / "results.jsonl")
    assert (row["strategy"], row["cell"], row["robots"], row["seed"]) == ("ddsa", 2, 2, 0)
    assert row["sim_seconds"] == 5.0 and row["total_resources"] == 200 and row["experiment"] == 2
    assert "collision_time_s_by_robot" not in row and "resources_per_robot" in row
    assert (tmp_path / "exp2" / "mannwhitney.md").exists()


def test_a_failing_run_is_recorded_with_its_error_and_the_sweep_goes_on(tmp_path, capsys):
    runner = FakeRunner(fail={"queue_qse": ModuleNotFoundError("no queue behaviour yet")})
    argv = ["queue", "--robots", "48", "--seeds", "2", "--strategies", "queue_cpfa", "queue_qse",
            "queue_qmt", "--out", str(tmp_path)]
    assert main(argv, run=runner) == 1
    assert "failed.jsonl" in capsys.readouterr().err
    kept = [(r["strategy"], r["seed"]) for r in read_results(tmp_path / "results.jsonl")]
    assert kept == [("queue_cpfa", 0), ("queue_cpfa", 1), ("queue_qmt", 0), ("queue_qmt", 1)]
    failed = read_results(tmp_path / "failed.jsonl")
    assert [(f["strategy"], f["seed"]) for f in failed] == [("queue_qse", 0), ("queue_qse", 1)]
    assert failed[0]["error"].startswith("ModuleNotFoundError: no queue behaviour yet")
    assert (tmp_path / "table.md").exists()
    fixed = FakeRunner()  # --resume tries the failed runs again, and only them
    assert main([*argv, "--resume"], run=fixed) == 0
    assert fixed.grouped() == [("queue_qse", 48, (0, 1))]


# --------------------------------------------------------------------------- comparisons as records


def test_comparisons_are_keyed_by_their_subcommand_names():
    found = comparisons()
    assert {"queue", "spiral", "drtm"} <= set(found)
    assert all(name == c.name for name, c in found.items())
    assert found["queue"].strategies == QUEUE_STRATEGIES and found["spiral"].strategies == SPIRAL_STRATEGIES
    assert found["drtm"].strategies == ("drtm", "artm")
    sub = next(a for a in build_parser(found)._actions if a.dest == "command")
    assert list(sub.choices) == [*found, "all"]


def test_the_cli_runs_any_comparison_it_is_given(tmp_path):
    """A comparison the CLI has never heard of: its own option, plans, output directory and report."""
    seen = {}

    def write_report(rows, out, args, strategies):
        seen.update(rows=rows, out=out, strategies=strategies)
        return [out / "report.md"]

    toy = Comparison(
        name="toy", help="a toy", default_out=str(tmp_path / "toy"), strategies=("a", "b", "c"),
        add_arguments=lambda p: p.add_argument("--size", type=int, default=3),
        plans=lambda args, strategies: [RunPlan(s, args.size, (), (("robots__count", args.size),))
                                        for s in strategies],
        write_report=write_report,
        out_dir=lambda args: args.out / f"size{args.size}",
    )
    runner = FakeRunner()
    assert main(["toy", "--size", "5", "--seeds", "2", "--strategies", "c", "a"], run=runner,
                comparisons={"toy": toy}) == 0
    assert [(c[0], c[3]) for c in runner.calls] == [("a", 0), ("a", 1), ("c", 0), ("c", 1)]  # the declared order
    assert seen["out"] == tmp_path / "toy" / "size5" and seen["strategies"] == ["a", "c"]
    assert [(r["strategy"], r["cell"]) for r in seen["rows"]] == [("a", 5), ("a", 5), ("c", 5), ("c", 5)]
    assert len(read_results(tmp_path / "toy" / "size5" / "results.jsonl")) == 4
    with pytest.raises(SystemExit):
        main(["queue"], run=FakeRunner(), comparisons={"toy": toy})


def test_all_runs_every_comparison_and_writes_one_report(tmp_path):
    """`swarm-compare all`: each registered comparison's reproduction sweeps (queue, spiral 1-3) and a
    plugged-in one, into OUT/<name>/, then REPORT.md with the headline claims, tables and plots."""
    seen = []

    def write_report(rows, out, args, strategies):
        seen.append((out, len(rows)))
        (out / "toy.md").write_text("# Toy tables\n\nours 1.0, paper 2.0\n")
        return [out / "toy.md"]

    toy = Comparison(
        name="toy", help="a future paper", default_out="results/toy", strategies=("ddsa",),
        add_arguments=lambda p: None, plans=lambda args, strategies: [RunPlan("ddsa", 1)],
        write_report=write_report,
    )
    found = {**comparisons(), "toy": toy}
    runner = FakeRunner()
    argv = ["all", "--seeds", "2", "--duration", "5", "--out", str(tmp_path), "--robot-model", "generic"]
    assert main(argv, run=runner, comparisons=found) == 0
    assert {c[0] for c in runner.calls} == {s for c in found.values() for s in c.strategies}
    assert all(c[2]["sim__duration"] == 5 for c in runner.calls if c[2])  # the toy plans set no fields
    for sub in ("queue/table.md", "spiral/exp1/tables.md", "spiral/exp2/mannwhitney.md", "spiral/exp3/tables.md",
                "queue/collected.png", "drtm/table.md", "drtm/food.png"):
        assert (tmp_path / sub).exists(), sub
    assert seen == [(tmp_path / "toy", 2)]
    report = (tmp_path / "REPORT.md").read_text()
    assert "Rehearsal" in report and "## Verdicts" in report
    assert "| queue | generic robot |" in report and "`order.Q_ME<Q_MT`: Q_MT collects more than Q_ME" in report
    assert "`exp2.D>DDSA`" in report and "| toy |" not in report.split("## Levels")[0]  # the toy declares none
    assert "### Resource collection [%] (Table II layout)" in report  # the tables file, nested
    assert "![collected](queue/collected.png)" in report and "#### Toy tables" not in report
    assert "### Toy tables" in report
    # a finished reproduction resumes to nothing new
    again = FakeRunner()
    assert main([*argv, "--resume"], run=again, comparisons=found) == 0 and again.calls == []


def test_all_without_a_robot_model_runs_both_and_puts_the_claims_side_by_side(tmp_path):
    """`swarm-compare all` on the authors' robots (OUT/authors/) and today's (OUT/generic/): one row
    per claim with both results, a count per model, and OUT/CAUSES.md included."""
    found = {"queue": comparisons()["queue"]}
    (tmp_path / "CAUSES.md").write_text("# Why claims do not hold\n\nmeasured: the motion rule\n")
    runner = FakeRunner()
    argv = ["all", "--seeds", "2", "--duration", "5", "--out", str(tmp_path)]
    assert main(argv, run=runner, comparisons=found) == 0
    models = {next((o for o in c[1] if o.startswith("robots.model=")), None) for c in runner.calls}
    assert models == {"robots.model=footbot_cpfa", "robots.model=generic"}  # queue runs on the foot-bot
    for model in ("authors", "generic"):
        assert (tmp_path / model / "queue" / "table.md").exists()
    report = (tmp_path / "REPORT.md").read_text()
    assert "| queue | authors' robots |" in report and "| queue | generic robot |" in report
    row = next(line for line in report.splitlines() if line.startswith("| `T2.Q_MT.48`"))
    assert row.count("|") == 12  # claim, where, paper, then ours, n, ratio, verdict per model
    assert "authors' robots: " in report and "generic robot: " in report and "claims hold" in report
    assert "`controller.queue.join_order`" in report  # text vs the authors' code
    assert "## Why claims do not hold" in report and "measured: the motion rule" in report
    assert "![collected](authors/queue/collected.png)" in report and "![collected](generic/queue/collected.png)" in report
    again = FakeRunner()  # the report alone, from what the results hold: nothing runs
    assert main(["all", "--report-only", "--seeds", "1", "--duration", "5", "--out", str(tmp_path)], run=again,
                comparisons=found) == 0
    assert again.calls == [] and "`swarm-compare all --report-only" in (tmp_path / "REPORT.md").read_text()
    assert "(n=2)" in (tmp_path / "authors" / "queue" / "table.md").read_text()  # both seeds held, though --seeds 1


def test_the_queue_claims_follow_table_ii_and_the_tests():
    from swarm_controllers.queue.claims import QUEUE_CLAIMS
    from swarm_sim.compare.verdicts import CONTRADICTS, HOLDS, LEVEL, NA, evaluate

    assert len([c for c in QUEUE_CLAIMS if c.kind == LEVEL]) == 25 and len({c.id for c in QUEUE_CLAIMS}) == len(QUEUE_CLAIMS)
    rng = np.random.default_rng(1)
    means = {"queue_cpfa": 15.0, "queue_qse": 17.0, "queue_qst": 38.0, "queue_qme": 47.0, "queue_qmt": 63.0}
    rows = [r for s, m in means.items() for r in rows_for(s, 48, rng.normal(m, 0.5, 10))]
    found = {v.claim.id: v for v in evaluate(QUEUE_CLAIMS, rows)}
    assert found["T2.Q_MT.48"].verdict == HOLDS and found["T2.Q_MT.64"].verdict == NA  # no runs at 64
    assert found["order.Q_SE<Q_ST"].cells[0].verdict == HOLDS  # +124 % against Table II's +118 %
    rows = [r for r in rows if r["strategy"] != "queue_cpfa"] + rows_for("queue_cpfa", 48, rng.normal(60, 0.5, 10))
    found = {v.claim.id: v for v in evaluate(QUEUE_CLAIMS, rows)}
    assert found["order.CPFA<Q_SE"].verdict == CONTRADICTS and found["T2.CPFA.48"].verdict == CONTRADICTS


def test_table_ii_ordering_checked_pair_by_pair():
    from swarm_controllers.queue.comparison import ordering_checks

    rng = np.random.default_rng(5)
    means = {"queue_cpfa": 60.0, "queue_qse": 17.0, "queue_qst": 34.0, "queue_qme": 50.0, "queue_qmt": 70.0}
    rows = [r for s, m in means.items() for r in rows_for(s, 48, rng.normal(m, 1.0, 8))]
    checks = dict(ordering_checks(rows, [48], list(means)))
    assert checks["CPFA < Q_SE"][0][1].startswith("reversed") and checks["CPFA < Q_SE"][0][2] is False
    assert checks["Q_SE < Q_ST"][0][1].startswith("holds") and checks["Q_SE < Q_ST"][0][2] is True
    ratio = checks["Q_ST = 2 Q_SE (Table II: x1.9-2.4)"][0]
    assert ratio[2] is True and ratio[1].startswith("holds: x")


def test_a_t_test_between_groups_that_do_not_vary_is_not_applicable():
    """scipy gives p = 0 for two constant groups; the reports must say n/a, not ***."""
    statistic, p = pair_test([1.0, 1.0, 1.0], [2.0, 2.0, 2.0], "t")
    assert math.isnan(statistic) and fmt_p(p) == "n/a" and stars(p) == "n/a"
    assert pair_test([1.0, 1.0, 1.5], [2.0, 2.0, 2.0], "t")[1] < 0.05  # one group varies: a real test
    assert pair_test([1.0, 1.0, 1.0], [2.0, 2.0, 2.0], "u")[1] < 0.05  # a rank test is defined


def test_reports_of_runs_cut_by_duration_say_so(tmp_path):
    argv = ["queue", "--robots", "48", "--seeds", "2", "--strategies", "queue_qmt", "--out", str(tmp_path)]
    assert main(argv, run=FakeRunner()) == 0
    assert "Runs cut short" not in (tmp_path / "table.md").read_text()
    assert main([*argv, "--overwrite", "--duration", "60"], run=FakeRunner()) == 0
    for name in ("table.md", "ttests.md"):
        assert (tmp_path / name).read_text().startswith("> **Runs cut short**: every run here was limited to 60 s")


def test_factor_tables_put_each_factor_beside_the_baseline(tmp_path):
    """`python -m swarm_sim.compare.factors ROOT`: per group, per headline measure, a row per factor
    (the baseline first) and a column per strategy and cell."""
    from swarm_sim.compare.factors import main as factors_main

    group = tmp_path / "queue48"
    for factor, values in (("turn_fast", [50.0, 54.0]), ("baseline", [30.0, 34.0])):
        (group / factor).mkdir(parents=True)
        rows = [{"strategy": "queue_qmt", "cell": 48, "seed": i, "resources_collected_pct": v}
                for i, v in enumerate(values)]
        (group / factor / "results.jsonl").write_text("".join(json.dumps(r) + "\n" for r in rows))
    (group / "README").write_text("- `turn_fast`: a faster turn")
    assert factors_main([str(tmp_path)]) == 0
    text = (tmp_path / "FACTORS.md").read_text()
    assert "## queue48" in text and "- `turn_fast`: a faster turn" in text
    table = text[text.index("(`resources_collected_pct`)"):].splitlines()
    assert table[2] == "| factor | queue_qmt 48 |"
    assert table[4:6] == ["| baseline | 32.00 ± 2.83 (2) |", "| turn_fast | 52.00 ± 2.83 (2) |"]
    extra = {"strategy": "queue_qmt", "cell": 48, "seed": 2, "resources_collected_pct": 90.0}
    with (group / "baseline" / "results.jsonl").open("a") as f:  # a seed the other factor did not run
        f.write(json.dumps(extra) + "\n")
    assert factors_main([str(tmp_path)]) == 0
    assert "| baseline | 32.00 ± 2.83 (2) |" in (tmp_path / "FACTORS.md").read_text()  # compared on common seeds
    assert factors_main([str(tmp_path / "nothing")]) == 2


def test_every_comparison_figure_says_which_robot_ran(tmp_path):
    """The caption under a figure names each run's robot model (from its settings, else its
    scenario's own) and the sweep's --set values; outside a `caption` block nothing is added."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from swarm_sim.compare.report import caption, runs_caption, save_figure

    rows = [{"strategy": "drtm", "settings": json.dumps({"overrides": ["robots.model=footbot_foraging"]})},
            {"strategy": "artm", "settings": json.dumps({"overrides": ["robots.model=generic", "robots.model=khepera3"]})},
            {"strategy": "cpfa", "settings": "not json"}]
    text = runs_caption(rows, ["robots.platform.diameter=0.07"], lambda s: f"own:{s}")
    assert text == "robot: footbot_foraging, khepera3, own:cpfa; --set robots.platform.diameter=0.07"
    fig = plt.figure()
    with caption(text):
        save_figure(fig, tmp_path / "a.png")
    assert [t.get_text() for t in fig.texts] == [text] and (tmp_path / "a.png").stat().st_size > 0
    plain = plt.figure()
    save_figure(plain, tmp_path / "b.png")
    assert plain.texts == []
    plt.close("all")
