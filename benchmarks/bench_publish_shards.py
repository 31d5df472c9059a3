"""Issue 40, lever 5: would the world's publication spread over processes pay? A lockstep
message loop without physics, measured as it is and with K publishing shards.

The world node sends every robot 3 observations a tick (odometry, scan, sense) and waits for every
robot's stamped command before the next tick. Here a stand-in world does exactly that with the
real codecs' bytes (CPFA foot-bot: `encode_odometry`, `encode_scan` of 24 rays, the foraging
sense), to stand-in controller processes (N/M robots each, raw subscriptions, one `cmd_vel`
answer per robot once its 3 observations of the tick are in, as `ControllerNode` does). With
``--shards K`` the world publishes nothing itself: it writes the tick's bytes into one
shared-memory block (`multiprocessing.shared_memory`), wakes K shard processes through a pipe
each, and each shard publishes its N/K robots' messages through its own DDS participant (the
design the issue names: physics in one process, publishing shards fed by shared memory). What
the world keeps in both: encoding the tick (the bag writes the same bytes) and taking the
commands. Best-effort lockstep QoS as the graph's; a tick not answered within 0.5 s is sent again.

    python benchmarks/bench_publish_shards.py --robots 112 --controller-processes 1 --shards 0 1 2
    python benchmarks/bench_publish_shards.py --robots 1000 --controller-processes 4 --shards 0 2 4

Per setting (alternated, --repeat times): wall ms per tick, and CPU ms per tick of the world's
process, the shards and the controllers (from /proc, over the measured ticks).
"""

from __future__ import annotations

import argparse
import multiprocessing as mp
import os
import statistics
import struct
import sys
import time
from multiprocessing import shared_memory
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from profile_graph import process_cpu_s  # noqa: E402

NAMES = ("odom", "scan", "sense")
STAMP = struct.Struct("<iI")  # CDR: 4 bytes of encapsulation, then std_msgs/Header's stamp
RESEND_S = 0.5


def templates(robots: int) -> list[list[bytes]]:
    """Per robot its 3 observation messages (tick 0), as the world encodes them."""
    import numpy as np

    from swarm_msgs_py.odometry import encode_odometry
    from swarm_msgs_py.scan import encode_scan
    from swarm_msgs_py.types import Pose2D
    from swarm_sim.scenario import load_scenario
    from swarm_sim.world.tasks.foraging import ForagingSense
    from swarm_sim.world.tasks.foraging_sensing import SENSING

    shape = load_scenario("cpfa").sensors.scan
    rng = np.random.default_rng(0)
    out = []
    for i in range(robots):
        r = f"robot_{i}"
        out.append([encode_odometry(r, 0, Pose2D(1.0, 2.0, 0.3), 0.2, 0.1),
                    encode_scan(r, 0, rng.uniform(0.2, 4.0, shape.rays), shape),
                    SENSING.encode(0, ForagingSense(resources=(), carrying=False))])
    return out


def stamped(data: bytes, tick: int) -> bytes:
    return data[:4] + STAMP.pack(tick, 0) + data[12:]


BASE_ENV = dict(os.environ)
"""The environment this benchmark started with: each process's DDS environment is made from it."""


def _env(domain: int, processes: int) -> None:
    from launch_py.dds import loopback_env

    os.environ.clear()
    os.environ.update(loopback_env(domain, processes, base=BASE_ENV))


def _types():
    from swarm_msgs_py import topics

    return {n: topics.type_of(n) for n in (*NAMES, topics.CMD_VEL)}


