"""A controller process's own Python per tick, without DDS: a recorded run replayed into the nodes.

The graph's controllers-in-one-process is the busiest process of a lockstep run (issue 14). This
benchmark measures the part of its work that is ours: the subscription callbacks (decoding, the
observation assembly), the behaviour step and the encoding of what the node publishes. It reads
a bag of a lockstep run (`swarm-run --bag DIR`), creates the run's controller nodes in one rclpy
context exactly as `swarm-controllers` does, and hands every node the recorded observation bytes
of every tick by calling its subscription callbacks directly, in the order the world sends them.
Publishing goes to real publishers nobody subscribes to (rclpy + Fast DDS without delivery,
~1 us). The replay is the run itself: the nodes must answer every tick with the very
``cmd_vel`` bytes the bag recorded, or the benchmark stops (graph == batch determinism makes
the controllers' choices the recorded ones).

    python benchmarks/bench_controller_node.py BAG [--ticks 300] [--repeat 3]

Prints the thread CPU time per tick and per robot-tick (median of the repeats).
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from collections import defaultdict
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import rclpy  # noqa: E402

from swarm_msgs_py import auth, topics  # noqa: E402
from swarm_sim.nodes.controller_node import ControllerConfig, ControllerNode  # noqa: E402
from swarm_sim.nodes.executor import StampTime  # noqa: E402
from swarm_sim.nodes.run_watch import WORLD_RUN  # noqa: E402
from swarm_sim.recording import bag_info, read_bag  # noqa: E402
from swarm_sim.scenario import scenario_from_dict  # noqa: E402


def load_ticks(bag: Path, ticks: int) -> tuple[list[list[tuple[str, str, bytes]]], dict[int, dict[str, bytes]]]:
    """(per tick the observation messages (robot, topic name, bytes) in recorded order,
    per tick the recorded cmd_vel bytes by robot)."""
    by_tick: dict[int, list] = defaultdict(list)
    commands: dict[int, dict[str, bytes]] = defaultdict(dict)
    stamps: list[int] = []
    for m in read_bag(bag):
        parts = m.topic.split("/")
        if len(parts) != 3 or not parts[1].startswith("robot_"):
            continue
        if m.stamp_ns not in by_tick and m.stamp_ns not in commands:
            stamps.append(m.stamp_ns)
            if len(stamps) > ticks:
                break
        if parts[2] == topics.CMD_VEL:
            commands[m.stamp_ns][parts[1]] = m.data
        elif parts[2] != topics.STATUS:
            by_tick[m.stamp_ns].append((parts[1], parts[2], m.data))
    stamps = stamps[:ticks]
    return [by_tick[s] for s in stamps], {s: commands[s] for s in stamps}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("bag", type=Path)
    parser.add_argument("--ticks", type=int, default=300)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    ticks, recorded = load_ticks(args.bag, args.ticks)
    # The recorded world's word that its run goes on, without the run's tag (this process has no key):
    # the nodes answer only the ticks of a world they heard (`swarm_sim.nodes.run_watch`).
    running = next((auth.strip(m.data) or m.data for m in read_bag(args.bag) if m.topic == WORLD_RUN), None)
    if running is None:
        sys.exit(f"{args.bag}: no {WORLD_RUN} message (not a bag of swarm-run)")
    custom = bag_info(args.bag).metadata
    scenario = scenario_from_dict(json.loads(custom["scenario"]))
    seed = int(custom["seed"])
    results = []
    for _ in range(args.repeat):
        context = rclpy.Context()
        rclpy.init(context=context)
        config = ControllerConfig(scenario=scenario.name, seed=seed, startup_timeout=0.0)
        stamp_time, watch, nodes = StampTime(), None, {}  # one of each a process, as swarm-controllers shares them
        for r in scenario.robot_names:
            nodes[r] = ControllerNode(r, config, scenario=scenario, context=context, stamp_time=stamp_time, watch=watch)
            watch = nodes[r].watch
        watch.on_message(running)
        callbacks = {}
        sent: dict[str, bytes] = {}
        for r, node in nodes.items():
            node.connect()
            for sub in node.subscriptions:
                callbacks[(r, sub.topic_name.rsplit("/", 1)[-1])] = sub.callback
            node._cmd_pub.publish = lambda data, r=r: sent.__setitem__(r, data)  # keep the answer
        unknown = sorted({name for tick in ticks for _, name, _ in tick} - {name for _, name in callbacks})
        if unknown:  # a bag of a tree before issue 40's single sense message, say
            sys.exit(f"{args.bag}: robot topics {unknown} that no controller node reads: record the bag with this tree")
        cpu = 0.0
        for stamp, messages in zip(recorded, ticks):
            sent.clear()
            t0 = time.thread_time()
            for robot, name, data in messages:
                callbacks[(robot, name)](data)
            cpu += time.thread_time() - t0
            if sent != recorded[stamp]:
                wrong = sorted(r for r in recorded[stamp] if sent.get(r) != recorded[stamp][r])
                sys.exit(f"tick {stamp} ns: the replayed nodes answered differently from the bag ({wrong[:5]})")
        results.append(cpu / len(ticks))
        for node in nodes.values():
            node.destroy_node()
        context.try_shutdown()
    per_tick = statistics.median(results)
    print(f"controller nodes, {len(scenario.robot_names)} robots, {len(ticks)} ticks replayed from {args.bag.name}: "
          f"{1e3 * per_tick:.2f} ms CPU per tick, {1e6 * per_tick / len(scenario.robot_names):.1f} us per robot "
          f"(median of {args.repeat}: {', '.join(f'{1e3 * r:.2f}' for r in results)} ms)")


if __name__ == "__main__":
    main()
