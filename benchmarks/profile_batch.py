"""Where each millisecond of a batch-runner tick goes, phase by phase (issue 14's profile).

    python benchmarks/profile_batch.py --robots 112 1000 --scenario cpfa queue_qmt
    python benchmarks/profile_batch.py --robots 112 --scenario cpfa --duration 60 --repeat 3
    python benchmarks/profile_batch.py --robots 1000 --warmup 60   # robots spread out first
    python benchmarks/profile_batch.py --scenario queue_qmt --set robots.model=footbot_cpfa   # a robot model

Each (scenario, robots) pair is run with the same seed plain (only the tick window is marked:
the real-time factor) and instrumented, alternated ``--repeat`` times; the table is the
instrumented run of median length, the real-time factor the plain runs' median. The instrumented run is `run_batch`
itself, untouched: the benchmark swaps the names `swarm_sim.batch` looks up (`World`,
`make_servers`, `Router`, `make_probes`, ...), the world's scan functions and the behaviour
class's ``step`` for versions wrapped in a `time.perf_counter` timer, and restores them
afterwards. A timer stack gives each phase its exclusive time (a behaviour's obstacle avoidance
is taken out of the behaviour, the scan out of ``World.observe``), and Python's garbage
collector is timed through ``gc.callbacks`` and taken out of the phase it interrupted, so the
phases plus "other" add up to the measured tick exactly. "other" is what no wrapper covers:
`run_batch`'s own loop (the commands dict, the message loop) and the timers' own cost.

The measured ticks run from the start of the first tick after ``--warmup`` sim seconds to the
end of the last: tick boundaries are the calls of the probes' ``update`` (`make_probes`: the
statement that opens every tick of `run_batch` and follows its last one; a marker probe is added
first). Set-up, the final status and the
trace's wrap-up are not per-tick work and are left out. The robots start on a grid around the
depot, so the first minute's ticks are the crowded ones (more robot pairs within scan range).

Scaled arenas: ``--arena N=SIDE`` gives the runs of N robots a SIDE x SIDE m arena (default
``1000=38``, issue 14's 1000 robots on 38 x 38 m); their clustered resources scale with the area
(more 8 x 8 clusters of the scenario's: 1000 robots, 50 clusters, 3,200 resources). The depot is
not scaled (one depot for the whole swarm, as in the scenario).
"""

from __future__ import annotations

import argparse
import contextlib
import gc
import math
import resource
import sys
import time
from collections import defaultdict
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from typing import Any

import swarm_sim.batch as batch
import swarm_sim.world.core as world_core
from swarm_controllers.avoidance import AvoidThenEscape, ObstacleAvoidance
from swarm_controllers.robots.stop_turn_go import StopTurnGo
from swarm_controllers.robots.wheel_turning import WheelTurning
from swarm_sim.behaviour import behaviour_rng
from swarm_sim.scenario import Scenario, ScenarioError, load_scenario
from swarm_sim.world.core import tune_malloc

GROUPS = ("world", "behaviours", "routing", "servers", "bookkeeping", "gc")
"""Phase names start with one of these (then ':'); the table prints a subtotal per group."""

AVOIDANCE = (ObstacleAvoidance, AvoidThenEscape, StopTurnGo, WheelTurning)
"""The behaviours' obstacle avoidance (the scan's consumer; the robot models' own for the
foot-bots): its ``update`` is a phase."""


class _TimedPybullet:
    """The pybullet module as `swarm_sim.world.core` sees it, with the calls made a few times per
    tick (not per robot) timed: the physics phase split into pybullet's own work and the
    per-robot Python around it."""

    def __init__(self, module: Any, timers: Timers) -> None:
        self._module = module
        self.stepSimulation = timers.wrap("world: physics: pybullet stepSimulation", module.stepSimulation)
        self.getContactPoints = timers.wrap("world: physics: pybullet getContactPoints", module.getContactPoints)

    def __getattr__(self, name: str) -> Any:
        return getattr(self._module, name)


