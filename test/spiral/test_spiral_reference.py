"""reference/spiral_argos.py: their experiment file gets the seed, their printed lines become one
row of our schema, and anything else is one clear line, not a row. Hand-made text throughout (the
shape of what the authors' loop functions print, not their output)."""

from __future__ import annotations

import importlib.util
import json
import stat
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
_spec = importlib.util.spec_from_file_location("spiral_argos", ROOT / "reference" / "spiral_argos.py")
ref = importlib.util.module_from_spec(_spec)
sys.modules["spiral_argos"] = ref
_spec.loader.exec_module(ref)

COMMIT = "a" * 40
XML = """<?xml version="1.0" ?>
<argos-configuration>
  <framework>
    <system threads="0" />
    <experiment length="180"{seed}
                ticks_per_second="32" />
  </framework>
  <loop_functions library="build/source/DSA/libDSA_loop_functions" label="DSA_loop_functions">
    <DDSA FoodItemCount = "40" NumOfRegions = "16" FilenameHeader = "results/x_"/>
  </loop_functions>
  <arena size="8.0, 8.0, 1">
    <distribute>
      <entity quantity="5" max_trials="100"> <!-- the "quantity" matches NumberOfRobots -->
        <foot-bot id="R"><controller config="DSA"/></foot-bot>
      </entity>
    </distribute>
  </arena>
  <!-- <visualization><qt-opengl/></visualization> -->
</argos-configuration>
"""


def output(seed: int = 7, minutes: tuple[int, ...] = (3, 0, 4), collected: int = 9, collision: str = "12.5",
           bots: int = 5, total: int = 40, sim: int = 180, color: bool = False) -> str:
    c, r = ("\x1b[1;32m", "\x1b[0m") if color else ("", "")
    lines = [f"{c}[INFO] Using random seed = {seed}{r}", "Finished Initializing the DDSA"]
    lines += [f"Minute Passed... getSimTimeInSeconds: {60 * (k + 1)}, Food Collected: {n}"
              for k, n in enumerate(minutes)]
    lines += [f"{c}Sim Time(s), Bots, Collected, Total, Collision Time(s), Percentage{r}",
              f"{c}{sim},   {bots},  {collected},\t\t{total},\t\t{collision},\t{100 * collected / total}%{r}"]
    return "\n".join(lines) + "\n"


def test_the_seed_replaces_theirs_or_is_added():
    with_zero = ref.experiment_xml(XML.format(seed=' random_seed="0"'), 11)
    without = ref.experiment_xml(XML.format(seed=""), 11)
    for text in (with_zero, without):
        assert text.count('random_seed="11"') == 1 and 'random_seed="0"' not in text
    with pytest.raises(ref.ReferenceError, match="seed from the clock"):
        ref.experiment_xml(XML.format(seed=""), 0)
    with pytest.raises(ref.ReferenceError, match="one <experiment>"):
        ref.experiment_xml(XML.format(seed="") + '<experiment length="1"/>', 3)


def test_the_file_facts_ignore_comments():
    facts = ref.xml_facts(XML.format(seed=""))
    assert facts == {"length_s": 180, "robots": 5, "resources": 40, "regions": 16}
    no_regions = XML.format(seed="").replace(' NumOfRegions = "16"', "")
    assert ref.xml_facts(no_regions)["regions"] is None
    with pytest.raises(ref.ReferenceError, match="robot quantity"):
        ref.xml_facts(XML.format(seed="").replace('quantity="5"', 'count="5"'))


def test_a_run_becomes_one_row_in_our_schema():
    printed = ref.parse_output(output(color=True))
    assert printed["minutes"] == [3, 0, 4] and printed["seed"] == 7
    facts = {"length_s": 180, "robots": 5, "resources": 40, "regions": 16}
    r = ref.row("mdbsa_c", 1, 16, 7, facts, printed, 2.0, 1.5, {"commit": COMMIT})
    assert (r["robots"], r["regions"], r["resources_delivered"], r["total_resources"]) == (5, 16, 9, 40)
    assert r["resources_per_robot"] == pytest.approx(1.8)
    assert r["resources_collected_pct"] == pytest.approx(22.5)
    assert r["foraging_rate_per_min"] == pytest.approx(3.0)
    assert r["resources_per_robot_per_min"] == [[60.0, 0.6], [120.0, 0.0], [180.0, 0.8]]
    assert r["resources_per_robot_per_min_mean"] == pytest.approx(1.4 / 3, abs=1e-6)
    # they print the summed counter halved: ours is the counter itself, per robot
    assert r["authors_collision_time_per_robot_s"] == pytest.approx(2.5)
    assert r["collision_time_per_robot_s"] == pytest.approx(5.0)
    assert r["collision_time_total_min"] == pytest.approx(25.0 / 60, abs=1e-6)
    assert (r["wall_seconds"], r["cpu_seconds"], r["real_time_factor"]) == (2.0, 1.5, 90.0)
    assert r["reference"] is True and r["mode"] == "reference" and r["commit"] == COMMIT
    assert ref.row("ddsa", 1, None, 7, facts, printed, 2.0, None, {})["regions"] is None


