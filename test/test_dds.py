"""Loopback-only DDS (launch_py/dds.py + fastdds_loopback.xml) with real processes.

Every DDS process here is a child started with an environment from ``loopback_env``;
this pytest process never imports rclpy. A child stops when its stdin closes (so also
when pytest dies) or after its lifetime; ``finally`` blocks close stdin, wait briefly,
then SIGKILL (harmless: UDP only, nothing left in /dev/shm). Set
``SWARMFORAGE_SKIP_DDS_SCALE=1`` to skip the 40-process test on an overloaded machine.

Run as a script, this file is the child: ``test_dds.py worker INDEX LIFETIME`` publishes
its index a few times on ``/dds_probe`` and subscribes to it; ``test_dds.py workers COUNT
LIFETIME`` forks COUNT such workers after its imports (indices 0..COUNT-1) and prints their
pids; ``test_dds.py checker COUNT TIMEOUT`` subscribes until it has heard indices
0..COUNT-1, prints one JSON line and exits. Sockets are inspected on workers only: they live
until stdin closes.
"""

from __future__ import annotations

import json
import os
import select
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from pathlib import Path
from typing import IO

import pytest

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from launch_py import dds  # noqa: E402

TOPIC = "dds_probe"
SCALE = 40


# --------------------------------------------------------------------------- children


def _child(role: str, number: int, seconds: float) -> int:
    """Worker or checker process body (imports rclpy: only ever runs in a child).

    A worker publishes "INDEX READY" a few times, READY being the CLOCK_MONOTONIC time
    (shared by all processes) at which its node existed. The checker prints, as soon as
    it has heard every index (or at its timeout), one JSON line with the times.
    """
    import rclpy
    from rclpy.context import Context
    from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
    from std_msgs.msg import String

    context = Context()
    rclpy.init(context=context)
    # Lean node (no parameter services, no rosout): the test is about discovery and
    # transport, and each service adds two endpoints to the N x N endpoint discovery.
    node = rclpy.create_node(
        f"dds_probe_{role}_{number}",
        context=context,
        start_parameter_services=False,
        enable_rosout=False,
    )
    ready = time.monotonic()
    # Transient local: a late checker still gets each worker's samples after matching.
    # Deep: one keyless reader history holds the samples of every writer, all replayed at once on
    # matching (3 from each of SCALE workers: 120). With depth 100 a checker spinning slowly on a
    # busy machine lost the oldest before it took them, and with them every sample of a few workers
    # (CI, 2026-11-29: workers 0, 2 and 12 missing after 240 s; a checker made to sleep 5 s before
    # spinning misses worker 0 with depth 100 and hears all 40 with this depth).
    qos = QoSProfile(
        depth=10 * (SCALE + 1),
        reliability=ReliabilityPolicy.RELIABLE,
        durability=DurabilityPolicy.TRANSIENT_LOCAL,
    )
    heard: dict[int, tuple[float, float]] = {}  # index -> (its node ready, first heard)

    def on_message(msg: String) -> None:
        index, sender_ready = msg.data.split()
        heard.setdefault(int(index), (float(sender_ready), time.monotonic()))

    node.create_subscription(String, TOPIC, on_message, qos)
    if role == "worker":
        publisher = node.create_publisher(String, TOPIC, qos)
        sent = [0]

        def publish() -> None:  # a few times, then quiet: the rest is DDS alone
            if sent[0] < 3:
                publisher.publish(String(data=f"{number} {ready}"))
                sent[0] += 1

        node.create_timer(0.5, publish)
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(node)
    stop = threading.Event()
    threading.Thread(target=lambda: (sys.stdin.read(), stop.set()), daemon=True).start()
    wanted = set(range(number)) if role == "checker" else set()
    try:
        while time.monotonic() - ready < seconds and context.ok() and not stop.is_set():
            executor.spin_once(timeout_sec=0.1)
            if wanted and wanted <= heard.keys():
                break
        result = {
            "missing": sorted(wanted - heard.keys()),
            "ready": ready,
            "last_heard": max((t for _, t in heard.values()), default=None),
            # From the moment both nodes existed to the first message heard.
            "max_latency_s": max((t - max(r, ready) for r, t in heard.values()), default=None),
            "publishers": node.count_publishers(TOPIC),
        }
        print(json.dumps(result), flush=True)  # before shutdown, which can hang
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        executor.shutdown()
        node.destroy_node()
        rclpy.try_shutdown(context=context)
    return 0