class Timers:
    """Exclusive time per phase: a stack of the child time of every open timer."""

    def __init__(self) -> None:
        self.seconds: dict[str, float] = defaultdict(float)
        self.calls: dict[str, int] = defaultdict(int)
        self._stack: list[float] = []
        self._gc_t0 = 0.0

    def wrap(self, name: str, fn: Callable[..., Any]) -> Callable[..., Any]:
        stack, seconds, calls, clock = self._stack, self.seconds, self.calls, time.perf_counter

        def timed(*args: Any, **kwargs: Any) -> Any:
            stack.append(0.0)
            t0 = clock()
            try:
                return fn(*args, **kwargs)
            finally:
                dt = clock() - t0
                seconds[name] += dt - stack.pop()
                calls[name] += 1
                if stack:
                    stack[-1] += dt

        return timed

    def gc_callback(self, phase: str, info: dict) -> None:
        """``gc.callbacks`` hook: the collector's pauses are a phase of their own."""
        if phase == "start":
            self._gc_t0 = time.perf_counter()
            return
        dt = time.perf_counter() - self._gc_t0
        self.seconds["gc: Python garbage collector"] += dt
        self.calls["gc: Python garbage collector"] += 1
        if self._stack:
            self._stack[-1] += dt

    def reset(self) -> None:
        self.seconds.clear()
        self.calls.clear()


@dataclass
class TickWindow:
    """The measured ticks of a run: from the start of tick `skip` to the end of the last."""

    skip: int = 0
    start: float = math.nan
    end: float = math.nan
    cpu_start: float = math.nan
    cpu_end: float = math.nan
    """The same window on the process's CPU clock (`time.process_time`): on a shared machine
    other processes stretch the wall time, not this."""
    marks: int = 0
    seconds: dict[str, float] = field(default_factory=dict)
    calls: dict[str, int] = field(default_factory=dict)

    def mark(self, timers: Timers | None) -> None:
        """A tick boundary (a probe's ``update``, `TickMarker`): opens the window or extends it."""
        self.end = time.perf_counter()
        self.cpu_end = time.process_time()
        self.marks += 1
        if self.marks == self.skip + 1:
            self.start = self.end
            self.cpu_start = self.cpu_end
            if timers is not None:
                timers.reset()
        elif timers is not None:
            self.seconds = dict(timers.seconds)
            self.calls = dict(timers.calls)

    @property
    def ticks(self) -> int:
        return self.marks - 1 - self.skip


@dataclass
class Profile:
    scenario: Scenario
    ticks: int
    window_s: float
    """Wall time of the ticks [s] (set-up and wrap-up excluded)."""
    run_s: float
    """Wall time of the whole `run_batch` call [s]."""
    phases: dict[str, float]
    """Exclusive wall time per phase over the window [s]; "other" is the rest."""
    calls: dict[str, int]
    run: batch.BatchRun
    window_cpu_s: float = math.nan
    """CPU time of the ticks [s] (`TickWindow.cpu_start`)."""

    @property
    def ms_per_tick(self) -> float:
        return 1e3 * self.window_s / self.ticks

    @property
    def cpu_ms_per_tick(self) -> float:
        return 1e3 * self.window_cpu_s / self.ticks

    @property
    def real_time_factor(self) -> float:
        return self.ticks * self.scenario.sim.dt / self.window_s if self.window_s > 0 else math.inf


def _instrument_instance(obj: Any, timers: Timers | None, methods: dict[str, str]) -> None:
    """Replace `obj`'s bound methods (name -> phase) by timed ones (instance attributes only)."""
    if timers is None:
        return
    for method, phase in methods.items():
        setattr(obj, method, timers.wrap(phase, getattr(obj, method)))


