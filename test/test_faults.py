"""Fault injection on the real graph: a server that dies is reported, not hidden. Bounded in
time; every process started is stopped by process group."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path


def _children_running(module: str) -> list[int]:
    out = []
    for p in Path("/proc").iterdir():
        if p.name.isdigit():
            try:
                cmdline = (p / "cmdline").read_bytes().split(b"\0")
            except OSError:
                continue
            if module.encode() in cmdline and str(os.getpid()).encode() not in cmdline:
                out.append(int(p.name))
    return out


def test_a_killed_depot_manager_is_reported_and_fails_the_run(tmp_path):
    domain = os.environ["ROS_DOMAIN_ID"]
    cmd = [sys.executable, "-m", "launch_py.run", "--scenario", "queue_qmt", "--robots", "4", "--duration", "120",
           "--bag", str(tmp_path / "bag"), "--domain-id", domain, "--tick-timeout", "0.5", "--json"]
    launcher = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True)
    try:
        deadline = time.monotonic() + 60
        manager = []
        while time.monotonic() < deadline and not (tmp_path / "bag" / "metadata.yaml").exists():
            time.sleep(0.5)
        time.sleep(1.0)
        manager = [pid for pid in _children_running("depot_manager.node")
                   if Path(f"/proc/{pid}/environ").read_bytes().count(f"ROS_DOMAIN_ID={domain}".encode())]
        assert len(manager) == 1, manager
        os.kill(manager[0], signal.SIGKILL)
        out, err = launcher.communicate(timeout=240)
    finally:
        if launcher.poll() is None:
            os.killpg(launcher.pid, signal.SIGKILL)
            launcher.wait()
    assert launcher.returncode == 3, err[-2000:]
    assert "a server missed" in err
    summary = json.loads(out.strip().splitlines()[-1])
    assert summary["server_stale_ticks"] > 0 and summary["stale_ticks"] == 0