def _forked_workers(count: int, seconds: float) -> int:
    """`count` workers forked after the imports, as swarm-run starts a process per robot (a
    Python start and its imports each were most of the 40-process test's time); prints their
    pids as one JSON line before any worker prints, then waits for them."""
    import rclpy  # noqa: F401 - imported once, before the forks
    import rclpy.executors  # noqa: F401
    import std_msgs.msg  # noqa: F401

    pids = []
    for index in range(count):
        pid = os.fork()
        if pid == 0:
            code = 1
            try:
                code = _child("worker", index, seconds)
            finally:
                os._exit(code)
        pids.append(pid)
    print(json.dumps({"pids": pids}), flush=True)
    for _ in pids:
        os.wait()
    return 0


def _alive(pid: int) -> bool:
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


# --------------------------------------------------------------------------- helpers


_LOGS: dict[int, IO[str]] = {}  # child pid -> its stderr (a file: a pipe could fill up)


def _spawn(env: Mapping[str, str], role: str, number: int, seconds: float) -> subprocess.Popen[str]:
    log = tempfile.TemporaryFile("w+")
    proc = subprocess.Popen(
        [sys.executable, __file__, role, str(number), str(seconds)],
        env=dict(env),
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        stderr=log,
        text=True,
        start_new_session=True,  # `_children` kills the whole group (forked workers too)
    )
    _LOGS[proc.pid] = log
    return proc


@contextmanager
def _children(grace_s: float = 5.0) -> Iterator[list[subprocess.Popen[str]]]:
    """Collects started children; on exit asks each to stop, then kills stragglers."""
    procs: list[subprocess.Popen[str]] = []
    try:
        yield procs
    finally:
        for p in procs:
            if p.stdin is not None and not p.stdin.closed:
                p.stdin.close()
        deadline = time.monotonic() + grace_s
        for p in procs:
            try:
                p.wait(timeout=max(0.1, deadline - time.monotonic()))
            except subprocess.TimeoutExpired:
                os.killpg(p.pid, signal.SIGKILL)  # e.g. stuck in Fast DDS participant deletion
                p.wait()
            if p.stdout is not None:
                p.stdout.close()
            _LOGS.pop(p.pid).close()


def _result(proc: subprocess.Popen[str], timeout: float) -> dict:
    """The child's JSON line, without waiting for its DDS shutdown."""
    assert proc.stdout is not None
    if select.select([proc.stdout], [], [], timeout)[0]:
        line = proc.stdout.readline()
        if line.startswith("{"):
            return json.loads(line)
    raise AssertionError(
        f"{proc.args[2:]}: no result within {timeout} s (rc={proc.poll()}); "
        f"stderr:\n{_stderr(proc)[-3000:]}"
    )


def _stderr(proc: subprocess.Popen[str]) -> str:
    """What the child wrote to stderr so far (pread: the file offset is shared with it)."""
    fd = _LOGS[proc.pid].fileno()
    return os.pread(fd, os.fstat(fd).st_size, 0).decode(errors="replace")


_RESERVED: dict[int, int] = {}
"""offset -> a domain reserved for this session (its lock held until pytest exits)."""


def _domain(offset: int) -> int:
    """A private domain per test, reserved (`launch_py.dds.reserve_free_domain`), so tests in one
    session, and concurrent sessions, never hear each other."""
    if offset not in _RESERVED:
        _RESERVED[offset], _ = dds.reserve_free_domain()
    return _RESERVED[offset]


def _udp_sockets() -> dict[int, tuple[str, int]]:
    """inode -> (local IP, port) for every UDP socket of this network namespace."""
    table: dict[int, tuple[str, int]] = {}
    for name, family in (("udp", socket.AF_INET), ("udp6", socket.AF_INET6)):
        path = Path("/proc/net") / name
        if not path.exists():
            continue
        for line in path.read_text().splitlines()[1:]:
            fields = line.split()
            ip_hex, port_hex = fields[1].split(":")
            raw = bytes.fromhex(ip_hex)
            # /proc prints each 32-bit word in host (little-endian) order.
            raw = b"".join(raw[i : i + 4][::-1] for i in range(0, len(raw), 4))
            table[int(fields[9])] = (socket.inet_ntop(family, raw), int(port_hex, 16))
    return table