@contextlib.contextmanager
def _patched(targets: list[tuple[Any, str, Any]]) -> Iterator[None]:
    saved = [(obj, name, getattr(obj, name)) for obj, name, _ in targets]
    try:
        for obj, name, value in targets:
            setattr(obj, name, value)
        yield
    finally:
        for obj, name, value in saved:
            setattr(obj, name, value)


class TickMarker:
    """A probe that observes nothing: its ``update`` opens each measured tick (`TickWindow`)."""

    def __init__(self, window: Any, timers: Any) -> None:
        self._window, self._timers = window, timers

    def update(self, _t: float, _xy: Any) -> None:
        self._window.mark(self._timers)

    def result(self) -> None:
        return None


def profile_run(
    scenario: Scenario, *, instrument: bool = True, warmup_ticks: int = 0, record_poses: bool = False
) -> Profile:
    """One `run_batch` of `scenario`; with `instrument`, the time of every phase of the ticks
    after the first `warmup_ticks`."""
    timers = Timers() if instrument else None
    window = TickWindow(warmup_ticks)
    world_cls, probes_of, router_cls, rule_cls = batch.World, batch.make_probes, batch.Router, batch.RuleLog
    wrap = timers.wrap if timers else (lambda _name, fn: fn)

    def make_world(s: Scenario, *args: Any) -> Any:
        world = world_cls(s, *args)
        task = world.task
        _instrument_instance(world, timers, {
            "_physics": "world: physics: per-body velocities + contact loop (Python)",
            "_read_state": "world: pose read-back (pybullet)",
            "_apply_commands": "world: commands + odometry",
            "_odometry": "world: commands + odometry",
            "observe": "world: observation assembly (Observation objects)",
            "step": "world: step() rest",
        })
        _instrument_instance(task, timers, {
            "sense": f"world: task sense ({type(task).__name__})",
            "post_step": f"world: task post_step ({type(task).__name__}: pick-ups, drops)",
        })
        return world

    def make_servers(s: Scenario) -> dict:
        servers = batch_make_servers(s)
        for server in servers.values():
            _instrument_instance(server, timers, {"step": f"servers: {type(server).__name__}.step"})
        return servers

    def make_router() -> Any:
        router = router_cls()
        _instrument_instance(router, timers, {
            "post": "routing: Router.post", "take_before": "routing: Router.take_before",
        })
        return router

    def make_probes(*args: Any) -> dict[str, Any]:
        probes = probes_of(*args)
        for probe in probes.values():
            probe.update = wrap("bookkeeping: probes (perimeter log)", probe.update)
        return {"tick marker": TickMarker(window, timers), **probes}

    def make_rule_log(*args: Any) -> Any:
        log = rule_cls(*args)
        log.update = wrap("bookkeeping: state rules (ring vectors, statuses)", log.update)
        return log

    batch_make_servers = batch.make_servers
    targets: list[tuple[Any, str, Any]] = [(batch, "World", make_world), (batch, "make_probes", make_probes)]
    if timers is not None:
        # The behaviours have slots (no instance attribute can shadow a method): their class's
        # step is timed, for the run only. A throwaway behaviour names the class.
        behaviour_cls = type(batch.make_behaviour(scenario, "robot_0", behaviour_rng(scenario.seed, "robot_0")))
        targets += [
            (behaviour_cls, "step", wrap(f"behaviours: {behaviour_cls.__name__}.step", behaviour_cls.step)),
            (batch, "make_servers", make_servers),
            (batch, "Router", make_router),
            (batch, "with_messages", wrap("routing: inbox into observations", batch.with_messages)),
            (batch, "_collect_events", wrap("bookkeeping: events + trace", batch._collect_events)),
            (batch, "_record_state", wrap("bookkeeping: events + trace", batch._record_state)),
            (batch, "RuleLog", make_rule_log),
            (world_core, "p", _TimedPybullet(world_core.p, timers)),
            (world_core, "cast_scan", wrap("world: ray casting (scan)", world_core.cast_scan)),
            (world_core, "cast_scan_pybullet", wrap("world: ray casting (scan)", world_core.cast_scan_pybullet)),
        ]
        targets += [(cls, "update", wrap("behaviours: obstacle avoidance", cls.update)) for cls in AVOIDANCE]
        gc.callbacks.append(timers.gc_callback)
    t0 = time.perf_counter()
    try:
        with _patched(targets):
            run = batch.run_batch(scenario, record_poses=record_poses)
    finally:
        if timers is not None:
            gc.callbacks.remove(timers.gc_callback)
    run_s = time.perf_counter() - t0
    if window.ticks < 1:
        raise ValueError(f"no tick after the {warmup_ticks} warm-up ticks (the run has {window.marks - 1})")
    window_s = window.end - window.start
    phases = dict(window.seconds)
    phases["other (run_batch loop, timers)"] = window_s - sum(phases.values())
    return Profile(scenario, window.ticks, window_s, run_s, phases, dict(window.calls), run,
                   window.cpu_end - window.cpu_start)


