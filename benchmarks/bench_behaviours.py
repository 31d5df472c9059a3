"""The behaviours alone, on a recorded batch run's observations: their share of a tick without the world.

    python benchmarks/bench_behaviours.py record --scenario cpfa --robots 1000 --duration 80 --out cpfa1000.pkl
    python benchmarks/bench_behaviours.py replay cpfa1000.pkl --skip 60 --repeat 3

``record`` runs `run_batch` and keeps, for every tick, what each behaviour was given (pose, scan,
sensed, inbox) and what it answered. ``replay`` builds fresh behaviours (same scenario, same
seeded generators) and steps them through the recorded observations, so they see exactly what
they saw in the run: it checks every command equals the recorded one (a recording made with one
version of the code checks that another decides the same) and times the ticks after ``--skip``
sim seconds in process CPU time, which other processes on a busy machine disturb less than the
wall clock. Runs of 1000 robots get the 38 x 38 m arena with scaled resources (`profile_batch`).
"""

from __future__ import annotations

import argparse
import gc
import pickle
import statistics
import sys
import time
from pathlib import Path

import numpy as np
from profile_batch import scaled_fields

import swarm_sim.batch as batch
from swarm_msgs_py.types import Observation, Pose2D
from swarm_sim.behaviour import behaviour_rng
from swarm_sim.registry import make_behaviour
from swarm_sim.scenario import Scenario, load_scenario
from swarm_sim.world.core import tune_malloc


def _scenario(name: str, robots: int, duration: float, seed: int) -> Scenario:
    fields = scaled_fields(name, robots, 38.0 if robots == 1000 else None)
    return load_scenario(name, **fields, sim__duration=duration, seed=seed)


def record(scenario: Scenario) -> list[dict]:
    """Per tick: the robots' observations (as arrays and lists) and their commands."""
    ticks: dict[int, list[tuple[Observation, tuple]]] = {}
    build = batch.make_behaviour

    def recording(s: Scenario, robot: str, rng: np.random.Generator):
        behaviour = build(s, robot, rng)
        step = behaviour.step

        def recorded(obs: Observation):
            command = step(obs)
            ticks.setdefault(obs.stamp_ns, []).append((obs, (command.linear, command.angular, command.messages)))
            return command

        behaviour.step = recorded
        return behaviour

    batch.make_behaviour = recording
    try:
        batch.run_batch(scenario)
    finally:
        batch.make_behaviour = build
    return [
        {
            "stamp_ns": stamp,
            "robots": [o.robot for o, _ in seen],
            "ranges": np.stack([o.ranges for o, _ in seen]),
            "poses": [(o.pose.x, o.pose.y, o.pose.yaw) for o, _ in seen],
            "velocities": [(o.linear_velocity, o.angular_velocity) for o, _ in seen],
            "sensed": [o.sensed for o, _ in seen],
            "messages": [o.messages for o, _ in seen],
            "commands": [c for _, c in seen],
        }
        for stamp, seen in sorted(ticks.items())
    ]


def replay(scenario: Scenario, ticks: list[dict], skip: int) -> tuple[float, int]:
    """(CPU seconds per tick after `skip` ticks, commands that differ from the recording)."""
    observations = []
    for t in ticks:
        rows = list(t["ranges"])  # views of one array, as the world hands them out
        observations.append([
            Observation(r, t["stamp_ns"], Pose2D(*p), v, w, g, s, m)
            for r, p, (v, w), g, s, m in zip(t["robots"], t["poses"], t["velocities"], rows, t["sensed"], t["messages"])
        ])
    steps = [make_behaviour(scenario, r, behaviour_rng(scenario.seed, r)).step for r in ticks[0]["robots"]]
    differ = 0
    t0 = 0.0
    for k, (seen, t) in enumerate(zip(observations, ticks)):
        if k == skip:
            t0 = time.process_time()
        commands = [step(o) for step, o in zip(steps, seen)]
        if k < skip:  # checked outside the timed ticks; after them, once below
            differ += sum((c.linear, c.angular, c.messages) != e for c, e in zip(commands, t["commands"]))
        else:
            t["answers"] = commands
    seconds = (time.process_time() - t0) / (len(ticks) - skip)
    for t in ticks[skip:]:
        differ += sum((c.linear, c.angular, c.messages) != e for c, e in zip(t.pop("answers"), t["commands"]))
    return seconds, differ


def main(argv: list[str] | None = None) -> int:
    tune_malloc()  # as the commands that run a world do (`tune_malloc`): time it as they run it
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    rec = sub.add_parser("record", help="run a batch and keep every behaviour's inputs and answers")
    rec.add_argument("--scenario", default="cpfa")
    rec.add_argument("--robots", type=int, default=112)
    rec.add_argument("--duration", type=float, default=60.0, help="sim seconds")
    rec.add_argument("--seed", type=int, default=0)
    rec.add_argument("--out", type=Path, required=True)
    rep = sub.add_parser("replay", help="step fresh behaviours through a recording, check and time them")
    rep.add_argument("recording", type=Path)
    rep.add_argument("--skip", type=float, default=0.0, help="sim seconds stepped before the timed ticks")
    rep.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args(argv)
    if args.command == "record":
        scenario = _scenario(args.scenario, args.robots, args.duration, args.seed)
        ticks = record(scenario)
        with args.out.open("wb") as f:
            pickle.dump({"scenario": (args.scenario, args.robots, args.duration, args.seed), "ticks": ticks}, f, protocol=5)
        print(f"recorded {len(ticks)} ticks of {args.robots} robots ({args.scenario}) to {args.out}")
        return 0
    with args.recording.open("rb") as f:
        recorded = pickle.load(f)
    name, robots, duration, seed = recorded["scenario"]
    scenario = _scenario(name, robots, duration, seed)
    skip = round(args.skip / scenario.sim.dt)
    gc.freeze()
    gc.set_threshold(batch.GC_THRESHOLD)  # as run_batch does
    results = [replay(scenario, recorded["ticks"], skip) for _ in range(max(1, args.repeat))]
    per_tick = [1e3 * s for s, _ in results]
    differ = max(d for _, d in results)
    print(f"{name}, {robots} robots, ticks {skip}-{len(recorded['ticks']) - 1}: behaviours "
          f"{statistics.median(per_tick):.3f} ms/tick CPU (median of {len(per_tick)}: "
          f"{', '.join(f'{t:.3f}' for t in per_tick)}); commands differing from the recording: {differ}")
    return 1 if differ else 0


if __name__ == "__main__":
    sys.exit(main())
