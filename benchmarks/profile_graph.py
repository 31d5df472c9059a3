"""Where a graph tick's time goes, process by process and thread by thread (issue 27's profile).

    python benchmarks/profile_graph.py --robots 112 --controller-processes 0 1 --duration 60
    python benchmarks/profile_graph.py --robots 1000 --controller-processes 8 --duration 20 --perf --cprofile

Runs ``swarm-run`` as a user does (lockstep, recording on, discovery server) and measures it from
outside, over a window of steady ticks (from the first progress line after ``--warmup`` sim
seconds to the first after ``--warmup + --window``):

- start-up: wall seconds from launch to the world node up (its topics made) and to every
  controller connected (the first tick);
- CPU per tick of every process of the run, thread by thread (``/proc/PID/task/TID/stat``): the
  Python main thread (which also serialises and sends: publication is synchronous), Fast DDS's
  receive threads (``dds.udp.*``: socket reads, deserialisation into the readers' histories,
  the executor's wake-up; ``dds.shm.*`` with shared memory) and its other threads (``dds.ev``, ``dds.ds_ev``: timers, heartbeats,
  discovery);
- ``--perf``: ``perf record`` of the world and one controller process over the window, samples
  by library: Fast DDS, the ROS layers (rmw, rcl, rclpy), the Python interpreter (our code),
  the kernel (sockets, wake-ups), libc (copies, malloc, locks), pybullet and numba (the world's
  step), zstd (the bag);
- ``--cprofile``: cProfile switched on over the same window in the world and the controller
  processes (forked robot processes too) through a ``sitecustomize`` on PYTHONPATH and two signals
  (nothing in the project changes), its exclusive times summed by category (`CATEGORIES`).
  cProfile makes Python code ~2x slower, and C calls not at all: read its shares as the Python
  side's split, not as times; the executor's C++ ``spin_once`` includes the time a process waits
  for messages (the thread CPU above says how busy it was);
- RSS and PSS of every process at the window's end (per robot node: the controllers' sum / robots;
  PSS counts the pages forked robot processes share once);
- the run's own real-time factor and stale ticks (its JSON summary).
"""

from __future__ import annotations

import argparse
import json
import marshal
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from collections import defaultdict
from pathlib import Path

from profile_batch import scaled_fields

ROOT = Path(__file__).resolve().parents[1]
TICK = 0.1
"""The CPFA scenario's tick [s] (sim.dt); checked against the scenario at start."""
CLK = os.sysconf("SC_CLK_TCK")

SITECUSTOMIZE = """\
import os, signal
_dir = os.environ.get("SWARM_PROFILE_DIR")
if _dir:
    import cProfile
    _prof = cProfile.Profile()
    def _on(*_):
        _prof.enable()
    def _off(*_):
        _prof.disable()
        _prof.dump_stats(os.path.join(_dir, f"{os.getpid()}.prof"))
    signal.signal(signal.SIGUSR1, _on)
    signal.signal(signal.SIGUSR2, _off)
"""
"""Installed in every Python process of the run when ``--cprofile`` is given: SIGUSR1 starts
the profiler on the main thread, SIGUSR2 stops it and writes PID.prof."""

CATEGORIES = (
    # (category, predicate on (file, function)); the first that matches wins.
    ("publish (rmw + Fast DDS: serialise, send)", lambda f, n: f == "~" and "publish" in n),
    ("executor C++: wait (idle included), take, dispatch", lambda f, n: f == "~" and "spin_once" in n),
    ("executor (rclpy Python)", lambda f, n: "rclpy/executors" in f or "rclpy/task" in f),
    ("graph queries (foreign watch, discovery)", lambda f, n: "taint.py" in f or (f == "~" and re.search(
        r"get_count_publishers|get_publishers_info|get_topic_names|get_node_names|get_publisher_count", n))
        or ("rclpy/node.py" in f and re.search(r"get_publishers_info|get_topic_names|count_", n))),
    ("recording (bag, zstd)", lambda f, n: re.search(r"recording/|recorder\.py|world_recording\.py|mcap/", f)
        or (f == "~" and re.search(r"compress|zstd|\.write'", n))),
    ("barrier and loop", lambda f, n: re.search(r"lockstep\.py|world_loop\.py", f)),
    ("intake and guards (callbacks)", lambda f, n: re.search(r"inbound\.py|endpoint\.py|peer_relay\.py|status_watch\.py|auth\.py", f)
        or re.search(r"_on_cmd|_take_cmd|_on_ack|_take_ack|_on_observation", n)),
    ("our CDR codecs", lambda f, n: "swarm_msgs_py/" in f or (f == "~" and re.search(r"Struct|pack|unpack", n))),
    ("world step (physics, sensing, task)", lambda f, n: "swarm_sim/world/" in f or "swarm_sim/tasks/" in f
        or (f == "~" and "pybullet" in n) or "numba" in f),
    ("behaviours", lambda f, n: "swarm_controllers/" in f and "controller_node" not in f or "swarm_sim/behaviour" in f),
    ("rclpy Python (other)", lambda f, n: "rclpy/" in f),
    ("node code (world_node, controller_node, outputs)", lambda f, n: "swarm_sim/nodes/" in f or "controller_node" in f),
)

