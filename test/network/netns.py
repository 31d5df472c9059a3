"""Hosts on one machine: network namespaces joined by veth links to a switch, for the network tests.

`Testbed` makes, as root, one namespace per host (``sfnet<pid>-<host>``) with an interface
``eth0`` holding 198.18.0.N/24 (RFC 2544's benchmarking range: no real network uses it) and a
``switch`` namespace joining them: a kernel bridge, or with ``shaped=True`` the user-space switch
`linkemu` (this machine's kernel has no netem), whose links `netem` shapes both ways (loss, delay,
jitter) and `partition` cuts. Nothing is made in this machine's own namespace: every veth end is
created inside a namespace of the testbed, so no traffic can leave them.

`Testbed.close` removes what it made by the names it made: it kills every process still inside
its namespaces (``ip netns pids``) and the process groups it started, then deletes the
namespaces (their veth pairs go with them). It runs at the end of the fixture whatever happened;
while a testbed is up, SIGTERM raises KeyboardInterrupt in the main thread, so that it runs then
too and the test session stops (pytest ends its session on KeyboardInterrupt; a SystemExit would
only fail the test at hand and go on to the next). A SIGTERM during `close` is held until the
clean-up is done.
`available` says why namespaces cannot be made here (not root, no ``ip``), for a skip.
"""

from __future__ import annotations

import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
from collections.abc import Sequence
from pathlib import Path

EMULATOR = Path(__file__).with_name("linkemu.py")
SUBNET = "198.18.0"
"""The testbed's /24: RFC 2544 benchmarking addresses, inside the testbed's namespaces only."""
PREFIX = "sfnet"
LINK_UP_WITHIN = 30.0
"""Seconds within which a new testbed's links must be running (`Testbed._wait_running`)."""