def controller_main(domain: int, processes: int, robots: list[str], ready) -> None:  # noqa: ANN001
    """Raw subscriptions of `robots`' observations; answer each robot's tick once all 3 are in."""
    _env(domain, processes)
    import rclpy

    from swarm_msgs_py import topics, twist
    from swarm_sim.nodes.executor import make_executor
    from swarm_sim.nodes.qos import SENSOR_LOCKSTEP

    rclpy.init()
    types = _types()
    node = rclpy.create_node(f"controllers_{robots[0]}", start_parameter_services=False, enable_rosout=False)
    pubs, seen, answered = {}, {}, {}
    for r in robots:
        pubs[r] = node.create_publisher(types[topics.CMD_VEL], f"/{r}/{topics.CMD_VEL}", SENSOR_LOCKSTEP)
        seen[r], answered[r] = {}, -1

        def on(data: bytes, r: str = r) -> None:
            tick = STAMP.unpack_from(data, 4)[0]
            if tick <= answered[r]:
                if tick == answered[r]:
                    pubs[r].publish(twist.encode_twist(r, tick * 10**9, 0.1, 0.0))
                return
            got = seen[r]
            got[tick] = got.get(tick, 0) + 1
            if got[tick] == 3:
                answered[r] = tick
                seen[r] = {}
                pubs[r].publish(twist.encode_twist(r, tick * 10**9, 0.1, 0.0))

        for n in NAMES:
            node.create_subscription(types[n], f"/{r}/{n}", on, SENSOR_LOCKSTEP, raw=True)
    executor = make_executor()
    executor.add_node(node)
    ready.send(os.getpid())
    while rclpy.ok():
        executor.spin_once(timeout_sec=0.5)


def shard_main(domain: int, processes: int, robots: list[int], shm_name: str, offsets: list[tuple[int, int]],
               wake, ready) -> None:  # noqa: ANN001
    """Publish `robots`' messages of each tick from the shared block when woken."""
    _env(domain, processes)
    import rclpy

    from swarm_sim.nodes.qos import SENSOR_LOCKSTEP

    rclpy.init()
    types = _types()
    node = rclpy.create_node(f"shard_{robots[0]}", start_parameter_services=False, enable_rosout=False)
    block = shared_memory.SharedMemory(shm_name)
    slots = []
    for i in robots:
        for k, n in enumerate(NAMES):
            pub = node.create_publisher(types[n], f"/robot_{i}/{n}", SENSOR_LOCKSTEP)
            slots.append((pub.handle.publish_raw, *offsets[3 * i + k]))
    ready.send(os.getpid())
    buf = block.buf
    while True:
        if wake.recv() is None:
            break
        for publish, start, size in slots:
            publish(bytes(buf[start:start + size]))
    block.close()
    rclpy.shutdown()


def _cpu_s(pids: list[int]) -> float:
    return sum(process_cpu_s(pid) for pid in pids)


def one_run(robots: int, controller_processes: int, shards: int, ticks: int, warmup: int, domain: int) -> dict:
    ctx = mp.get_context("fork")
    processes = 1 + controller_processes + shards
    msgs = templates(robots)
    offsets, at = [], 0
    for per in msgs:
        for data in per:
            offsets.append((at, len(data)))
            at += len(data)
    block = shared_memory.SharedMemory(create=True, size=at)
    children, wakes, controller_pids, shard_pids = [], [], [], []
    names = [f"robot_{i}" for i in range(robots)]
    try:
        for k in range(controller_processes):
            mine, theirs = ctx.Pipe()
            p = ctx.Process(target=controller_main, args=(domain, processes, names[k::controller_processes], theirs),
                            daemon=True)
            p.start()
            children.append(p)
            controller_pids.append(mine.recv())
        for k in range(shards):
            mine, theirs = ctx.Pipe()
            wake_r, wake_w = ctx.Pipe(duplex=False)
            p = ctx.Process(target=shard_main, args=(domain, processes, list(range(robots))[k::shards], block.name,
                                                     offsets, wake_r, theirs), daemon=True)
            p.start()
            children.append(p)
            wakes.append(wake_w)
            shard_pids.append(mine.recv())
        return _world(robots, processes, shards, ticks, warmup, domain, msgs, offsets, block, wakes,
                      controller_pids, shard_pids)
    finally:
        for w in wakes:
            w.send(None)
        for p in children:
            p.join(timeout=5)
            if p.is_alive():
                p.kill()
        block.close()
        block.unlink()