LIBRARIES = (
    ("Fast DDS", ("libfastrtps", "libfastcdr", "libfoonathan")),
    ("ROS layers (rmw, rcl, rclpy C++)", ("librmw", "librcl", "_rclpy_pybind11", "librcutils", "librosidl", "libtracetools",
                                          "rosidl_typesupport", "__rosidl")),
    ("Python interpreter", ("libpython", "python3", "_struct", "math.cpython", "_pcg64", "bit_generator", "_random")),
    ("kernel", ("[kernel",)),
    ("libc, libstdc++", ("libc.so", "libstdc++", "libm.so", "[vdso]", "libgcc")),
    ("numpy", ("_multiarray", "libscipy_openblas", "libopenblas")),
    ("pybullet", ("pybullet",)),
    ("numba (JIT)", ("[JIT]", "numba", "perf-")),
    ("zstd, zlib, crypto", ("backend_c", "zstd", "libz.", "libcrypto", "_hashlib")),
)


def scenario_sets(robots: int, arena: float | None) -> list[str]:
    out = []
    for key, value in scaled_fields("cpfa", robots, arena).items():
        if key != "robots__count":
            out += ["--set", f"{key.replace('__', '.')}={value}"]
    return out


def process_cpu_s(pid: int) -> float:
    """CPU seconds (user + system) process `pid` has used so far; 0 once it is gone."""
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    except OSError:
        return 0.0
    return (int(fields[11]) + int(fields[12])) / CLK


def tree(root: int) -> dict[int, str]:
    """pid -> role (launcher, world, shards, controllers, server, other) of `root` and its descendants;
the process that forks the robot processes counts as the launcher's; shards: the world's publishing
shards (``--run-arg=--publish-shards --run-arg=K``)."""
    children: dict[int, list[int]] = defaultdict(list)
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                with open(f"/proc/{entry}/stat") as f:
                    children[int(f.read().rsplit(")", 1)[1].split()[1])].append(int(entry))
            except (OSError, IndexError, ValueError):
                continue
    out, stack = {}, [(root, 0)]
    while stack:
        pid, parent = stack.pop()
        stack.extend((child, pid) for child in children.get(pid, []))
        try:
            cmd = Path(f"/proc/{pid}/cmdline").read_bytes().replace(b"\0", b" ").decode()
        except OSError:
            continue
        forking = "controller_node" in cmd and " --fork" in cmd and parent == root  # runs no robot itself
        role = ("world" if "world_node" in cmd else "shards" if "publish_shard" in cmd
                else "launcher" if pid == root or forking
                else "controllers" if "controller_node" in cmd else "server" if "server_node" in cmd else "other")
        out[pid] = role
    return out


def thread_group(comm: str, main: bool) -> str:
    if main:
        return "main thread (Python, publish, take)"
    if comm.startswith(("dds.udp", "dds.shm")):
        return "DDS receive threads (dds.udp, dds.shm)"
    if comm.startswith("dds."):
        return "DDS event/discovery threads"
    return "other threads"


