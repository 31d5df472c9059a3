"""Conformance checks any registered algorithm runs through (PettingZoo's ``parallel_api_test``).

`check_algorithm` takes an algorithm's registry record and a scenario that runs it, and checks:

- **ros_free**: every core the record names (behaviour, sections, checks, server cores, world
  task, metrics, paths, message families, sense codecs) imports with rclpy and every ``*_msgs``
  package blocked, and a short batch run works that way;
- **determinism**: two batch runs with the same seed give identical results and trajectories;
- **codecs**: every message class of its families, its task's sense and its servers' state
  topics survive encode/decode unchanged (messages built from their field types, senses and task
  states taken from a real world, server states from its cores after a first tick);
- **graph_equals_batch** (optional): a lockstep run on the ROS graph (``swarm-run``) gives the
  batch run's trajectories and metrics for the same seed.

A test gets all four for an algorithm by registering it; nothing here names one.
"""

from __future__ import annotations

import dataclasses
import enum
import json
import os
import subprocess
import sys
import textwrap
import types
import typing
from pathlib import Path
from typing import Any

import numpy as np

from swarm_msgs_py.types import Command
from swarm_sim import registry
from swarm_sim.analysis.metrics import summarize
from swarm_sim.analysis.replay import load_odometry
from swarm_sim.batch import run_batch
from swarm_sim.outputs import outputs_of
from swarm_sim.scenario import Scenario, load_scenario, scenario_to_dict
from swarm_sim.world import World

ROS_BLOCKER = textwrap.dedent(
    """
    import importlib.abc, sys

    class _BlockRos(importlib.abc.MetaPathFinder):
        def find_spec(self, name, path=None, target=None):
            root = name.split(".")[0]
            if root in ("rclpy", "rosidl_runtime_py", "rcl_interfaces") or root.endswith("_msgs"):
                raise ImportError(f"blocked for the ROS-free check: {name}")
            return None

    sys.meta_path.insert(0, _BlockRos())
    """
)
"""Python source that makes importing rclpy or any ``*_msgs`` package fail."""

WALL_FIELDS = ("wall_seconds", "real_time_factor", "mode")
GRAPH_COMPARED = ("resources_delivered", "collision_time_s_by_robot", "contact_time_s_by_robot", "oae_by_robot",
                  "trips_by_robot", "clamped_commands", "stale_ticks")
"""Compared between the graph and the batch run, with every probe's per-event lists."""


class ConformanceError(AssertionError):
    """An algorithm failed a conformance check; the message names the check and the cause."""


def _fail(check: str, why: str) -> None:
    raise ConformanceError(f"{check}: {why}")


def core_paths(algorithm: registry.Algorithm) -> list[str]:
    """Every ``module:attribute`` of the record whose module must import without ROS."""
    task = registry.task(algorithm.task)
    paths = [algorithm.behaviour, *(p for _, p in algorithm.config), *algorithm.checks,
             *(s.core for s in algorithm.servers), *(s.family for s in algorithm.servers),
             *(s.outputs for s in algorithm.servers if s.outputs), *algorithm.peers,
             *(m.function for m in algorithm.metrics), task.core, task.sensing]
    paths += [p for p in (algorithm.paths, algorithm.comparison, algorithm.figures, task.metrics, task.state) if p]
    return paths


def check_ros_free(algorithm: registry.Algorithm, scenario: Scenario) -> None:
    code = ROS_BLOCKER + textwrap.dedent(
        f"""
        from swarm_sim import registry
        for path in {core_paths(algorithm)!r}:
            registry.resolve(path)
        from swarm_sim.batch import run_batch
        from swarm_sim.scenario import scenario_from_dict
        import json
        scenario = scenario_from_dict(json.loads({json.dumps(json.dumps(_short(scenario, 1.0)))}))
        run_batch(scenario)
        print("ok")
        """
    )
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    if result.returncode != 0 or not result.stdout.strip().endswith("ok"):
        _fail("ros_free", (result.stderr.strip().splitlines() or ["no output"])[-1])


def _short(scenario: Scenario, duration: float) -> dict[str, Any]:
    data = scenario_to_dict(scenario)
    data["sim"]["duration"] = duration
    return data


def _batch(scenario: Scenario) -> tuple[dict[str, Any], np.ndarray]:
    run = run_batch(scenario, record_poses=True)
    summary = {k: v for k, v in summarize(run.trace).items() if k not in WALL_FIELDS}
    return summary, run.poses


def check_determinism(scenario: Scenario) -> tuple[dict[str, Any], np.ndarray]:
    """Two batch runs, same seed: identical. Returns the run (summary, poses)."""
    first, second = _batch(scenario), _batch(scenario)
    if first[0] != second[0]:
        keys = sorted(k for k in first[0] if first[0][k] != second[0].get(k))
        _fail("determinism", f"the same seed gave different {', '.join(keys)}")
    if not np.array_equal(first[1], second[1]):
        _fail("determinism", "the same seed gave different trajectories")
    return first


def _sample(tp: Any, name: str, where: str) -> Any:
    if typing.get_origin(tp) in (typing.Union, types.UnionType):
        tp = next(a for a in typing.get_args(tp) if a is not type(None))
    if typing.get_origin(tp) is tuple and typing.get_args(tp)[1:] == (Ellipsis,):
        item = _sample(typing.get_args(tp)[0], name, where)
        return (item, item)
    if isinstance(tp, type) and issubclass(tp, enum.Enum):
        return list(tp)[-1]
    if tp is bool:
        return True
    if tp is int:
        return 1_700_000_003 if name == "stamp_ns" else 3
    if tp is float:
        return 1.0 / 3.0  # a float whose text needs every digit
    if tp is str:
        return "robot_1"
    _fail("codecs", f"{where}: no sample for type {tp}")