def scaled_fields(scenario: str, robots: int, arena: float | None) -> dict[str, Any]:
    """load_scenario fields: `robots`, and an `arena` side [m] (None: the scenario's) with the
    scenario's clustered resources scaled with the area (whole clusters)."""
    fields: dict[str, Any] = {"robots__count": robots}
    if arena is None:
        return fields
    base = load_scenario(scenario)
    fields["arena__size"] = float(arena)
    factor = (arena / base.arena.size) ** 2
    res = base.resources
    if res.distribution == "clustered":
        clusters = max(1, round(res.clusters * factor))
        fields["resources__clusters"] = clusters
        fields["resources__count"] = clusters * res.cluster_side**2
    else:
        fields["resources__count"] = max(1, round(res.count * factor))
    return fields


def arena_override(text: str) -> tuple[int, float]:
    """argparse type of ``--arena``: ``ROBOTS=SIDE``."""
    try:
        n, side = text.split("=")
        return int(n), float(side)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected ROBOTS=SIDE (e.g. 1000=38), got {text!r}") from None


def timer_overhead_s() -> float:
    """Cost of one timed call beyond the call itself [s] (median of a few measurements)."""
    timers = Timers()
    timed = timers.wrap("x", len)
    n, samples = 20000, []
    for _ in range(5):
        t0 = time.perf_counter()
        for _ in range(n):
            timed(())
        t1 = time.perf_counter()
        for _ in range(n):
            len(())
        samples.append((t1 - t0 - (time.perf_counter() - t1)) / n)
    return sorted(samples)[2]