def available() -> str | None:
    """Why namespaces cannot be made here, or None."""
    if os.geteuid() != 0:
        return "network namespaces need root (ip netns, veth, AF_PACKET)"
    for tool in ("ip", "ss"):
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

    def __init__(self, names: Sequence[str], shaped: bool = False) -> None:
        self.tag = f"{PREFIX}{os.getpid()}"
        self.switch = f"{self.tag}-switch"
        self.namespaces: list[str] = []
        self.procs: list[subprocess.Popen] = []
        self.address: dict[str, str] = {}
        self.ns: dict[str, str] = {}
        self.shape: dict[str, dict[str, float]] = {}
        self.stats: dict = {}
        """The user-space switch's counters per host port, once closed (`linkemu`)."""
        self._dir = tempfile.mkdtemp(prefix=f"{self.tag}-")
        self._config = os.path.join(self._dir, "links.json")
        self._emulator: subprocess.Popen | None = None
        self._sigterm = signal.signal(signal.SIGTERM, _stop_on_sigterm)
        own = socket.if_nameindex()  # this machine's own namespace: must stay as it is
        try:
            self._add_ns(self.switch)
            if not shaped:
                _ip("ip", "link", "add", "br0", "type", "bridge", ns=self.switch)
                _ip("ip", "link", "set", "br0", "up", ns=self.switch)
            for i, name in enumerate(names):
                ns = f"{self.tag}-{name}"
                self._add_ns(ns)
                # Both ends made inside the testbed's namespaces: nothing in this machine's own.
                _ip("ip", "link", "add", "eth0", "netns", ns, "type", "veth", "peer", "name", name[:15],
                    "netns", self.switch)
                _ip("ip", "link", "set", name[:15], *(() if shaped else ("master", "br0")), "up", ns=self.switch)
                self.address[name] = f"{SUBNET}.{i + 1}"
                self.ns[name] = ns
                _ip("ip", "addr", "add", f"{self.address[name]}/24", "dev", "eth0", ns=ns)
                _ip("ip", "link", "set", "eth0", "up", ns=ns)
                if shaped:  # frames relayed from user space go as they are: real checksums, within the MTU
                    _ip(sys.executable, str(EMULATOR), "offload", "eth0", ns=ns)
            if socket.if_nameindex() != own:
                raise RuntimeError("the testbed changed this machine's own interfaces")
            if shaped:
                self._write_shape()
                self._emulator = self.popen_in(self.switch, [sys.executable, str(EMULATOR), "run", self._config,
                                                             *(n[:15] for n in names)])
            self._wait_running(LINK_UP_WITHIN)
        except BaseException:
            self.close()
            raise

    def _wait_running(self, timeout: float) -> None:
        """Until every host's ``eth0`` is running (operstate up). The kernel reports a new veth's
        carrier a moment after both ends are up, later while it is still tearing down an earlier
        testbed's namespaces; Fast DDS leaves an interface that is not running out, so a node
        bound to its address then fails to create its participant (seen: 4 of 5 network stages
        on clean clones)."""
        deadline = time.monotonic() + timeout
        for host, ns in self.ns.items():
            while True:
                done = subprocess.run(["ip", "-j", "-n", ns, "link", "show", "eth0"], capture_output=True, text=True)
                state = json.loads(done.stdout or "[{}]")[0].get("operstate")
                if state == "UP":
                    break
                if time.monotonic() > deadline:
                    raise RuntimeError(f"{host}'s eth0 not running {timeout:g} s after it was set up ({state})")
                time.sleep(0.02)

    def _add_ns(self, ns: str) -> None:
        _ip("ip", "netns", "add", ns)
        self.namespaces.append(ns)
        _ip("ip", "link", "set", "lo", "up", ns=ns)

    # ------------------------------------------------------------------ processes

    def popen(self, host: str, cmd: Sequence[str], **kwargs) -> subprocess.Popen:
        """`cmd` on `host` (in its namespace), in a process group of its own."""
        return self.popen_in(self.ns[host], cmd, **kwargs)

    def popen_in(self, ns: str, cmd: Sequence[str], **kwargs) -> subprocess.Popen:
        proc = subprocess.Popen(["ip", "netns", "exec", ns, *cmd], start_new_session=True, **kwargs)
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

    def _write_shape(self) -> None:
        with open(self._config + ".new", "w", encoding="utf-8") as f:
            json.dump({h[:15]: v for h, v in self.shape.items()}, f)
        os.replace(self._config + ".new", self._config)  # the switch re-reads it whole

    def netem(self, host: str, loss: float = 0.0, delay: float = 0.0, jitter: float = 0.0) -> None:
        """Shape `host`'s link both ways (needs ``shaped=True``): loss probability, delay and jitter
        [s], e.g. ``netem("hosta", 0.05, 0.020, 0.010)``."""
        assert self._emulator is not None, "a Testbed(shaped=True) shapes its links"
        self.shape[host] = {"loss": loss, "delay": delay, "jitter": jitter}
        self._write_shape()
        time.sleep(0.1)  # the switch checks every 20 ms

    def partition(self, host: str, seconds: float) -> None:
        """Cut `host` off for `seconds` (every frame either way dropped), then shape its link as
        before."""
        before = dict(self.shape.get(host, {}))
        self.netem(host, loss=1.0)
        time.sleep(seconds - 0.1)
        self.netem(host, **before)

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
        held: list[int] = []
        if self._sigterm is not None:  # a SIGTERM now waits for the clean-up
            signal.signal(signal.SIGTERM, lambda *_: held.append(1))
        if self._emulator is not None and self._emulator.poll() is None:
            self._emulator.terminate()  # it writes its counters
            try:
                self._emulator.wait(5)
                with open(self._config + ".stats", encoding="utf-8") as f:
                    self.stats = json.load(f)
            except (subprocess.TimeoutExpired, OSError, ValueError):
                pass
        for sig, grace in ((signal.SIGINT, 5.0), (signal.SIGKILL, 10.0)):  # a chance to leave cleanly first
            for proc in self.procs:
                if proc.poll() is None:
                    try:
                        os.killpg(proc.pid, sig)
                    except ProcessLookupError:
                        pass
            deadline = time.monotonic() + grace
            while any(p.poll() is None for p in self.procs) and time.monotonic() < deadline:
                time.sleep(0.05)
        for pid in self.pids():
            try:
                os.kill(pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
        for ns in reversed(self.namespaces):
            subprocess.run(["ip", "netns", "del", ns], capture_output=True)
        self.namespaces.clear()
        shutil.rmtree(self._dir, ignore_errors=True)
        if self._sigterm is not None:
            signal.signal(signal.SIGTERM, self._sigterm)
            self._sigterm = None
        if held:
            _stop_on_sigterm()


def _stop_on_sigterm(*_: object) -> None:
    raise KeyboardInterrupt("SIGTERM")  # unwinds through the `finally` that closes the testbed


def leftovers() -> list[str]:
    """Namespaces of this process's testbeds that still exist (none after `Testbed.close`)."""
    tag = f"{PREFIX}{os.getpid()}-"
    return [p.name for p in Path("/run/netns").glob(f"{tag}*")] if Path("/run/netns").exists() else []