def _socket_inodes(pid: int) -> set[int]:
    inodes = set()
    for fd in Path(f"/proc/{pid}/fd").iterdir():
        try:
            target = os.readlink(fd)
        except OSError:
            continue
        if target.startswith("socket:["):
            inodes.add(int(target[8:-1]))
    return inodes


def _bound_udp(pids: list[int]) -> list[tuple[str, int]]:
    table = _udp_sockets()
    return [table[i] for pid in pids for i in _socket_inodes(pid) if i in table]


def _multicast_ports(domain: int) -> set[int]:
    """The UDP ports a participant of `domain` listens on for multicast (RTPS well-known ports:
    metatraffic 7400 + 250 d, user data + 2)."""
    base = 7400 + 250 * domain
    return {base, base + 2}


# --------------------------------------------------------------------------- tests


def test_loopback_env_always_uses_the_loopback_profile() -> None:
    base = {
        "PATH": "/bin",
        "ROS_LOCALHOST_ONLY": "1",
        "ROS_STATIC_PEERS": "192.0.2.7",
        "ROS_DISCOVERY_SERVER": "192.0.2.7:11811",
    }
    few = dds.loopback_env(150, 1, base)
    many = dds.loopback_env(150, 120, base)
    for env in (few, many):
        assert env["ROS_AUTOMATIC_DISCOVERY_RANGE"] == "SYSTEM_DEFAULT"
        assert Path(env["FASTRTPS_DEFAULT_PROFILES_FILE"]).is_file()
        assert env["RMW_IMPLEMENTATION"] == "rmw_fastrtps_cpp"
        assert env["ROS_DOMAIN_ID"] == "150"
        assert env["PATH"] == "/bin"
        assert not {"ROS_LOCALHOST_ONLY", "ROS_STATIC_PEERS", "ROS_DISCOVERY_SERVER"} & env.keys()


def test_private_domain_id_is_deterministic_and_in_range(monkeypatch) -> None:
    monkeypatch.delenv("ROS_DOMAIN_ID", raising=False)
    lo, hi = dds.DOMAIN_RANGE
    ids = {dds.private_domain_id(seed) for seed in range(500)}
    assert ids == set(range(lo, hi + 1))
    assert dds.private_domain_id(42) == dds.private_domain_id(42)
    monkeypatch.setenv("ROS_DOMAIN_ID", "7")
    assert dds.private_domain_id(42) == 7


def _memory_mib(pid: int) -> tuple[float, float]:
    """(RSS, PSS) of a process; PSS splits shared library pages among their users."""
    fields = {}
    for line in Path(f"/proc/{pid}/smaps_rollup").read_text().splitlines()[1:]:
        key, value = line.split(":", 1)
        fields[key] = int(value.split()[0]) / 1024
    return fields["Rss"], fields["Pss"]


def _assert_loopback_only(pids: list[int], domains: set[int]) -> None:
    """Every UDP socket of ``pids`` is IPv4 bound to 127.0.0.1, so it can neither receive from
    nor send to another host, nor receive multicast (a datagram to a group goes only to sockets
    bound to the group's address or the wildcard), and none is on a multicast port of
    `domains`. Judged by these processes' own sockets (their inodes), not by the machine's
    multicast memberships (/proc/net/igmp): a ros2 daemon with default discovery, or another
    suite, elsewhere on this machine does not change the verdict."""
    bound = _bound_udp(pids)
    assert bound, "no UDP socket found: the processes are not running DDS over UDP"
    assert {ip for ip, _ in bound} == {"127.0.0.1"}, sorted(set(bound))
    multicast = set().union(*(_multicast_ports(d) for d in domains))
    assert not [b for b in bound if b[1] in multicast], sorted(set(bound))


