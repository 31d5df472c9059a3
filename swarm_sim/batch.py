"""In-process batch runner: the graph's core objects stepped without DDS, for sweeps.

It plays the roles the graph splits over nodes, in the same order: observations of tick k go
to every behaviour, each with the messages stamped before k from the router (as a controller node
hands its behaviour its mailbox's), the commands come back, the servers (center, depot manager)
handle their messages stamped before k, the world steps. Same scenario and seed as a lockstep
graph run -> same trajectories and metrics (tested in test/test_determinism.py). With
``sim.stop_when_finished`` a run ends early once every behaviour says it is finished (sweeps). The
world task's state is kept every tick as the trace's series, and the servers' series are read off
what they publish, as a bag replay reads them (`swarm_sim.outputs.SeriesLog`).
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import gc
import json
import sys
import time
from collections.abc import Iterator
from dataclasses import dataclass
from itertools import chain
from operator import attrgetter, call
from typing import Any

import numpy as np

from swarm_msgs_py.types import FINISHED, NS_PER_S, DropEvent, PickupEvent
from swarm_sim.analysis.metrics import RunTrace, summarize
from swarm_sim.analysis.state_rules import RuleLog, StatusLog
from swarm_sim.analysis.text import summary_line
from swarm_sim.behaviour import behaviour_rng
from swarm_sim.cli import add_scenario_arguments, first_paragraph, number, scenario_fields, stop_on_signals
from swarm_sim.executors import Progress, add_executor_arguments, executor_from_args
from swarm_sim.messaging import Router, delivery_order
from swarm_sim.outputs import SeriesLog, StateWatch, outputs_of
from swarm_sim.protocol import ROBOTS
from swarm_sim.registry import make_behaviour, make_servers, of, resolve, task, task_factory
from swarm_sim.registry import probes as registered_probes
from swarm_sim.scenario import Scenario, ScenarioError, load_scenario
from swarm_sim.world import World
from swarm_sim.world.core import tune_malloc
from swarm_sim.world.observations import with_messages


@dataclass
class BatchRun:
    trace: RunTrace
    poses: np.ndarray | None
    """(ticks + 1, robots, 3) odometry poses (x, y, yaw) as the behaviours saw them, if asked."""


_MESSAGES = attrgetter("messages")

GC_THRESHOLD = 50_000
"""Tracked objects allocated (net) between two young-generation collections during a run. A tick
makes and drops a few objects per robot (observations, commands: freed by reference counting);
at Python's default of 700 the collector ran ~5 times a tick at 1000 robots (~2 ms a tick), at
this threshold a few times a run; peak memory measured the same."""


@contextlib.contextmanager
def _few_collections() -> Iterator[None]:
    """Freeze what exists (the world, behaviours: they live all run) and collect rarely."""
    threshold = gc.get_threshold()
    gc.freeze()
    gc.set_threshold(GC_THRESHOLD, *threshold[1:])
    try:
        yield
    finally:
        gc.set_threshold(*threshold)
        gc.unfreeze()


def make_probes(scenario: Scenario, robots: tuple[str, ...]) -> dict[str, Any]:
    """The observers of the probes the run asks for (`swarm_sim.registry.Probe`), by name; each is
    fed the odometry positions at the start of every tick and after the last."""
    return {p.name: resolve(p.observer)(scenario, robots) for p in registered_probes(scenario)}


def run_batch(scenario: Scenario, *, record_poses: bool = False) -> BatchRun:
    with _few_collections():
        return _run_batch(scenario, record_poses)


def _run_batch(scenario: Scenario, record_poses: bool) -> BatchRun:
    wall0 = time.monotonic()
    world = World(scenario, task_factory(scenario))
    robots = world.robots
    behaviours = {r: make_behaviour(scenario, r, behaviour_rng(scenario.seed, r)) for r in robots}
    steps = [b.step for b in behaviours.values()]  # robot order, bound once: stepped every tick
    servers = make_servers(scenario)
    router = Router()
    last_step_ns = 0
    trace = RunTrace(
        scenario=scenario.name, seed=scenario.seed, robots=robots, sim_seconds=0.0,
        wall_seconds=0.0, total_resources=scenario.resources.count, mode="batch", config=scenario,
    )
    probes = make_probes(scenario, robots)
    observers = tuple(probes.values())
    poses = np.zeros((scenario.ticks + 1, len(robots), 3)) if record_poses else None
    algorithm = of(scenario)
    spec = task(algorithm.task).state
    state_topics = resolve(spec) if spec else ()
    keep = tuple(cls for path in algorithm.peers for cls in resolve(path).topics) if algorithm.trace_peers else ()
    series = SeriesLog(algorithm.servers, trace.series)
    # The servers whose published state a series reads: asked for their state every tick.
    watched = {s.channel: StateWatch(outputs_of(s).state) for s in algorithm.servers if s.channel in series.reads_state}
    # State-dependent metrics (`swarm_sim.analysis.state_rules`): only for algorithms that declare them.
    robot_list = list(behaviours.values())
    rule_log = RuleLog(robots, resolve(algorithm.collision_rule)(scenario), scenario.sim.dt) \
        if algorithm.collision_rule else None
    status_log = StatusLog(robots) if algorithm.trace_status else None
    try:
        obs = world.reset()
        _record_state(world, state_topics, trace)
        for k in range(scenario.ticks):
            for observer in observers:
                observer.update(world.t_ns / NS_PER_S, world.odometry_positions)
            if poses is not None:
                poses[k] = [(o.pose.x, o.pose.y, o.pose.yaw) for o in obs.values()]
            # Each behaviour's inbox: every message stamped before this tick has been posted (the
            # robots' and servers' of the last tick); every robot gets the same tuple.
            inbox = router.take_before(ROBOTS, world.t_ns)
            seen = obs.values() if not inbox else [with_messages(o, inbox) for o in obs.values()]
            answers = list(map(call, steps, seen))  # the world's dict is in robot order
            if rule_log is not None:
                t_ns = world.t_ns
                rule_log.update(*world.ring.vectors(world.scan_ranges), lambda i: robot_list[i].status(t_ns))
            if status_log is not None:
                status_log.update(b.status(world.t_ns) for b in robot_list)
            sent = list(chain.from_iterable(map(_MESSAGES, answers)))
            for message in sent:
                router.post(message)
                if keep and isinstance(message, keep):
                    trace.messages.append(message)
            series.sent(sent)
            for channel, server in servers.items():
                answered = server.step(world.t_ns, router.take_before(channel, world.t_ns))
                for message in answered:
                    router.post(message)
                series.sent(answered)
                if channel in watched:
                    series.published(world.t_ns, watched[channel].changed(server.state()))
            last_step_ns = world.t_ns
            obs = world.step(dict(zip(robots, answers)))
            _collect_events(world, trace)
            _record_state(world, state_topics, trace)
            if scenario.sim.stop_when_finished and all(getattr(b, "finished", False) for b in behaviours.values()):
                trace.ended = FINISHED
                if poses is not None:
                    poses = poses[:k + 2]
                break
        for observer in observers:
            observer.update(world.t_ns / NS_PER_S, world.odometry_positions)
        if poses is not None:
            poses[-1] = [(o.pose.x, o.pose.y, o.pose.yaw) for o in obs.values()]
        status = {r: b.status(last_step_ns) for r, b in behaviours.items()}
        trace.sim_seconds = world.t_ns / NS_PER_S
        trace.stats = {r: dataclasses.replace(s) for r, s in world.stats.items()}
        trace.status = status
        trace.probes = {name: observer.result() for name, observer in probes.items()}
        trace.messages.sort(key=delivery_order)
        if rule_log is not None:
            trace.rule_collision_s = rule_log.seconds()
        if status_log is not None:
            trace.status_log = status_log.log
    finally:
        world.close()
    trace.wall_seconds = time.monotonic() - wall0
    return BatchRun(trace, poses)


def _record_state(world: World, state_topics: tuple, trace: RunTrace) -> None:
    """The task's state of the current tick, as a bag replay reads it back (`StateTopic`)."""
    if not state_topics:
        return
    values, t = world.task.state(), world.t_ns / NS_PER_S
    for st in state_topics:
        trace.series.setdefault(st.field, []).append((t, values[st.field]))