def snapshot(pids: dict[int, str]) -> dict[tuple[int, int], tuple[str, str, float]]:
    """(pid, tid) -> (role, thread group, CPU seconds so far)."""
    out = {}
    for pid, role in pids.items():
        try:
            tids = os.listdir(f"/proc/{pid}/task")
        except OSError:
            continue
        for tid in tids:
            try:
                with open(f"/proc/{pid}/task/{tid}/stat") as f:
                    text = f.read()
            except OSError:
                continue
            comm = text[text.index("(") + 1:text.rindex(")")]
            fields = text.rsplit(")", 1)[1].split()
            cpu = (int(fields[11]) + int(fields[12])) / CLK
            out[(pid, int(tid))] = (role, thread_group(comm, int(tid) == pid), cpu)
    return out


def memory_mb(pid: int) -> tuple[float, float]:
    """(RSS, PSS) of `pid` [MB]: PSS splits the pages forked robot processes share with their
    parent (and libraries shared by all) among their users, so PSS adds up to the machine's use."""
    out = [0.0, 0.0]
    try:
        for line in Path(f"/proc/{pid}/smaps_rollup").read_text().splitlines():
            for i, key in enumerate(("Rss:", "Pss:")):
                if line.startswith(key):
                    out[i] = int(line.split()[1]) / 1024
    except OSError:
        pass
    return out[0], out[1]


def classify(predicates, key: str) -> str:
    for name, match in predicates:
        if any(m in key for m in match):
            return name
    return "other"


def perf_libraries(data: Path) -> dict[str, float]:
    """Share of `data`'s samples per library group (`LIBRARIES`)."""
    text = subprocess.run(["perf", "report", "-i", str(data), "--stdio", "--sort", "dso"],
                          capture_output=True, text=True).stdout
    out: dict[str, float] = defaultdict(float)
    for line in text.splitlines():
        m = re.match(r"\s+([\d.]+)%\s+(\S.*)$", line)
        if m:
            out[classify(LIBRARIES, m.group(2))] += float(m.group(1))
    return out


def cprofile_categories(files: list[Path], top: int) -> tuple[dict[str, float], list[tuple[float, str, str]]]:
    """Exclusive seconds of the profiled code by category (`CATEGORIES`), summed over `files`,
    and the `top` functions (seconds, category, function)."""
    out: dict[str, float] = defaultdict(float)
    functions: dict[tuple[str, str], float] = defaultdict(float)
    for path in files:
        with open(path, "rb") as f:
            stats = marshal.load(f)
        for (file, line, name), (_, _, tottime, _, _) in stats.items():
            category = next((c for c, match in CATEGORIES if match(file, name)), "other")
            out[category] += tottime
            functions[(category, f"{file.split('site-packages/')[-1].split('wt-scale/')[-1]}:{line} {name}")] += tottime
    ranked = sorted(((s, c, f) for (c, f), s in functions.items()), reverse=True)[:top]
    return out, ranked