def test_profile_carries_messages_between_two_processes_over_loopback_only() -> None:
    domain = _domain(1)
    env = dds.loopback_env(domain, 2)
    plain = {**env, "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"}  # no profile: as `ros2` CLIs run
    for key in ("FASTRTPS_DEFAULT_PROFILES_FILE", "FASTDDS_DEFAULT_PROFILES_FILE"):
        plain.pop(key)
    with _children() as procs:
        procs.append(worker := _spawn(env, "worker", 0, 30.0))
        procs.append(control := _spawn(plain, "worker", 1, 30.0))
        procs.append(checker := _spawn(env, "checker", 2, 20.0))
        # The profile's processes talk to each other and to LOCALHOST-range ones.
        assert _result(checker, timeout=25.0)["missing"] == []
        # A broken profile is only logged, and Fast DDS falls back to its defaults.
        assert "XMLPARSER" not in _stderr(worker), _stderr(worker)
        _assert_loopback_only([worker.pid], {domain})
        # The socket check can fail: without the profile, Fast DDS binds every interface.
        assert {ip for ip, _ in _bound_udp([control.pid])} - {"127.0.0.1"}


@pytest.mark.alone  # 41 DDS processes (test/conftest.py)
@pytest.mark.slow
@pytest.mark.skipif(
    os.environ.get("SWARMFORAGE_SKIP_DDS_SCALE") == "1",
    reason="SWARMFORAGE_SKIP_DDS_SCALE=1 (machine overloaded)",
)
def test_profile_discovers_40_processes_over_loopback_only(record_property) -> None:
    env = dds.loopback_env(_domain(3), SCALE + 1)
    with _children() as procs:
        t0 = time.monotonic()
        # Generous bounds: the checker answers once it has heard all 40 (seconds on an idle machine),
        # and starting 41 Pythons beside a busy machine's load can take minutes.
        procs.append(forker := _spawn(env, "workers", SCALE, 300.0))
        workers = _result(forker, timeout=250.0)["pids"]
        procs.append(checker := _spawn(env, "checker", SCALE, 240.0))
        result = _result(checker, timeout=250.0)
        assert result["missing"] == [], result
        assert all(_alive(pid) for pid in workers), "a worker died"
        _assert_loopback_only(workers, {_domain(3)})
        memory = [_memory_mib(pid) for pid in workers]
    all_heard_s = result["last_heard"] - t0  # includes starting 41 Pythons on this machine
    rss, pss = (sum(m[i] for m in memory) / SCALE for i in (0, 1))
    record_property("all_heard_after_spawn_s", round(all_heard_s, 2))
    record_property("max_latency_s", round(result["max_latency_s"], 2))
    record_property("rss_mib_mean", round(rss, 1))
    record_property("pss_mib_mean", round(pss, 1))
    print(
        f"\n{SCALE} workers: all heard {all_heard_s:.1f} s after spawning; max node-ready"
        f" -> heard {result['max_latency_s']:.1f} s; per process RSS {rss:.0f} MiB,"
        f" PSS {pss:.0f} MiB"
    )


if __name__ == "__main__":
    if sys.argv[1] == "workers":
        sys.exit(_forked_workers(int(sys.argv[2]), float(sys.argv[3])))
    sys.exit(_child(sys.argv[1], int(sys.argv[2]), float(sys.argv[3])))


def test_a_swarm_run_and_the_test_process_bind_loopback_only(tmp_path) -> None:
    """The whole graph of a default swarm-run (world, controllers, depot manager) and this
    test process's own DDS participant: every UDP socket on 127.0.0.1, no multicast."""
    import rclpy

    context = rclpy.Context()
    rclpy.init(context=context)
    node = rclpy.create_node("binding_probe", context=context)
    cmd = [sys.executable, "-m", "launch_py.run", "--scenario", "queue_qmt", "--robots", "4", "--duration", "600",
           "--bag", str(tmp_path / "bag"), "--domain-id", "auto"]  # ours holds ROS_DOMAIN_ID: a run refuses it
    launcher = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                                start_new_session=True)
    try:
        deadline = time.monotonic() + 60
        pids: list[int] = []
        while time.monotonic() < deadline and len(pids) < 3:  # world, controllers, depot manager
            time.sleep(1.0)
            pids = [int(p.name) for p in Path("/proc").iterdir() if p.name.isdigit() and _parent(int(p.name)) == launcher.pid]
        assert len(pids) >= 3, pids
        time.sleep(3.0)
        run_domain = int(launcher.stdout.readline().rsplit("domain ", 1)[1])  # its first line names it
        _assert_loopback_only([launcher.pid, *pids, os.getpid()], {run_domain, int(os.environ["ROS_DOMAIN_ID"])})
    finally:
        _stop_launcher(launcher)
        node.destroy_node()
        rclpy.try_shutdown(context=context)