@pytest.mark.parametrize("text, message", [
    (output() + output(), "2 summary headers"),
    (output().replace("Sim Time(s), Bots", "Sim Time, Bots"), "0 summary headers"),
    (output().replace("12.5,", "twelve,"), "line after the summary header"),
    (output().replace("Using random seed = 7", "Using no seed"), "0 random seeds"),
    (output(minutes=(3, 4)).replace("getSimTimeInSeconds: 120", "getSimTimeInSeconds: 150"), "minute line 2"),
    (output(minutes=(5, 5), collected=9), "more resources than"),
])
def test_output_that_is_not_one_run_is_refused(text, message):
    with pytest.raises(ref.ReferenceError, match=message):
        ref.parse_output(text)


@pytest.mark.parametrize("kwargs, message", [
    ({"seed": 8}, "printed seed 8"),
    ({"bots": 6}, "printed 6 robots"),
    ({"sim": 120}, "120 s"),
])
def test_a_run_that_is_not_the_file_it_was_given_is_refused(kwargs, message):
    facts = {"length_s": 180, "robots": 5, "resources": 40, "regions": 16}
    with pytest.raises(ref.ReferenceError, match=message):
        ref.row("mdbsa_d", 1, 16, 7, facts, ref.parse_output(output(**kwargs)), 1.0, 1.0, {})


def test_cells_name_their_files():
    assert ref.xml_name("mdbsa_d", 1, 64) == "experiments/Experiment1_rg64.xml"
    assert ref.xml_name("ddsa", 1, None) == "experiments/Experiment1_rg4.xml"
    assert ref.xml_name("ddsa", 2, 26) == "experiments/Experiment2_r26.xml"
    assert ref.xml_name("mdbsa_c", 3, 250) == "experiments/Experiment3_food250.xml"
    with pytest.raises(ref.ReferenceError, match="no regions"):
        ref.xml_name("ddsa", 1, 16)


def _tree(tmp_path: Path, script: str) -> tuple[Path, Path]:
    """A tree with their experiment-1 file for 16 regions, and a stand-in argos3 printing `script`."""
    tree = tmp_path / "tree"
    (tree / "experiments").mkdir(parents=True)
    (tree / "experiments" / "Experiment1_rg16.xml").write_text(XML.format(seed=' random_seed="0"'))
    argos = tmp_path / "prefix" / "bin" / "argos3"
    argos.parent.mkdir(parents=True)
    argos.write_text("#!/bin/sh\n" + script)
    argos.chmod(argos.stat().st_mode | stat.S_IEXEC)
    return tree, argos


def _main(tree: Path, argos: Path, out: Path, *extra: str) -> int:
    return ref.main(["--argos", str(argos), "--tree", str(tree), "--strategy", "mdbsa_d", "--commit", COMMIT,
                     "--argos-commit", "b" * 40, "--experiment", "1", "--cells", "16", "--out", str(out), *extra])


def test_main_appends_rows_skips_done_runs_and_cleans_up(tmp_path):
    # the stand-in prints the seed its file was given, as ARGoS does
    script = ("seed=$(sed -n 's/.*random_seed=\"\\([0-9]*\\)\".*/\\1/p' \"$4\")\n"
              f"cat <<EOF\n{output(seed=999)}EOF\n").replace("= 999", "= $seed")
    tree, argos = _tree(tmp_path, script)
    out = tmp_path / "results.jsonl"
    assert _main(tree, argos, out, "--seeds", "2") == 0
    rows = [json.loads(line) for line in out.read_text().splitlines()]
    assert all(r["cpu_seconds"] >= 0 for r in rows)
    assert [(r["seed"], r["cell"], r["xml"]) for r in rows] == [
        (1, 16, "Distributed/experiments/Experiment1_rg16.xml"), (2, 16, "Distributed/experiments/Experiment1_rg16.xml")]
    assert _main(tree, argos, out, "--seeds", "3") == 0
    assert [json.loads(line)["seed"] for line in out.read_text().splitlines()] == [1, 2, 3]
    assert sorted(p.name for p in tree.iterdir()) == ["experiments"]


def test_main_says_one_line_and_keeps_what_ran(tmp_path, capsys):
    tree, argos = _tree(tmp_path, "echo 'segfault' >&2\nexit 139\n")
    out = tmp_path / "results.jsonl"
    out.write_text('{"strategy": "mdbsa_d", "experiment": 1, "cell": 16, "seed": 9, "commit": "x"}\n')
    assert _main(tree, argos, out) == 2
    err = capsys.readouterr().err
    assert err.strip().splitlines() == ["reference: experiments/Experiment1_rg16.xml seed 1: argos3 exited 139: segfault"]
    assert len(out.read_text().splitlines()) == 1
    out.write_text("not json\n")
    assert _main(tree, argos, out) == 2
    assert "not a reference row" in capsys.readouterr().err
    assert _main(tree, argos, tmp_path / "o.jsonl", "--cells", "5") == 2
    assert "cells are (4, 16, 64)" in capsys.readouterr().err
