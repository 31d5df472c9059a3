"""World core speed: ms per tick of ``World.step`` (physics + sensing + observations) on one core.

Budget: the batch runner must run 112 robots at >= 20x real time with dt = 0.1 s including the
controllers, so step() + observe() should stay under ~2.5 ms per tick.

Prints, for 16/64/112 robots and each scan backend, the ms per tick in three phases - "start"
(robots wandering off the start grid around the depot), "spread" (after the swarm has
dispersed) and "jammed" (every robot pushing towards the depot centre: the worst case, a
congested nest) - with a breakdown, then the raycast alone for 112 x 24 = 2,688 rays, then the
peak RSS. Robots are driven by cheap vectorised policies (wander: full speed, turn away from
anything within 0.3 m ahead, seeded random turns; homing: steer to the depot) whose cost is not
counted. Timings are per block of 20 ticks: the median and minimum wall time and the median CPU time of
the thread (on a loaded machine the CPU time is the better estimate of the unloaded cost).

    python benchmarks/bench_world.py [--robots 16 64 112] [--ticks 300] [--backends analytic pybullet]
"""

from __future__ import annotations

import argparse
import math
import resource
import statistics
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from swarm_msgs_py.types import Command  # noqa: E402
from swarm_sim.registry import task_factory  # noqa: E402
from swarm_sim.scenario import load_scenario  # noqa: E402
from swarm_sim.world import World  # noqa: E402
from swarm_sim.world.raycast import StaticScene, cast_scan, cast_scan_pybullet  # noqa: E402
from swarm_sim.world.core import tune_malloc  # noqa: E402

BLOCK = 20
"""Ticks per timing block."""


class Wander:
    """Full speed ahead; turn away from anything within 0.3 m in the front sector."""

    def __init__(self, robots: tuple[str, ...], rays: int, seed: int = 0) -> None:
        self.robots = robots
        self.rng = np.random.default_rng(seed)
        front = np.arange(rays)
        angle = -math.pi + front * (2 * math.pi / rays)
        self.front = np.abs(angle) < 1.0

    def __call__(self, obs: dict) -> dict[str, Command]:
        ranges = np.stack([obs[r].ranges for r in self.robots])
        blocked = (ranges[:, self.front] < 0.3).any(axis=1)
        turn = np.where(blocked, 2.0, self.rng.normal(0.0, 0.5, len(self.robots)))
        speed = np.where(blocked, 0.0, 0.16)
        return {r: Command(v, w) for r, v, w in zip(self.robots, speed.tolist(), turn.tolist())}


class Homing:
    """Everyone drives at full speed towards the depot centre: the worst case, a jammed nest."""

    def __init__(self, robots: tuple[str, ...]) -> None:
        self.robots = robots

    def __call__(self, obs: dict) -> dict[str, Command]:
        x = np.array([obs[r].pose.x for r in self.robots])
        y = np.array([obs[r].pose.y for r in self.robots])
        yaw = np.array([obs[r].pose.yaw for r in self.robots])
        error = np.remainder(np.arctan2(-y, -x) - yaw + math.pi, 2 * math.pi) - math.pi
        turn = np.clip(3.0 * error, -2.0, 2.0)
        speed = np.where(np.abs(error) < 0.5, 0.16, 0.0)
        return {r: Command(v, w) for r, v, w in zip(self.robots, speed.tolist(), turn.tolist())}


def time_ticks(world: World, policy, obs: dict, ticks: int) -> tuple[list[tuple[float, float]], dict]:
    """Per-block (wall, CPU) ms per tick of world.step (the policy is outside the clock)."""
    blocks, wall, cpu, done = [], 0.0, 0.0, 0
    while done < ticks:
        commands = policy(obs)
        t0, c0 = time.perf_counter(), time.thread_time()
        obs = world.step(commands)
        wall += time.perf_counter() - t0
        cpu += time.thread_time() - c0
        done += 1
        if done % BLOCK == 0:
            blocks.append((wall / BLOCK * 1e3, cpu / BLOCK * 1e3))
            wall = cpu = 0.0
    return blocks, obs


def breakdown(world: World, policy: Wander, obs: dict, ticks: int) -> dict[str, float]:
    """ms per tick of the parts of step(), measured by calling them one by one."""
    parts = dict.fromkeys(("commands", "physics", "read+odometry", "task", "scan", "observations"), 0.0)
    sc = world.scenario.sensors.scan
    scene = StaticScene.from_scenario(world.scenario)
    for _ in range(ticks):
        commands = policy(obs)
        t = [time.perf_counter()]
        idx = np.fromiter(map(world._index.__getitem__, commands), np.intp, len(commands))
        world._apply_commands(idx, commands.values())
        world._fresh = False
        world._count_avoidance()
        world._obs_cache = None
        pos0, yaw0 = world._pos, world._yaw
        t.append(time.perf_counter())
        world._physics()
        t.append(time.perf_counter())
        world._read_state()
        world._odometry(pos0, yaw0)
        t.append(time.perf_counter())
        world.task.post_step((world.tick + 1) * world._dt_ns)
        world.tick += 1
        t.append(time.perf_counter())
        if sc.backend == "pybullet":
            cast_scan_pybullet(world.client, world._pos, world._yaw, world._z0, world._radius, sc)
        else:
            cast_scan(
                world._pos, world._yaw, world._radius, scene, sc.rays, sc.fov, sc.range_max, sc.range_min,
                world._pairs,
            )
        t.append(time.perf_counter())
        obs = world.observe()  # includes the scan again; subtract below
        t.append(time.perf_counter())
        for k, name in enumerate(parts):
            parts[name] += (t[k + 1] - t[k]) * 1e3 / ticks
    parts["observations"] = max(parts["observations"] - parts["scan"], 0.0)
    return parts


