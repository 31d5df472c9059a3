"""Hosts on one machine: network namespaces joined by veth links to a switch, for the network tests.

`Testbed` makes, as root, one namespace per host (``sfnet<pid>-<host>``) with an interface
``eth0`` holding 198.18.0.N/24 (RFC 2544's benchmarking range: no real network uses it) and a
``switch`` namespace holding the bridge that joins them. Nothing is made in this machine's own
namespace: every veth end is created inside a namespace of the testbed, so no traffic can leave
them. `netem` shapes a host's link both ways (loss, delay, jitter), `partition` cuts it.

`Testbed.close` removes what it made by the names it made: it kills every process still inside
its namespaces (``ip netns pids``) and the process groups it started, then deletes the
namespaces (their veth pairs go with them). It runs at the end of the fixture whatever happened.
`available` says why namespaces cannot be made here (not root, no ``ip``), for a skip.
"""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import time
from collections.abc import Sequence
from pathlib import Path

SUBNET = "198.18.0"
"""The testbed's /24: RFC 2544 benchmarking addresses, inside the testbed's namespaces only."""
PREFIX = "sfnet"


def available() -> str | None:
    """Why namespaces cannot be made here, or None."""
    if os.geteuid() != 0:
        return "network namespaces need root (ip netns, veth, tc netem)"
    for tool in ("ip", "tc", "ss"):
        if shutil.which(tool) is None:
            return f"no {tool!r} command (iproute2)"
    probe = f"{PREFIX}{os.getpid()}-probe"
    made = subprocess.run(["ip", "netns", "add", probe], capture_output=True, text=True)
    if made.returncode != 0:
        return f"cannot make a network namespace: {made.stderr.strip()}"
    subprocess.run(["ip", "netns", "del", probe], capture_output=True)
    return None


def _ip(*args: str, ns: str | None = None) -> None:
    cmd = [*(["ip", "netns", "exec", ns] if ns else []), *args]
    done = subprocess.run(cmd, capture_output=True, text=True, timeout=20)
    if done.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)}: {done.stderr.strip()}")


class Testbed:
    """Hosts `names` (each its namespace and address) on one bridge; see the module docstring."""

    __test__ = False  # not a test class (pytest collects Test*)

    def __init__(self, names: Sequence[str]) -> None:
        self.tag = f"{PREFIX}{os.getpid()}"
        self.switch = f"{self.tag}-switch"
        self.namespaces: list[str] = []
        self.procs: list[subprocess.Popen] = []
        self.address: dict[str, str] = {}
        self.ns: dict[str, str] = {}
        try:
            self._add_ns(self.switch)
            _ip("ip", "link", "add", "br0", "type", "bridge", ns=self.switch)
            _ip("ip", "link", "set", "br0", "up", ns=self.switch)
            for i, name in enumerate(names):
                ns = f"{self.tag}-{name}"
                self._add_ns(ns)
                # Both ends made inside the testbed's namespaces: nothing in this machine's own.
                _ip("ip", "link", "add", "eth0", "netns", ns, "type", "veth", "peer", "name", name[:15],
                    "netns", self.switch)
                _ip("ip", "link", "set", name[:15], "master", "br0", "up", ns=self.switch)
                self.address[name] = f"{SUBNET}.{i + 1}"
                self.ns[name] = ns
                _ip("ip", "addr", "add", f"{self.address[name]}/24", "dev", "eth0", ns=ns)
                _ip("ip", "link", "set", "eth0", "up", ns=ns)
        except BaseException:
            self.close()
            raise

    def _add_ns(self, ns: str) -> None:
        _ip("ip", "netns", "add", ns)
        self.namespaces.append(ns)
        _ip("ip", "link", "set", "lo", "up", ns=ns)

    # ------------------------------------------------------------------ processes

    def popen(self, host: str, cmd: Sequence[str], **kwargs) -> subprocess.Popen:
        """`cmd` on `host` (in its namespace), in a process group of its own."""
        proc = subprocess.Popen(["ip", "netns", "exec", self.ns[host], *cmd], start_new_session=True, **kwargs)
        self.procs.append(proc)
        return proc

    def run(self, host: str, cmd: Sequence[str], timeout: float = 20.0) -> str:
        """`cmd`'s output on `host` (RuntimeError if it fails)."""
        done = subprocess.run(["ip", "netns", "exec", self.ns[host], *cmd], capture_output=True, text=True,
                              timeout=timeout)
        if done.returncode != 0:
            raise RuntimeError(f"{host}: {' '.join(cmd)}: {done.stderr.strip()}")
        return done.stdout

    def sockets(self, host: str) -> list[tuple[str, str, str]]:
        """(protocol, local address:port, process) of every socket bound on `host` (``ss -tulpn``)."""
        out = []
        for line in self.run(host, ["ss", "-H", "-tulpn"]).splitlines():
            fields = line.split()
            out.append((fields[0], fields[4], " ".join(fields[6:])))
        return out

    # ------------------------------------------------------------------ links

    def _qdisc(self, host: str, verb: str, netem: Sequence[str]) -> None:
        _ip("tc", "qdisc", verb, "dev", "eth0", "root", "netem", *netem, ns=self.ns[host])
        _ip("tc", "qdisc", verb, "dev", host[:15], "root", "netem", *netem, ns=self.switch)

    def netem(self, host: str, *netem: str) -> None:
        """Shape `host`'s link both ways, e.g. ``netem("b", "loss", "5%", "delay", "20ms", "10ms")``."""
        self._qdisc(host, "replace", netem)

    def partition(self, host: str, seconds: float, *restore: str) -> None:
        """Cut `host` off for `seconds` (every packet either way dropped), then shape its link with
        `restore` again (netem arguments; none: a plain link)."""
        self._qdisc(host, "replace", ("loss", "100%"))
        time.sleep(seconds)
        self._qdisc(host, "replace", restore or ("delay", "0ms"))

    def link_stats(self, host: str) -> dict:
        """The netem qdisc's counters on `host`'s side (sent, dropped packets)."""
        data = json.loads(self.run(host, ["tc", "-s", "-j", "qdisc", "show", "dev", "eth0"]))
        return {k: data[0].get(k) for k in ("packets", "drops")} if data else {}

    # ------------------------------------------------------------------ clean-up

    def pids(self) -> list[int]:
        """Processes inside the testbed's namespaces."""
        out = []
        for ns in self.namespaces:
            done = subprocess.run(["ip", "netns", "pids", ns], capture_output=True, text=True)
            out += [int(p) for p in done.stdout.split()]
        return out

    def close(self) -> None:
        """Every process of the testbed killed, every namespace of it deleted (by its name)."""
        for proc in self.procs:
            if proc.poll() is None:
                try:
                    os.killpg(proc.pid, signal.SIGKILL)
                except ProcessLookupError:
                    pass
        for pid in self.pids():
            try:
                os.kill(pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
        for proc in self.procs:
            try:
                proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                pass
        for ns in reversed(self.namespaces):
            subprocess.run(["ip", "netns", "del", ns], capture_output=True)
        self.namespaces.clear()


def leftovers() -> list[str]:
    """Namespaces of this process's testbeds that still exist (none after `Testbed.close`)."""
    tag = f"{PREFIX}{os.getpid()}-"
    return [p.name for p in Path("/run/netns").glob(f"{tag}*")] if Path("/run/netns").exists() else []