def _world(robots, processes, shards, ticks, warmup, domain, msgs, offsets, block, wakes,  # noqa: ANN001, PLR0913
           controller_pids, shard_pids) -> dict:
    _env(domain, processes)
    import rclpy

    from swarm_msgs_py import topics
    from swarm_sim.nodes.executor import make_executor
    from swarm_sim.nodes.qos import SENSOR_LOCKSTEP

    rclpy.init()
    types = _types()
    node = rclpy.create_node("world_standin", start_parameter_services=False, enable_rosout=False)
    waiting: set[int] = set()
    current = [-1]

    def on_cmd(data: bytes, robot: int) -> None:
        if STAMP.unpack_from(data, 4)[0] == current[0]:
            waiting.discard(robot)

    subs = [node.create_subscription(types[topics.CMD_VEL], f"/robot_{i}/{topics.CMD_VEL}",
                                     lambda data, i=i: on_cmd(data, i), SENSOR_LOCKSTEP, raw=True)
            for i in range(robots)]
    pubs = [] if shards else [[node.create_publisher(types[n], f"/robot_{i}/{n}", SENSOR_LOCKSTEP).handle.publish_raw
                               for n in NAMES] for i in range(robots)]
    executor = make_executor()
    executor.add_node(node)
    deadline = time.monotonic() + 120
    while any(s.get_publisher_count() < 1 for s in subs) and time.monotonic() < deadline:
        executor.spin_once(timeout_sec=0.1)
    time.sleep(2.0)  # the shards' and controllers' readers matched the writers too (best effort: else lost, resent)
    buf = block.buf
    me = [os.getpid()]
    t0 = c0 = None
    resent = 0
    for tick in range(warmup + ticks):
        if tick == warmup:
            t0, c0 = time.perf_counter(), (_cpu_s(me), _cpu_s(shard_pids), _cpu_s(controller_pids))
        current[0] = tick
        waiting.update(range(robots))
        data = [[stamped(m, tick) for m in per] for per in msgs]  # the world's encoding stands here
        while waiting:
            if shards:
                for i, per in enumerate(data):
                    for k, d in enumerate(per):
                        start, size = offsets[3 * i + k]
                        buf[start:start + size] = d
                for w in wakes:
                    w.send(tick)
            else:
                for per, pub in zip(data, pubs):
                    for d, publish in zip(per, pub):
                        publish(d)
            until = time.monotonic() + RESEND_S
            while waiting and time.monotonic() < until:
                executor.spin_once(timeout_sec=0.05)
            if waiting:
                resent += 1
    wall = time.perf_counter() - t0
    c1 = (_cpu_s(me), _cpu_s(shard_pids), _cpu_s(controller_pids))
    executor.shutdown()
    node.destroy_node()
    rclpy.shutdown()
    per = lambda a, b: 1e3 * (b - a) / ticks  # noqa: E731
    return {"wall_ms": 1e3 * wall / ticks, "world_ms": per(c0[0], c1[0]), "shards_ms": per(c0[1], c1[1]),
            "controllers_ms": per(c0[2], c1[2]), "resent": resent}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robots", type=int, default=112)
    parser.add_argument("--controller-processes", type=int, default=1)
    parser.add_argument("--shards", type=int, nargs="+", default=[0, 1, 2], help="settings, alternated (0: the world "
                        "publishes itself)")
    parser.add_argument("--ticks", type=int, default=200)
    parser.add_argument("--warmup", type=int, default=30)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--domain-id", type=int, default=None, help="default: a free one")
    args = parser.parse_args()
    from launch_py.run import claim_run_domain

    domain, _lock = claim_run_domain(args.domain_id if args.domain_id is not None else "auto")
    results: dict[int, list[dict]] = {k: [] for k in args.shards}
    for _ in range(args.repeat):
        for k in args.shards:
            ctx = mp.get_context("fork")
            out, into = ctx.Pipe(duplex=False)
            p = ctx.Process(target=lambda: into.send(one_run(args.robots, args.controller_processes, k, args.ticks,
                                                             args.warmup, domain)))
            p.start()
            r = out.recv()
            p.join()
            results[k].append(r)
            print(f"robots={args.robots} controller processes={args.controller_processes} shards={k}: "
                  f"{r['wall_ms']:.1f} ms wall a tick; CPU ms a tick: world {r['world_ms']:.1f}, shards "
                  f"{r['shards_ms']:.1f}, controllers {r['controllers_ms']:.1f}; resent {r['resent']}; "
                  f"load {os.getloadavg()[0]:.1f}", flush=True)
    for k, rs in results.items():
        med = {key: statistics.median(r[key] for r in rs) for key in rs[0]}
        print(f"median shards={k}: wall {med['wall_ms']:.1f} ms, world {med['world_ms']:.1f}, shards "
              f"{med['shards_ms']:.1f}, controllers {med['controllers_ms']:.1f}, all "
              f"{med['world_ms'] + med['shards_ms'] + med['controllers_ms']:.1f} ms CPU a tick")


if __name__ == "__main__":
    main()
