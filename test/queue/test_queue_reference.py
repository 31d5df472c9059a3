"""reference/queue_argos.py: the experiment file it writes and the line it reads (hand-made text)."""
import importlib.util
import json
from pathlib import Path

import pytest

_PATH = Path(__file__).resolve().parents[2] / "reference" / "queue_argos.py"
_spec = importlib.util.spec_from_file_location("queue_argos", _PATH)
qa = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(qa)

XML = """<argos-configuration><framework><experiment length="0" random_seed="513568" ticks_per_second="32"/>
</framework><arena>
""" + "".join(f'<distribute><entity max_trials="100" quantity="28"><foot-bot id="F{i}-"/></entity></distribute>\n'
              for i in range(4)) + "</arena></argos-configuration>"

PRINTED = ("noise\nResource Collected: 69.00, Collision Time: 21.27, Time Inside RedCircle: 6.33, "
           "Time Took: 18.00 minutes, Random Seed: 123456\n")


def test_the_swarm_is_split_over_the_four_groups_and_the_seed_set():
    out = qa.experiment_xml(XML, 48, 42)
    assert out.count('quantity="12"') == 4 and 'quantity="28"' not in out
    assert 'random_seed="42"' in out and "513568" not in out


def test_the_cpfa_baseline_gets_one_nest_at_the_centre_and_the_papers_18_minutes():
    xml = XML.replace("<arena>", '<loop_functions><settings MaxSimTimeInSeconds="3000" '
                      'NestPosition="0,0.3;0.3,0;0,-0.3;-0.3,0" NestRadius="0.1"/></loop_functions><arena>')
    out = qa.experiment_xml(xml, 48, 42, "queue_cpfa")
    assert 'NestPosition="0,0"' in out and 'MaxSimTimeInSeconds="1080"' in out and 'NestRadius="0.1"' in out
    assert qa.experiment_xml(xml, 48, 42) == qa.experiment_xml(xml, 48, 42, "queue_qst")
    assert 'NestPosition="0,0.3;' in qa.experiment_xml(xml, 48, 42)
    with pytest.raises(qa.ReferenceError, match="one NestPosition attribute, found 0"):
        qa.experiment_xml(XML, 48, 42, "queue_cpfa")


def test_the_cpfa_line_becomes_a_row_without_a_collision_time():
    printed = qa.parse_line("\x1b[1;32mNestRadius=\x1b[0m0.18934\n39.000000, 1080.000000, 123456\n\x1b[0m",
                            "queue_cpfa")
    row = qa.row("queue_cpfa", 48, 123456, printed, 60.0, {})
    assert row["resources_delivered"] == 39 and row["sim_seconds"] == 1080.0
    assert row["authors_collision_time_total_min"] is None and row["authors_collision_time_per_robot_s"] is None
    with pytest.raises(qa.ReferenceError, match="printed 0 'score, seconds, seed' lines"):
        qa.parse_line(PRINTED, "queue_cpfa")


def test_the_cpfa_baseline_needs_the_queue_authors_experiment(tmp_path, capsys):
    tree = tmp_path / "tree"
    tree.mkdir()
    base = ["--argos", "/bin/false", "--tree", str(tree), "--strategy", "queue_cpfa", "--branch", "main",
            "--commit", "b" * 40, "--argos-commit", "a" * 40]
    assert qa.main(base) == 2
    assert "takes --experiment and --experiment-commit" in capsys.readouterr().err
    assert qa.main(base + ["--experiment", str(tmp_path / "x.xml"), "--experiment-commit", "c" * 40]) == 2
    assert "no experiment file" in capsys.readouterr().err


@pytest.mark.parametrize("robots", [50, 3])
def test_a_size_the_four_groups_cannot_hold_equally_is_refused(robots):
    with pytest.raises(qa.ReferenceError, match="multiple of 4"):
        qa.experiment_xml(XML, robots, 1)