def one_run(args: argparse.Namespace, robots: int, processes: int) -> dict:
    tmp = Path(tempfile.mkdtemp(prefix="profile-graph-"))  # the bag, profiles, perf data
    try:
        return measure(args, robots, processes, tmp)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def measure(args: argparse.Namespace, robots: int, processes: int, tmp: Path) -> dict:
    arena = dict(args.arena).get(robots)
    env = dict(os.environ)
    if args.cprofile:
        (tmp / "site").mkdir()
        (tmp / "site" / "sitecustomize.py").write_text(SITECUSTOMIZE)
        (tmp / "prof").mkdir()
        env["PYTHONPATH"] = os.pathsep.join([str(tmp / "site"), str(ROOT), env.get("PYTHONPATH", "")])
        env["SWARM_PROFILE_DIR"] = str(tmp / "prof")
    cmd = [sys.executable, "-m", "launch_py.run", "--scenario", "cpfa", "--robots", str(robots),
           "--duration", str(args.duration), "--controller-processes", str(processes), "--bag", str(tmp / "bag"),
           "--json", "--tick-timeout", str(args.tick_timeout), *scenario_sets(robots, arena), *args.set,
           *args.run_arg]
    t0 = time.perf_counter()
    proc = subprocess.Popen(cmd, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, env=env)
    result: dict = {"robots": robots, "processes": processes, "arena": arena}
    start = end = None
    perf: list[subprocess.Popen] = []
    lines: list[str] = []
    assert proc.stdout is not None
    for line in proc.stdout:
        lines.append(line)
        now = time.perf_counter() - t0
        if line.startswith("[world] up") and "up_s" not in result:
            result["up_s"] = now
        if re.search(r"(\d+)/(\d+) controllers connected after [\d.]+ s: starting", line):
            result["connected_s"] = now
            result["connected_line"] = line.strip()
        m = re.match(r"\[world\] t=\s*([\d.]+)/", line)
        if not m:
            continue
        t = float(m.group(1))
        if start is None and t >= args.warmup:
            pids = tree(proc.pid)
            start = (t, time.perf_counter(), snapshot(pids))
            if args.cprofile:
                for pid, role in pids.items():
                    if role in ("world", "controllers"):
                        os.kill(pid, signal.SIGUSR1)
            if args.perf:
                world = [p for p, r in pids.items() if r == "world"]
                ctrl = sorted(p for p, r in pids.items() if r == "controllers")
                ctrl = ctrl[:1]
                for label, pid in (("world", world[0]), ("controller", ctrl[0])):
                    perf.append(subprocess.Popen(["perf", "record", "-F", "499", "-e", "cpu-clock", "-o",
                                                  str(tmp / f"{label}.perf"), "-p", str(pid)],
                                                 stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        elif start is not None and end is None and t >= args.warmup + args.window:
            pids = tree(proc.pid)
            end = (t, time.perf_counter(), snapshot(pids))
            for p in perf:
                p.send_signal(signal.SIGINT)
            if args.cprofile:
                for pid, role in pids.items():
                    if role in ("world", "controllers"):
                        os.kill(pid, signal.SIGUSR2)
            result["rss_mb"] = {pid: (role, *memory_mb(pid)) for pid, role in pids.items()}
    proc.wait()
    for p in perf:
        p.wait()
    result["wall_s"] = time.perf_counter() - t0
    summary = [line for line in lines if line.startswith("{")]  # swarm-run's --json line (verdicts follow it)
    try:
        result["summary"] = json.loads(summary[-1])
    except (ValueError, IndexError):
        result["summary"] = {}
        print("".join(lines[-20:]), file=sys.stderr)
    if start is None or end is None:
        result["error"] = "the run ended before the window did (give a longer --duration)"
        return result
    ticks = round((end[0] - start[0]) / TICK)
    result["ticks"] = ticks
    result["window_wall_s"] = end[1] - start[1]
    cpu: dict[tuple[str, str], float] = defaultdict(float)
    for key, (role, group, seconds) in end[2].items():
        before = start[2].get(key)
        cpu[(role, group)] += seconds - (before[2] if before else 0.0)
    result["cpu_ms_per_tick"] = {f"{r}|{g}": 1e3 * s / ticks for (r, g), s in cpu.items()}
    if args.perf:
        result["perf"] = {label: perf_libraries(tmp / f"{label}.perf") for label in ("world", "controller")}
    if args.cprofile:
        time.sleep(0.5)
        world = [tmp / "prof" / f"{p}.prof" for p, (r, *_) in result["rss_mb"].items() if r == "world"]
        ctrl = [tmp / "prof" / f"{p}.prof" for p, (r, *_) in result["rss_mb"].items() if r == "controllers"]
        result["cprofile"] = {"world": cprofile_categories([f for f in world if f.exists()], args.top),
                              "controllers": cprofile_categories([f for f in ctrl if f.exists()], args.top)}
    return result


def report(result: dict) -> None:
    n, k = result["robots"], result["processes"]
    s = result["summary"]
    label = f"{n} robots, {'one process per robot' if k == 0 else f'{k} controller process(es)'}"
    print(f"\n== {label}" + (f", {result['arena']:g} x {result['arena']:g} m" if result["arena"] else ""))
    print(f"start-up: world up {result.get('up_s', float('nan')):.1f} s, all connected "
          f"{result.get('connected_s', float('nan')):.1f} s after launch; run: rtf {s.get('real_time_factor')}x, "
          f"stale {s.get('stale_ticks')}, whole run {result['wall_s']:.1f} s wall")
    if "error" in result:
        print(result["error"])
        return
    ticks = result["ticks"]
    print(f"window: {ticks} ticks in {result['window_wall_s']:.1f} s wall "
          f"({ticks * TICK / result['window_wall_s']:.2f}x)")
    cpu = result["cpu_ms_per_tick"]
    roles = [r for r in ("world", "shards", "controllers", "server", "launcher", "other") if any(c.startswith(r + "|") for c in cpu)]
    groups = sorted({c.split("|")[1] for c in cpu})
    print("CPU ms per tick | " + " | ".join(roles))
    for g in groups:
        print(f"  {g:38s} | " + " | ".join(f"{cpu.get(f'{r}|{g}', 0.0):7.2f}" for r in roles))
    print(f"  {'total':38s} | " + " | ".join(f"{sum(v for c, v in cpu.items() if c.startswith(r + '|')):7.2f}"
                                             for r in roles) + f"   (all: {sum(cpu.values()):.2f} ms, "
          f"wall {1e3 * result['window_wall_s'] / ticks:.2f} ms a tick)")
    mem = result["rss_mb"]
    for i, kind in ((0, "RSS"), (1, "PSS")):
        world = sum(m[i] for r, *m in mem.values() if r == "world")
        ctrl = [m[i] for r, *m in mem.values() if r == "controllers"]
        print(f"{kind}: world {world:.0f} MB; {len(ctrl)} controller process(es) {sum(ctrl):.0f} MB "
              f"({sum(ctrl) / max(len(ctrl), 1):.1f} MB each, {sum(ctrl) / n:.2f} MB per robot node); "
              f"all processes {sum(m[i] for _, *m in mem.values()):.0f} MB")
    for label, shares in result.get("perf", {}).items():
        print(f"perf, {label} process, share of samples: " + ", ".join(
            f"{name} {pct:.0f} %" for name, pct in sorted(shares.items(), key=lambda x: -x[1]) if pct >= 0.5))
    for label, (cats, ranked) in result.get("cprofile", {}).items():
        total = sum(cats.values())
        if total:
            print(f"cProfile, {label}, exclusive time by category: " + ", ".join(
                f"{name} {100 * v / total:.0f} %" for name, v in sorted(cats.items(), key=lambda x: -x[1])
                if v / total >= 0.01))
            for seconds, category, function in ranked:
                print(f"    {100 * seconds / total:4.1f} %  {function[:110]}  [{category}]")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robots", type=int, nargs="+", default=[112])
    parser.add_argument("--controller-processes", type=int, nargs="+", default=[0, 1],
                        help="splits to profile, each for every --robots (0: one process per robot)")
    parser.add_argument("--duration", type=float, default=60.0, help="sim seconds of each run")
    parser.add_argument("--warmup", type=float, default=10.0, help="sim seconds before the window")
    parser.add_argument("--window", type=float, default=20.0, help="sim seconds measured")
    parser.add_argument("--tick-timeout", type=float, default=2.0)
    parser.add_argument("--arena", type=lambda t: (int(t.split("=")[0]), float(t.split("=")[1])), nargs="*",
                        default=[(1000, 38.0)], metavar="ROBOTS=SIDE",
                        help="arena side for runs of ROBOTS robots, resources scaled (as profile_batch.py)")
    parser.add_argument("--set", action="append", default=[], type=lambda t: f"--set={t}", metavar="KEY=VALUE")
    parser.add_argument("--run-arg", action="append", default=[], metavar="ARG",
                        help="a swarm-run option, e.g. --run-arg=--no-parameter-services (repeatable)")
    parser.add_argument("--perf", action="store_true", help="perf record the world and one controller process")
    parser.add_argument("--cprofile", action="store_true", help="cProfile the world and the controller processes")
    parser.add_argument("--top", type=int, default=0, help="with --cprofile: list the N costliest functions")
    parser.add_argument("--json", type=Path, help="append each run's figures to this file (JSON lines)")
    args = parser.parse_args()
    for n in args.robots:
        for k in args.controller_processes:
            result = one_run(args, n, k)
            report(result)
            if args.json:
                with open(args.json, "a") as f:
                    f.write(json.dumps(result, default=str) + "\n")
            sys.stdout.flush()


if __name__ == "__main__":
    main()
