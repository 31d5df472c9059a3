"""Sweep executors: the local pool and a real Dask LocalCluster on 127.0.0.1 give the same results,
a run that raises is an outcome with its error, and a sweep interrupted on one back-end resumes on
the other."""

from __future__ import annotations

import argparse
import math

import pytest

from swarm_sim.batch import run_one
from swarm_sim.compare.sweep import RunPlan, read_results, run_sweep
from swarm_sim.executors import DaskExecutor, LocalExecutor, add_executor_arguments, executor_from_args

TINY = ("robots.count=2", "sim.duration=4")
PLANS = [RunPlan("ddsa", 2, TINY), RunPlan("cpfa", 2, TINY)]
WALL = ("wall_seconds", "real_time_factor")


def _explode(x):
    if x % 2:
        raise ValueError(f"odd {x}")
    return x * 10


def _same(rows):
    """Rows without the wall-clock fields, keyed by run."""
    return {(r["strategy"], r["seed"]): {k: v for k, v in r.items() if k not in WALL} for r in rows}


@pytest.mark.parametrize("jobs", [1, 2])
def test_a_run_that_raises_is_an_outcome_and_the_others_go_on(jobs):
    outcomes = sorted(LocalExecutor(jobs).map(_explode, range(5)), key=lambda o: o.index)
    assert [o.value for o in outcomes if o.ok] == [0, 20, 40]
    assert [o.error.split(" (at ")[0] for o in outcomes if not o.ok] == ["ValueError: odd 1", "ValueError: odd 3"]


def test_options_pick_the_back_end_and_refuse_a_bad_address(capsys):
    parser = argparse.ArgumentParser()
    add_executor_arguments(parser)
    assert executor_from_args(parser.parse_args(["--jobs", "3"])).workers == 3
    for bad in (["--scheduler", "127.0.0.1:8786"], ["--scheduler", "tcp://h:1", "--jobs", "2"], ["--dask-local", "0"]):
        with pytest.raises(SystemExit):
            parser.parse_args(bad)
    assert "expected tcp://HOST:PORT" in capsys.readouterr().err


def test_dask_local_cluster_matches_the_local_pool_and_resumes_its_sweep(tmp_path):
    seeds = [0, 1]
    pool = run_sweep(PLANS, seeds, tmp_path / "pool" / "results.jsonl", executor=LocalExecutor(2), log=lambda _: None)
    assert len(pool.rows) == 4 and not pool.failed

    # a sweep cut after one run on the pool, finished on Dask
    path = tmp_path / "mixed" / "results.jsonl"
    seen = []

    def cut(job):
        if seen:
            raise KeyboardInterrupt
        seen.append(job)
        return run_one(job)

    with pytest.raises(KeyboardInterrupt):
        run_sweep(PLANS, seeds, path, run=cut, log=lambda _: None)
    assert len(read_results(path)) == 1
    with DaskExecutor(local_workers=2) as dask:
        assert dask.address.startswith("tcp://127.0.0.1:")
        workers = dask.client.scheduler_info()["workers"]
        assert len(workers) == 2 and all(w.startswith("tcp://127.0.0.1:") for w in workers)
        assert all(w["nanny"].startswith("tcp://127.0.0.1:") for w in workers.values())
        resumed = run_sweep(PLANS, seeds, path, executor=dask, resume=True, log=lambda _: None)
        # a run that raises on a Dask worker is recorded and the others finish
        bad = run_sweep([RunPlan("no_such_scenario", 2, TINY), PLANS[0]], [0], tmp_path / "bad" / "results.jsonl",
                        executor=dask, log=lambda _: None)
    assert len(read_results(path)) == 4 and len(resumed.rows) == 4
    assert _same(resumed.rows) == _same(pool.rows)
    assert [r["strategy"] for r in resumed.rows] == ["ddsa", "ddsa", "cpfa", "cpfa"]  # plan order, then seed
    assert all(math.isfinite(r["collision_time_per_robot_s"]) for r in resumed.rows)
    assert [r["strategy"] for r in bad.rows] == ["ddsa"]
    (failure,) = read_results(tmp_path / "bad" / "failed.jsonl")
    assert failure["strategy"] == "no_such_scenario" and "ScenarioError" in failure["error"]


def _children(pid: int) -> set[int]:
    """The live child processes of `pid` (Linux /proc)."""
    from pathlib import Path

    out = set()
    for task in Path(f"/proc/{pid}/task").glob("*"):
        try:
            out |= {int(c) for c in (task / "children").read_text().split()}
        except OSError:
            pass
    return out


def _alive(pid: int) -> bool:
    from pathlib import Path

    try:
        return Path(f"/proc/{pid}/stat").read_text().split(") ", 1)[1][0] != "Z"
    except OSError:
        return False


@pytest.mark.slow
@pytest.mark.parametrize("how", ["SIGTERM", "SIGKILL"])
def test_a_stopped_parallel_sweep_ends_in_one_line_and_leaves_no_worker(tmp_path, how):
    """``swarm-compare --jobs 2`` stopped mid-sweep: SIGTERM ends it with its one "interrupted"
    line, exit code 130 and no worker's traceback; SIGKILL of the parent alone still takes its
    workers with it (PR_SET_PDEATHSIG). Waits for the workers to exist, never for a time."""
    import os
    import signal
    import subprocess
    import sys
    import time

    cmd = [sys.executable, "-m", "swarm_sim.compare.cli", "queue", "--strategies", "queue_qse", "--robots", "48",
           "--seeds", "4", "--jobs", "2", "--duration", "1800", "--out", str(tmp_path)]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True)
    workers: set[int] = set()
    try:
        deadline = time.monotonic() + 120  # a bound on a broken start-up, not a timing assumption
        while len(workers) < 2 and proc.poll() is None and time.monotonic() < deadline:
            workers = _children(proc.pid)
            time.sleep(0.05)
        assert len(workers) >= 2, "the pool's workers never started"
        os.kill(proc.pid, getattr(signal, how))
        out, err = proc.communicate(timeout=120)
        deadline = time.monotonic() + 15  # a run of 1800 s of sim takes longer: a worker left alone outlives it
        while any(_alive(w) for w in workers) and time.monotonic() < deadline:
            time.sleep(0.05)
        assert not any(_alive(w) for w in workers), "a worker outlived the sweep"
        if how == "SIGTERM":
            assert proc.returncode == 130, err
            assert "Traceback" not in err and "Traceback" not in out, err
            assert "interrupted" in err and "--resume" in err
        else:
            assert proc.returncode == -signal.SIGKILL
    finally:
        try:
            os.killpg(proc.pid, signal.SIGKILL)  # the group this test made, by its id
        except ProcessLookupError:
            pass
        proc.wait()