def test_a_file_without_four_groups_is_refused_by_name():
    with pytest.raises(qa.ReferenceError, match="4 robot groups, found 3"):
        qa.experiment_xml(XML.replace('quantity="28"', "", 1).replace("<entity max_trials=\"100\" >", ""), 48, 1)


def test_the_printed_line_becomes_a_row_in_our_schema():
    printed = qa.parse_line(PRINTED)
    row = qa.row("queue_qse", 48, 123456, printed, 60.0, {"commit": "c" * 40, "reference": True})
    assert row["resources_delivered"] == 69 and row["total_resources"] == 320
    assert row["resources_collected_pct"] == pytest.approx(21.5625)
    # their print is half the time their rule fired; the row holds the whole, as our count does
    assert row["authors_collision_time_total_min"] == pytest.approx(2 * 21.27)
    assert row["authors_collision_time_per_robot_s"] == pytest.approx(2 * 60 * 21.27 / 48)
    assert row["dropoff_time_mean_s"] == pytest.approx(60 * 6.33)
    assert row["sim_seconds"] == 1080.0 and row["real_time_factor"] == 18.0
    assert row["reference"] is True and row["mode"] == "reference"
    json.dumps(row)


def test_a_run_that_delivered_nothing_has_no_drop_off_time():
    """Their per-delivery circle time of a run without a delivery prints as nan: no number, not NaN."""
    printed = qa.parse_line(PRINTED.replace("69.00", "0.00").replace("6.33", "nan"))
    row = qa.row("queue_qse", 48, 123456, printed, 60.0, {})
    assert row["dropoff_time_mean_s"] is None and row["authors_time_in_circle_per_delivery_min"] is None
    assert row["authors_collision_time_total_min"] == pytest.approx(2 * 21.27)
    json.dumps(row, allow_nan=False)


@pytest.mark.parametrize("text, why", [("", "0 'Resource Collected' lines"),
                                       (PRINTED * 2, "2 'Resource Collected' lines")])
def test_output_without_exactly_one_result_line_is_refused(text, why):
    with pytest.raises(qa.ReferenceError, match=why):
        qa.parse_line(text)


def test_a_run_that_printed_another_seed_is_refused():
    with pytest.raises(qa.ReferenceError, match="printed seed 123456, it was given 7"):
        qa.row("queue_qse", 48, 7, qa.parse_line(PRINTED), 1.0, {})


def test_bad_flags_and_a_foreign_output_file_get_one_line(tmp_path, capsys):
    tree = tmp_path / "tree"
    (tree / "experiments").mkdir(parents=True)
    (tree / qa.EXPERIMENT).write_text(XML)
    base = ["--argos", "/bin/false", "--tree", str(tree), "--strategy", "queue_qse", "--branch", "main",
            "--argos-commit", "a" * 40]
    assert qa.main(base + ["--commit", "nothex"]) == 2
    assert "40 hex digits" in capsys.readouterr().err
    out = tmp_path / "r.jsonl"
    out.write_text("not json\n")
    assert qa.main(base + ["--commit", "b" * 40, "--out", str(out)]) == 2
    assert f"{out}:1: not a reference row" in capsys.readouterr().err
    assert out.read_text() == "not json\n"


def test_a_failing_argos_is_named_and_nothing_is_written(tmp_path, capsys):
    tree = tmp_path / "tree"
    (tree / "experiments").mkdir(parents=True)
    (tree / qa.EXPERIMENT).write_text(XML)
    out = tmp_path / "r.jsonl"
    code = qa.main(["--argos", "/bin/false", "--tree", str(tree), "--strategy", "queue_qse", "--branch", "main",
                    "--commit", "b" * 40, "--argos-commit", "a" * 40, "--robots", "48", "--seeds", "1",
                    "--out", str(out)])
    assert code == 2 and "argos3 exited 1" in capsys.readouterr().err
    assert not out.exists() or out.read_text() == ""
    assert not list(tree.glob(".swarmforage_*"))
