"""A sweep across hosts (issue 26, item 5): a Dask scheduler on one network namespace, a worker on
each of two others, the sweep's client on a fourth; its results equal the local pool's. Every
socket of theirs is bound to its host's address (no 0.0.0.0). Skipped without root."""

from __future__ import annotations

import json
import subprocess
import sys
import time
from pathlib import Path

import pytest
from multihost import node_env
from netns import Testbed, available, leftovers

from swarm_sim.compare.sweep import RunPlan, run_sweep
from swarm_sim.executors import LocalExecutor

TINY = ("robots.count=2", "sim.duration=4")
PLANS = [RunPlan("ddsa", 2, TINY), RunPlan("cpfa", 2, TINY)]
SEEDS = [0, 1]
WALL = ("wall_seconds", "real_time_factor")
PORT = 8786
CLIENT = f"""
import json, sys
from pathlib import Path
from swarm_sim.compare.sweep import RunPlan, run_sweep
from swarm_sim.executors import DaskExecutor
plans = [RunPlan("ddsa", 2, {TINY!r}), RunPlan("cpfa", 2, {TINY!r})]
with DaskExecutor(sys.argv[1]) as dask:
    dask.client.wait_for_workers(2, timeout=120)
    workers = sorted(dask.client.scheduler_info()["workers"])
    sweep = run_sweep(plans, {SEEDS!r}, Path(sys.argv[2]), executor=dask, log=lambda _: None)
    ran = dask.client.run(lambda dask_worker: dask_worker.state.executed_count)
print(json.dumps({{"workers": workers, "ran": ran, "rows": sweep.rows, "failed": len(sweep.failed)}}))
"""


def _same(rows):
    """Rows without the wall-clock fields, keyed by run."""
    return {(r["strategy"], r["seed"]): {k: v for k, v in r.items() if k not in WALL} for r in rows}


def test_a_sweep_on_dask_workers_on_two_hosts_equals_the_local_pool(tmp_path):
    why = available()
    if why is not None:
        pytest.skip(f"no network namespaces here: {why}")
    dask = str(Path(sys.executable).with_name("dask"))
    bed = Testbed(("sched", "hosta", "hostb", "client"))
    try:
        scheduler = f"tcp://{bed.address['sched']}:{PORT}"
        bed.popen("sched", [dask, "scheduler", "--host", bed.address["sched"], "--port", str(PORT),
                            "--no-dashboard", "--no-show", "--dashboard-address", f"{bed.address['sched']}:0"], env=node_env(), stdout=subprocess.DEVNULL,
                  stderr=subprocess.DEVNULL)
        for host in ("hosta", "hostb"):
            bed.popen(host, [dask, "worker", scheduler, "--host", bed.address[host], "--nworkers", "1",
                             "--nthreads", "1", "--no-dashboard", "--name", host,
                             # without it a worker's HTTP server (health, metrics) listens on 0.0.0.0
                             "--dashboard-address", f"{bed.address[host]}:0"], env=node_env(),
                      stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        client = bed.popen("client", [sys.executable, "-c", CLIENT, scheduler, str(tmp_path / "dask.jsonl")],
                           env=node_env(), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        sockets: set[tuple[str, str, str]] = set()
        deadline = time.monotonic() + 240
        while client.poll() is None:
            assert time.monotonic() < deadline, "the sweep did not finish in 240 s"
            for host in bed.address:
                sockets |= {(host, local, proc) for _, local, proc in bed.sockets(host)}
            time.sleep(0.3)
        out, err = client.communicate()
        assert client.returncode == 0, err[-3000:]
        remote = json.loads(out.strip().splitlines()[-1])
    finally:
        bed.close()
        assert leftovers() == []
    listening = {host for host, _, _ in sockets}
    assert {"sched", "hosta", "hostb"} <= listening
    assert [s for s in sockets if s[1].rpartition(":")[0] != bed.address[s[0]]] == []
    assert [w.rpartition(":")[0] for w in remote["workers"]] == [f"tcp://{bed.address[h]}" for h in ("hosta", "hostb")]
    assert sum(remote["ran"].values()) >= 4 and all(n >= 1 for n in remote["ran"].values()), remote["ran"]
    pool = run_sweep(PLANS, SEEDS, tmp_path / "pool.jsonl", executor=LocalExecutor(2), log=lambda _: None)
    assert remote["failed"] == 0 and len(remote["rows"]) == 4
    assert _same(remote["rows"]) == _same(pool.rows)