def _collect_events(world: World, trace: RunTrace) -> None:
    for event in world.drain_events():
        if isinstance(event, DropEvent):
            trace.drops.append(event)
        elif isinstance(event, PickupEvent):
            trace.pickups.append(event)


def run_one(job: tuple[str, tuple[str, ...], dict, int]) -> dict:
    """One sweep run, (scenario, overrides, fields, seed) -> its summary. What executors call, in
    the ``swarm-batch`` or ``swarm-compare`` process or in a worker's: so it is where that process
    gets `tune_malloc`."""
    tune_malloc()
    name, overrides, fields, seed = job
    scenario = load_scenario(name, overrides, **fields, seed=seed)
    return summarize(run_batch(scenario).trace)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="swarm-batch", description=first_paragraph(__doc__))
    add_scenario_arguments(parser)
    parser.add_argument("--runs", type=number(int, 1, 10**6), default=1, help="runs with seeds seed, seed+1, ...")
    add_executor_arguments(parser)
    parser.add_argument("--json", action="store_true", help="print one JSON object per run")
    args = parser.parse_args(argv)
    if argv is None:  # the command itself, not a caller's function call
        stop_on_signals()
    try:
        base = load_scenario(args.scenario, args.overrides, **scenario_fields(args), seed=args.seed)
    except ScenarioError as exc:
        print(f"swarm-batch: {exc}", file=sys.stderr)
        return 2
    seeds = [base.seed + i for i in range(args.runs)]
    jobs = [(args.scenario, tuple(args.overrides), scenario_fields(args), s) for s in seeds]
    failed = 0
    try:
        with executor_from_args(args) as executor, Progress(len(jobs), f"swarm-batch ({executor.name})") as bar:
            for outcome in executor.map(run_one, jobs):
                if outcome.ok:
                    bar.write(json.dumps(outcome.value) if args.json else summary_line(outcome.value, base),
                              numbered=False)
                else:
                    failed += 1
                    bar.write(f"swarm-batch: seed {seeds[outcome.index]} failed: {outcome.error}",
                              lambda text: print(text, file=sys.stderr, flush=True), numbered=False)
                bar.update(outcome.ok)
    except (RuntimeError, OSError) as exc:  # no Dask installed, scheduler unreachable
        print(f"swarm-batch: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("swarm-batch: interrupted", file=sys.stderr)
        return 130
    if failed:
        print(f"swarm-batch: {failed} of {len(jobs)} runs failed", file=sys.stderr)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