def print_profile(prof: Profile, plains: list[Profile], overhead_s: float) -> None:
    s = prof.scenario
    n = s.robots.count
    print(f"\n== {s.name}, {n} robots ({s.robots.model}{', planar' if s.robots.planar else ''}), "
          f"{s.arena.size:g} x {s.arena.size:g} m, {s.resources.count} resources, "
          f"ticks {s.ticks - prof.ticks}-{s.ticks - 1} of {s.sim.dt:g} s, seed {s.seed}")
    ms = sorted(p.ms_per_tick for p in plains)
    plain = sorted(plains, key=lambda p: p.ms_per_tick)[len(plains) // 2]
    spread = f" (range {ms[0]:.2f}-{ms[-1]:.2f} over {len(ms)} runs)" if len(ms) > 1 else ""
    print(f"plain run:        {plain.ms_per_tick:7.2f} ms/tick{spread}, "
          f"real-time factor {plain.real_time_factor:6.1f}x, "
          f"delivered {len(plain.run.trace.drops)}")
    cpu = sorted(p.cpu_ms_per_tick for p in plains)
    print(f"plain run, CPU:   {cpu[len(cpu) // 2]:7.2f} ms/tick of CPU time (range {cpu[0]:.2f}-{cpu[-1]:.2f}; "
          f"what other processes on the machine do not stretch)")
    calls = sum(prof.calls.values())
    print(f"instrumented run: {prof.ms_per_tick:7.2f} ms/tick, real-time factor {prof.real_time_factor:6.1f}x, "
          f"delivered {len(prof.run.trace.drops)}; {calls / prof.ticks:.0f} timed calls/tick, "
          f"timer cost ~{1e3 * overhead_s * calls / prof.ticks:.2f} ms/tick (inside 'other' and the phases)")
    total = prof.window_s
    per_tick = 1e3 / prof.ticks
    print(f"{'phase':62s} {'ms/tick':>8s} {'%':>6s} {'us/robot':>9s}")

    def row(seconds: float) -> str:
        return f"{seconds * per_tick:8.3f} {100 * seconds / total:6.1f} {1e3 * seconds * per_tick / n:9.2f}"

    rows = sorted(prof.phases.items(), key=lambda kv: (_group_rank(kv[0]), -kv[1]))
    group = None
    for name, sec in rows:
        g = name.split(":")[0] if ":" in name else "other"
        if g != group and g in GROUPS:
            sub = sum(v for k, v in prof.phases.items() if k.startswith(g + ":"))
            print(f"{g + ' (total)':62s} {row(sub)}")
        group = g
        indent = "  " if g in GROUPS else ""
        print(f"{indent}{name:{62 - len(indent)}s} {row(sec)}")
    print(f"{'TOTAL (measured tick)':62s} {row(total)}")
    print(f"sum of phases {sum(prof.phases.values()) * per_tick:.3f} ms/tick; peak RSS so far "
          f"{resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:.0f} MB", flush=True)


def _group_rank(name: str) -> int:
    g = name.split(":")[0]
    return GROUPS.index(g) if g in GROUPS else len(GROUPS)


def main(argv: list[str] | None = None) -> int:
    tune_malloc()  # as the commands that run a world do (`tune_malloc`): time it as they run it
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robots", type=int, nargs="+", default=[112, 1000])
    parser.add_argument("--scenario", nargs="+", default=["cpfa", "queue_qmt"])
    parser.add_argument("--duration", type=float, default=None,
                        help="sim seconds per run (default: 60 s below 500 robots, 10 s from 500)")
    parser.add_argument("--arena", type=arena_override, nargs="*", default=[(1000, 38.0)], metavar="ROBOTS=SIDE",
                        help="arena side [m] for runs of ROBOTS robots, resources scaled with the area "
                             "(default 1000=38)")
    parser.add_argument("--warmup", type=float, default=0.0, help="sim seconds run before the measured ticks")
    parser.add_argument("--repeat", type=int, default=1, help="plain and instrumented runs, alternated")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                        help="any scenario field, e.g. robots.model=footbot_cpfa or robots.planar=true")
    args = parser.parse_args(argv)
    overhead = timer_overhead_s()
    print(f"timer cost {1e9 * overhead:.0f} ns per timed call", flush=True)
    for name in args.scenario:
        for n in sorted(args.robots):
            duration = args.duration or (60.0 if n < 500 else 10.0)
            try:
                fields = scaled_fields(name, n, dict(args.arena).get(n))
                scenario = load_scenario(name, args.overrides, **fields, sim__duration=args.warmup + duration,
                                         seed=args.seed)
            except ScenarioError as exc:
                print(f"profile_batch: {exc}", file=sys.stderr)
                return 2
            warmup = round(args.warmup / scenario.sim.dt)
            plains, profs = [], []
            for _ in range(max(1, args.repeat)):
                plains.append(profile_run(scenario, instrument=False, warmup_ticks=warmup))
                profs.append(profile_run(scenario, warmup_ticks=warmup))
            print_profile(sorted(profs, key=lambda p: p.window_s)[len(profs) // 2], plains, overhead)
    return 0


if __name__ == "__main__":
    sys.exit(main())