def _stop_launcher(launcher: subprocess.Popen) -> None:
    """Ctrl-C to the launcher's process group (it stops its children), SIGKILL after 60 s."""
    os.killpg(launcher.pid, signal.SIGINT)
    try:
        launcher.wait(timeout=60)
    except subprocess.TimeoutExpired:
        os.killpg(launcher.pid, signal.SIGKILL)
        launcher.wait()


def _parent(pid: int) -> int:
    try:
        return int(Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[1])
    except (OSError, IndexError, ValueError):
        return -1


def test_robots_do_not_read_graph_announcements_but_everyone_sees_their_nodes(tmp_path) -> None:
    """With one process per robot, the controllers' `ros_discovery_info` readers match nobody
    (`dds.robot_profile`: N x N pairs become N), yet a `ros2`-style client of the run's discovery
    server still sees every robot's node, as `ros2 node list` / `ros2 param` need."""
    profile = dds.robot_profile()
    assert 'profile_name="ros_discovery_info"' in profile and "<kind>EXCLUSIVE</kind>" in profile
    assert "127.0.0.1" in profile and "<useBuiltinTransports>false</useBuiltinTransports>" in profile
    domain = int(os.environ["ROS_DOMAIN_ID"])
    cmd = [sys.executable, "-m", "launch_py.run", "--scenario", "cpfa", "--robots", "3", "--duration", "600",
           "--controller-processes", "0", "--bag", str(tmp_path / "bag"), "--domain-id", str(domain)]
    launcher = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                                start_new_session=True)
    probe = (
        "import rclpy, time, json\n"
        "rclpy.init()\n"
        "node = rclpy.create_node('graph_probe')\n"
        "names = set()\n"
        "end = time.monotonic() + 60\n"
        "while time.monotonic() < end and not {'/robot_0/controller', '/robot_2/controller'} <= names:\n"
        "    rclpy.spin_once(node, timeout_sec=0.5)\n"
        "    names = {ns.rstrip('/') + '/' + n for n, ns in node.get_node_names_and_namespaces()}\n"
        "print(json.dumps(sorted(names)))\n"
    )
    env = {**dds.loopback_env(domain, processes=2, server_port=dds.discovery_port(domain)), "ROS_SUPER_CLIENT": "TRUE"}
    try:
        deadline = time.monotonic() + 60  # the probe joins once the world is up: before, it would hold
        while not (tmp_path / "bag" / "metadata.yaml").exists():  # the domain and the run refuse it
            assert time.monotonic() < deadline and launcher.poll() is None, launcher.stdout.read()[-2000:]
            time.sleep(0.1)
        out = subprocess.run([sys.executable, "-c", probe], env=env, capture_output=True, text=True, timeout=120)
        names = set(json.loads(out.stdout.strip().splitlines()[-1]))
        assert {"/robot_0/controller", "/robot_1/controller", "/robot_2/controller", "/world"} <= names, names
    finally:
        _stop_launcher(launcher)


# --------------------------------------------------------------------------- one run per domain


def test_a_domain_is_in_use_while_its_discovery_port_is_bound_or_a_participant_is_on_it() -> None:
    domain = _domain(5)
    assert dds.domain_in_use(domain) is None
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as squatter:
        squatter.bind(("127.0.0.1", dds.discovery_port(domain)))
        assert f"discovery server port 127.0.0.1:{dds.discovery_port(domain)}" in dds.domain_in_use(domain)
        with pytest.raises(dds.DomainTaken, match=f"domain {domain} is in use"):
            os.close(dds.claim_domain(domain))
    assert dds.domain_in_use(domain) is None
    with _children() as procs:
        procs.append(worker := _spawn(dds.loopback_env(domain, 2), "worker", 0, 30.0))
        deadline = time.monotonic() + 20
        while dds.domain_in_use(domain) is None and time.monotonic() < deadline and worker.poll() is None:
            time.sleep(0.1)
        assert "a DDS participant is on it" in (dds.domain_in_use(domain) or ""), _stderr(worker)[-2000:]
    assert dds.domain_in_use(domain) is None  # the participant left with its process