def sample_message(cls: type) -> Any:
    """An instance of message dataclass `cls` with a value of each field's type."""
    hints = typing.get_type_hints(cls)
    return cls(**{f.name: _sample(hints[f.name], f.name, f"{cls.__name__}.{f.name}") for f in dataclasses.fields(cls)})


def check_codecs(algorithm: registry.Algorithm, scenario: Scenario) -> None:
    families = [registry.resolve(p) for p in (*(s.family for s in algorithm.servers), *algorithm.peers)]
    for family in families:
        for cls in family.topics:
            message = sample_message(cls)
            try:
                decoded = tuple(m for data in family.encode(message.stamp_ns, [message]) for m in family.decode(data))
            except ValueError as exc:
                _fail("codecs", f"{cls.__name__}: {exc}")
            if decoded != (message,):
                _fail("codecs", f"{cls.__name__} came back as {decoded!r}")

    sensing = registry.resolve(registry.task(algorithm.task).sensing)

    state = registry.task(algorithm.task).state
    state_topics = registry.resolve(state) if state else ()
    with World(scenario, registry.task_factory(scenario)) as world:  # robots drive in circles so that what they sense changes
        observations = [world.reset()]
        states = [(world.t_ns, world.task.state())] if state_topics else []
        turn = Command(scenario.robots.max_linear_speed, 0.5)
        for _ in range(50):
            observations.append(world.step(dict.fromkeys(world.robots, turn)))
            if state_topics:
                states.append((world.t_ns, world.task.state()))
    for obs in (o for step in observations for o in step.values()):
        stamp, sense = sensing.decode(sensing.encode(obs.stamp_ns, obs.sensed))
        if stamp != obs.stamp_ns or sense != obs.sensed:
            _fail("codecs", f"the sense {obs.sensed!r} stamped {obs.stamp_ns} came back as {sense!r} stamped {stamp}")
    for t_ns, state in states:
        for st in state_topics:
            stamp, value = st.decode(st.encode(t_ns, state[st.field]))
            if stamp != t_ns or value != state[st.field]:
                _fail("codecs", f"state {st.field} on {st.topic} came back as {value!r}")
    for spec in algorithm.servers:
        core = registry.resolve(spec.core)(scenario)
        core.step(0, ())
        for st in outputs_of(spec).state:
            value = core.state()[st.field]
            stamp, decoded = st.decode(st.encode(1_700_000_003, value))
            if stamp != 1_700_000_003 or decoded != value:
                _fail("codecs", f"server {spec.channel}'s state {st.field} on {st.topic} came back as {decoded!r}")


def check_graph_equals_batch(scenario_args: list[str], scenario: Scenario, batch_summary: dict[str, Any],
                             batch_poses: np.ndarray, bag: Path, domain_id: int) -> None:
    """`scenario_args`: swarm-run arguments that load exactly `scenario`."""
    cmd = [sys.executable, "-m", "launch_py.run", "--bag", str(bag), "--json", "--tick-timeout", "20",
           "--domain-id", str(domain_id), *scenario_args]
    result = subprocess.run(cmd, capture_output=True, text=True, timeout=600, env=dict(os.environ))
    if result.returncode != 0:  # the last line says why; the lines before it, what the nodes said
        lines = result.stderr.strip().splitlines() or ["?"]
        _fail("graph_equals_batch", f"swarm-run failed: {lines[-1]}\n" + "\n".join(lines[-60:-1]))
    graph = json.loads(result.stdout.strip().splitlines()[-1])
    for key in (*GRAPH_COMPARED, *(field for p in registry.probes() for field, _ in p.details)):
        if key not in graph and key not in batch_summary:
            continue  # a probe this run does not ask for
        if graph.get(key) != batch_summary.get(key):
            _fail("graph_equals_batch", f"{key}: graph {graph.get(key)!r} != batch {batch_summary.get(key)!r}")
    odometry = load_odometry(bag)
    for i, robot in enumerate(scenario.robot_names):
        rows = odometry.get(robot)
        if rows is None or not np.array_equal(rows[:, 1:], batch_poses[:, i, :]):
            _fail("graph_equals_batch", f"{robot}'s recorded odometry differs from the batch trajectory")


def check_algorithm(
    scenario_name: str, overrides: list[str] | tuple[str, ...] = (), *, robots: int = 4,
    duration: float = 20.0, seed: int = 3, graph_bag: Path | None = None, domain_id: int | None = None,
) -> list[str]:
    """Run the algorithm of scenario `scenario_name` (with `overrides`) through every check;
    the graph check runs only with `graph_bag` (where the bag goes) and `domain_id`. Returns the
    names of the checks passed; raises ConformanceError at the first failure."""
    fields = [*overrides, f"robots.count={robots}", f"sim.duration={duration}"]
    scenario = load_scenario(scenario_name, fields, seed=seed)
    algorithm = registry.of(scenario)
    passed = []
    check_ros_free(algorithm, scenario)
    passed.append("ros_free")
    summary, poses = check_determinism(scenario)
    passed.append("determinism")
    check_codecs(algorithm, scenario)
    passed.append("codecs")
    if graph_bag is not None and domain_id is not None:
        args = ["--scenario", scenario_name, "--seed", str(seed), *(a for f in fields for a in ("--set", f))]
        check_graph_equals_batch(args, scenario, summary, poses, graph_bag, domain_id)
        passed.append("graph_equals_batch")
    return passed