def bench_world(robots: int, backend: str, ticks: int, spread_after: int, jammed: bool) -> None:
    """Phases: "start" (wandering off the start grid), "spread" (wandering after `spread_after`
    ticks), "jammed" (everyone pushing towards the depot centre after 400 ticks of homing)."""
    s = load_scenario("cpfa", robots__count=robots, sensors__scan__backend=backend)
    world = World(s, task_factory(s))
    wander, homing = Wander(world.robots, s.sensors.scan.rays), Homing(world.robots)
    obs = world.reset()
    phases, parts = {}, {}
    phases["start"], obs = time_ticks(world, wander, obs, ticks)
    for _ in range(max(0, spread_after - ticks)):
        obs = world.step(wander(obs))
    phases["spread"], obs = time_ticks(world, wander, obs, ticks)
    parts["spread"] = breakdown(world, wander, obs, min(ticks, 100))
    if jammed:
        for _ in range(400):
            obs = world.step(homing(obs))
        phases["jammed"], obs = time_ticks(world, homing, obs, ticks)
        parts["jammed"] = breakdown(world, homing, obs, min(ticks, 100))
    world.close()
    for phase, blocks in phases.items():
        wall = statistics.median(b[0] for b in blocks)
        cpu = statistics.median(b[1] for b in blocks)
        print(
            f"  {robots:4d} robots  {backend:9s} {phase:7s} wall {wall:7.2f} ms/tick median "
            f"({min(b[0] for b in blocks):6.2f} min), CPU {cpu:7.2f} ms/tick "
            f"= {100 / cpu:6.1f}x real time for the world alone"
        )
    for phase, p in parts.items():
        print(f"       {phase} breakdown [ms/tick]: " + ", ".join(f"{k} {v:.2f}" for k, v in p.items()))


def bench_raycast(repeats: int = 200) -> None:
    s = load_scenario("cpfa", robots__count=112)
    sc = s.sensors.scan
    rng = np.random.default_rng(0)
    side = 11
    i = np.arange(112)
    grid = np.column_stack([(i % side - 5) * 0.3, (i // side - 5) * 0.3])
    layouts = {"crowded (start grid)": grid, "spread (uniform)": rng.uniform(-5.8, 5.8, (112, 2))}
    yaw = rng.uniform(-math.pi, math.pi, 112)
    scene = StaticScene.from_scenario(s)
    world = World(s, task_factory(s))
    try:
        for name, pos in layouts.items():
            world.teleport({r: _pose(pos[k], yaw[k]) for k, r in enumerate(world.robots)})
            for backend in ("analytic", "pybullet"):
                if backend == "analytic":
                    def call():
                        return cast_scan(pos, yaw, world._radius, scene, sc.rays, sc.fov, sc.range_max)
                else:
                    def call():
                        return cast_scan_pybullet(world.client, pos, yaw, world._z0, world._radius, sc)
                n = repeats if backend == "analytic" else repeats // 4
                samples = []
                for _ in range(n):
                    t0 = time.perf_counter()
                    call()
                    samples.append((time.perf_counter() - t0) * 1e3)
                print(
                    f"  raycast 2,688 rays  {backend:9s} {name:22s} {statistics.median(samples):6.3f} ms "
                    f"median ({min(samples):.3f} min)"
                )
    finally:
        world.close()


def _pose(xy, yaw):
    from swarm_msgs_py.types import Pose2D

    return Pose2D(float(xy[0]), float(xy[1]), float(yaw))


def main() -> None:
    tune_malloc()  # as the commands that run a world do (`tune_malloc`): time it as they run it
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--robots", type=int, nargs="+", default=[16, 64, 112])
    parser.add_argument("--ticks", type=int, default=300, help="timed ticks per phase")
    parser.add_argument("--backends", nargs="+", default=["analytic", "pybullet"])
    parser.add_argument("--spread-after", type=int, default=600, help="ticks before the spread phase")
    parser.add_argument("--pybullet-ticks", type=int, default=40,
                        help="timed ticks per phase for the (slow) pybullet scan backend")
    args = parser.parse_args()
    print(f"World.step() ms per tick (dt = 0.1 s; the budget for 112 robots is ~2.5 ms), load {_load()}")
    for backend in args.backends:
        for n in args.robots:
            if backend == "analytic":
                bench_world(n, backend, args.ticks, args.spread_after, jammed=True)
            else:  # rayTestBatch takes 30-150 ms a tick for 112 robots: short phases, no jam
                bench_world(n, backend, args.pybullet_ticks, 200, jammed=False)
    bench_raycast()
    rss_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"  peak RSS {rss_mb:.0f} MB")


def _load() -> str:
    try:
        return Path("/proc/loadavg").read_text().split()[0]
    except OSError:
        return "?"


if __name__ == "__main__":
    main()