def test_a_claimed_domain_is_refused_to_a_second_claim_until_released() -> None:
    domain = _domain(6)
    lock = dds.claim_domain(domain)
    try:
        with pytest.raises(dds.DomainTaken, match="another swarmforage run"):
            dds.claim_domain(domain)
        other, other_lock = dds.claim_free_domain(first=domain)  # auto: the next free one
        os.close(other_lock)
        assert other != domain and dds.DOMAIN_RANGE[0] <= other <= dds.DOMAIN_RANGE[1]
    finally:
        os.close(lock)
    os.close(dds.claim_domain(domain))


def test_the_shared_memory_profile_keeps_udp_on_loopback_and_adds_no_socket() -> None:
    """`with_shared_memory`: the SHM transport beside the UDP one (which stays on the 127.0.0.1
    allow-list, with discovery on 127.0.0.1), and no explicit UDP default locator to hide it."""
    for profile in (dds.robot_profile(), dds.server_profile(7123), dds.PROFILE_PATH.read_text()):
        shm = dds.with_shared_memory(profile)
        assert "<type>SHM</type>" in shm and "<useBuiltinTransports>false</useBuiltinTransports>" in shm
        assert "defaultUnicastLocatorList" not in shm
        assert shm.count("swarmforage_shm") == 2 and shm.count("swarmforage_udp_lo") == 2
        assert "<address>127.0.0.1</address>" in shm.split("interfaceWhiteList")[1]
        assert "metatrafficUnicastLocatorList" in shm and "0.0.0.0" not in shm


def test_dead_shared_memory_files_are_removed_and_live_ones_kept(tmp_path) -> None:
    import fcntl

    for base in ("fastrtps_0123456789abcdef", "fastrtps_port7411", "fastrtps_fedcba9876543210"):
        (tmp_path / base).write_bytes(b"x")
        (tmp_path / f"{base}_el").write_bytes(b"")
    (tmp_path / "sem.fastrtps_port7411_mutex").write_bytes(b"")
    (tmp_path / "other_el").write_bytes(b"")  # not Fast DDS's
    with open(tmp_path / "fastrtps_fedcba9876543210_el", "ab") as live:
        fcntl.flock(live, fcntl.LOCK_EX | fcntl.LOCK_NB)  # its owner lives
        assert dds.remove_dead_shm_files(tmp_path) == 5
    assert sorted(p.name for p in tmp_path.iterdir()) == ["fastrtps_fedcba9876543210", "fastrtps_fedcba9876543210_el",
                                                          "other_el"]


def test_a_reserved_domain_is_never_picked_again_nor_by_auto_but_runs_may_claim_it_by_number() -> None:
    """Concurrent test sessions each reserve their domains (`reserve_free_domain`); ``auto``
    passes over them; the session's own runs claim them by number."""
    first, held = dds.reserve_free_domain()
    try:
        second, other = dds.reserve_free_domain(first=first)
        os.close(other)
        assert second != first
        auto, lock = dds.claim_free_domain(first=first)
        os.close(lock)
        assert auto != first
        os.close(dds.claim_domain(first))  # by number: the session's own run
    finally:
        os.close(held)
    again, lock = dds.reserve_free_domain(first=first)  # released with its descriptor
    os.close(lock)
    assert again == first


def test_discovery_ports_lie_below_every_port_fast_dds_picks_itself() -> None:
    """Below 7000, where each Fast DDS 2.14 participant binds a port of its own counting up (a
    112-process run took 7000-7115, once every discovery port of domains 0-115), and below every
    domain's RTPS ports (7400 + 250 d + ...): another program's participants never hold one."""
    ports = [dds.discovery_port(d) for d in range(dds.MAX_DOMAIN_ID + 1)]
    assert len(set(ports)) == len(ports) and 1024 <= min(ports) and max(ports) < 7000
    assert max(ports) < min(dds.participant_ports(0, 0))


def test_private_domains_keep_a_hundred_and_twenty_processes_below_the_ephemeral_ports() -> None:
    """Every port of a 120-process run on any domain of `DOMAIN_RANGE` lies below Linux's ephemeral
    range, which the kernel hands to any socket on the machine; domain 0 is left to everyone else."""
    lo, hi = dds.DOMAIN_RANGE
    assert 0 < lo <= hi
    assert max(max(dds.participant_ports(d, p)) for d in (lo, hi) for p in range(120)) < dds.EPHEMERAL_FLOOR
    assert max(dds.participant_ports(hi + 2, 0)) >= dds.EPHEMERAL_FLOOR  # the bound is tight
