"""scripts/factors: every paper's factor groups found in its own package, each factor's
overrides a key a shipped scenario takes, and the script's command line as before."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from swarm_sim import registry
from swarm_sim.factor_sweeps import FactorGroup, groups, main, seed_baseline
from swarm_sim.scenario import ScenarioError, load_scenario

REPO = Path(__file__).resolve().parents[1]


def test_each_paper_declares_its_groups_in_its_own_package():
    found = groups()
    assert set(found) == {"queue48", "queue112", "qst48", "qse48", "qse112", "qst112", "qse64", "qst64", "qse80",
                          "qst80", "qse96", "qst96", *(f"q{s}{n}" for s in ("me", "mt") for n in (48, 64, 80, 96, 112)), "cpfa48", "drtm31", "drtm41",
                          "drtm43", "spiral1", "spiral2", "caging", "cagingplan", "cagingdistance"}
    for group in found.values():
        names = [f.name for f in group.factors]
        assert names[0] == "baseline" and len(set(names)) == len(names), group.name


def _accepted_somewhere(override: str) -> bool:
    for name in registry.scenario_files():
        try:
            load_scenario(name, [override])
        except ScenarioError:
            continue
        return True
    return False


def test_every_override_is_a_key_a_shipped_scenario_takes():
    """A factor that sets a key no scenario has (one that moved, say) would sweep nothing new."""
    bad = []
    for group in groups().values():
        for factor in group.factors:
            args = list(factor.args)
            overrides = [args[i + 1] for i, a in enumerate(args) if a == "--set"]
            bad += [f"{group.name}/{factor.name}: {o}" for o in overrides if not _accepted_somewhere(o)]
    assert bad == []
    assert not _accepted_somewhere("depot.dock_distance=0.585")  # the check can fail


def test_the_baseline_is_seeded_from_the_main_sweep_once(tmp_path):
    main_dir, out = tmp_path / "main", tmp_path / "out"
    (main_dir / "p").mkdir(parents=True)
    (main_dir / "p" / "results.jsonl").write_text('{"cell": 1, "x": 1}\n{"cell": 2, "x": 2}\n\n{"cell": 3, "x": 3}\n')
    group = FactorGroup("g", ("p",), "p/results.jsonl", "1,3", ())
    seed_baseline(group, out, main_dir)
    seeded = out / "g" / "baseline" / "results.jsonl"
    assert seeded.read_text() == '{"cell": 1, "x": 1}\n{"cell": 3, "x": 3}\n'
    seeded.write_text("kept\n")
    seed_baseline(group, out, main_dir)
    assert seeded.read_text() == "kept\n"


def test_a_group_of_one_strategy_seeds_only_its_runs(tmp_path):
    main_dir, out = tmp_path / "main", tmp_path / "out"
    (main_dir / "p").mkdir(parents=True)
    (main_dir / "p" / "results.jsonl").write_text(
        '{"cell": 1, "strategy": "a"}\n{"cell": 1, "strategy": "b"}\n{"cell": 2, "strategy": "b"}\n')
    seed_baseline(FactorGroup("g", ("p",), "p/results.jsonl", "1", (), strategies=("b",)), out, main_dir)
    assert (out / "g" / "baseline" / "results.jsonl").read_text() == '{"cell": 1, "strategy": "b"}\n'


def test_the_command_line_refuses_an_unknown_group_in_one_line(capsys):
    assert main(["nowhere"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("factors: unknown group nowhere (known: ")


def test_the_script_still_answers_help():
    result = subprocess.run(["bash", str(REPO / "scripts" / "factors"), "--help"], capture_output=True, text=True, timeout=60,
                            env={"PYTHON": sys.executable, "PATH": "/usr/bin:/bin"})
    assert result.returncode == 0, result.stderr
    assert "--seeds" in result.stdout and "queue48" in result.stdout
