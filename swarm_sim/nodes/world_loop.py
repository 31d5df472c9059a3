"""The world node's loop: start-up, then one tick after another, lockstep or free-running.

Lockstep (default): for each tick k the node publishes ``/clock`` and every robot's observations
stamped k, this loop spins until every live controller has answered with a ``cmd_vel`` stamped k
and every server with a ``/lockstep/ack`` stamped k (`swarm_sim.nodes.lockstep.LockstepBarrier`),
re-sending the tick to those that are slow every `resend_period`, and closes the tick after
`tick_timeout` wall seconds at the latest (the silent ones are stale; see `LoopHost.close_tick`);
then the world steps. Free-running (`realtime`): steps every dt / real_time_factor wall seconds
with whatever commands have arrived.

Time spent flushing the bag does not count against the controllers' deadline. A stop requested
by a signal (`LoopHost.stop_requested`) raises `Interrupted` at the next spin.

The loop sees the node only through `LoopHost`, the few things it reads and calls (the world
node is one; the loop writes none of its fields), so it can be read, and changed, without the
node's hundreds of members.
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING, Protocol

from rclpy.executors import Executor

from swarm_msgs_py.types import NS_PER_S

if TYPE_CHECKING:
    from rclpy.impl.rcutils_logger import RcutilsLogger

    from swarm_msgs_py.types import Command, Observation, RobotId
    from swarm_sim.nodes.lockstep import LockstepBarrier
    from swarm_sim.scenario import Scenario
    from swarm_sim.world.core import World

_IMPORTED = time.monotonic()
"""When the world node's imports were done (start-up lines count from here)."""


POLL_PERIOD = 0.05
"""Wall seconds between the lockstep wait's polls of the bag (it flushes every second)."""


class Interrupted(Exception):
    """SIGINT or SIGTERM arrived: stop at the next safe point and close the bag."""


class LoopSettings(Protocol):
    """The loop's settings (the world node's config carries them, with their meaning)."""

    @property
    def mode(self) -> str: ...
    @property
    def tick_timeout(self) -> float: ...
    @property
    def resend_period(self) -> float: ...
    @property
    def real_time_factor(self) -> float: ...
    @property
    def pace(self) -> float: ...
    @property
    def startup_timeout(self) -> float: ...
    @property
    def progress_period(self) -> float: ...


class LoopHost(Protocol):
    """What the loop reads and calls on the node that owns the run (the world node): the world
    it steps, the barrier it waits on, and the node's steps of a tick."""

    @property
    def config(self) -> LoopSettings: ...
    @property
    def scenario(self) -> Scenario: ...
    @property
    def world(self) -> World: ...
    @property
    def robots(self) -> tuple[RobotId, ...]: ...
    @property
    def servers(self) -> tuple[str, ...]:
        """Server channels the barrier waits for besides the robots."""
    @property
    def barrier(self) -> LockstepBarrier: ...
    @property
    def stop_requested(self) -> bool:
        """A signal asked the run to stop."""
    @property
    def ended(self) -> str:
        """``complete`` while the run goes on; anything else ends it after this tick."""

    def get_logger(self) -> RcutilsLogger: ...

    def poll_recording(self) -> float:
        """Let the bag flush or split; the wall seconds that took."""

    def start_live_view(self) -> None: ...

    def discover(self) -> None:
        """Find the graph's topics and any foreign publisher on the run's."""

    def check_foreign(self) -> None:
        """Find foreign publishers on the run's topics (cheaper than `discover`)."""

    def unconnected(self, among: list[str]) -> list[str]:
        """Those of `among` (robots; servers by name) not connected yet."""

    def publish_tick(self, obs: dict[RobotId, Observation], *, send: bool = True) -> None:
        """The tick's clock and observations (`send=False`: recorded, nobody asked to answer)."""

    def resend(self, waiting: list[str], stamp: int) -> None:
        """Tick `stamp` again to those of `waiting`."""

    def close_tick(self, stamp: int) -> None:
        """Lockstep tick `stamp` is over: count the stale, declare the dead."""

    def commands(self) -> dict[RobotId, Command]:
        """The commands the world steps with."""

    def publish_world_state(self, final: bool = False) -> None:
        """What follows a step (events, stats, markers, diagnostics)."""

    def check_finished(self, executor: Executor) -> None:
        """Set `ended` if the run is over before its time (``sim.stop_when_finished``)."""

    def progress_text(self) -> str: ...


class WorldLoop:
    def __init__(self, host: LoopHost) -> None:
        self.host = host
        self._next_discovery = 0.0
        self.wall_start: float | None = None
        """When the first tick began (monotonic wall seconds); None before."""

    def spin(self, executor: Executor, timeout: float) -> float:
        """Spin once; returns the wall seconds the bag took (flush/split), which must not
        count against the controllers' deadline. Raises Interrupted once a stop is requested."""
        if self.host.stop_requested:
            raise Interrupted
        executor.spin_once(timeout_sec=timeout)
        return self.host.poll_recording()

    def run(self, executor: Executor) -> None:
        host = self.host
        cfg, sim, world = host.config, host.scenario.sim, host.world
        host.discover()
        self.wait_for_controllers(executor)
        host.check_foreign()  # at every foreign node; at every topic's count within minutes at 1000 robots
        host.start_live_view()
        obs = world.reset()
        wall0 = last_progress = self.wall_start = time.monotonic()
        for k in range(host.scenario.ticks):
            now = time.monotonic()
            if now >= self._next_discovery:
                host.discover()
                self._next_discovery = now + 1.0
            host.publish_tick(obs)
            if cfg.mode == "lockstep":
                self.await_commands(executor)
                if cfg.pace > 0:
                    self.pace(executor, wall0 + (k + 1) * sim.dt / cfg.pace)
            else:
                self.await_wall(executor, wall0 + (k + 1) * sim.dt / cfg.real_time_factor)
            obs = world.step(host.commands())
            host.publish_world_state()
            host.check_finished(executor)
            if now - last_progress >= cfg.progress_period:
                last_progress = now
                self.print_progress(now - wall0)
            if host.ended != "complete":
                break
        host.publish_tick(obs, send=False)
        host.publish_world_state(final=True)
        # Let the controllers' last status messages reach the recorder.
        end = time.monotonic() + 0.5
        while time.monotonic() < end:
            self.spin(executor, 0.05)

    def wait_for_controllers(self, executor: Executor) -> None:
        host = self.host
        robots, servers = host.robots, host.servers
        start = time.monotonic()
        print(f"[world] up ({start - _IMPORTED:.1f} s after its imports to build the world and the topics of "
              f"{len(robots)} robots); waiting for the controllers{' and servers' if servers else ''} to connect",
              flush=True)
        deadline = start + host.config.startup_timeout
        missing = list(robots)
        said = checked = counted = start
        while missing and time.monotonic() < deadline:
            self.spin(executor, 0.1)
            now = time.monotonic()
            if now - checked >= 1.0:
                checked = now
                host.check_foreign()  # foreign nodes by name, counts within the budget
            if now - counted >= 0.1:  # not at each of the start-up's many wake-ups: 5 counts a robot
                counted = now
                missing = host.unconnected(missing)
            if missing and time.monotonic() - said >= host.config.progress_period:
                said = time.monotonic()
                self.print_startup(missing, said - start)
        print(f"[world] {len(robots) - len([m for m in missing if m in robots])}/{len(robots)} "
              f"controllers connected after {time.monotonic() - start:.1f} s: starting", flush=True)
        if missing:
            host.get_logger().warning(
                f"starting without {len(missing)} controller(s) that did not connect: {missing[:5]}"
            )

    def await_commands(self, executor: Executor) -> None:
        """Lockstep barrier: spin until every live controller and server answered this tick.
        One wake-up dispatches one message (the EventsExecutor), so the loop does as little as
        it can per wake-up: the barrier keeps the set of those outstanding, the stop flag is a
        read, and the bag is polled every `POLL_PERIOD`."""
        host = self.host
        stamp = host.world.t_ns
        barrier = host.barrier
        barrier.open_tick(stamp)
        outstanding = barrier.outstanding
        now = time.monotonic()
        deadline, resend = now + host.config.tick_timeout, now + host.config.resend_period
        next_poll = now + POLL_PERIOD
        while outstanding:
            if host.stop_requested:
                raise Interrupted
            now = time.monotonic()
            if now >= deadline:  # take what has already arrived before calling anyone stale
                for _ in range(4 * len(outstanding)):
                    executor.spin_once(timeout_sec=0.0)
                break
            if now >= resend:  # a sample lost (e.g. while discovery settles): ask again
                resend = now + host.config.resend_period
                host.resend([p for p in barrier.live() if p in outstanding], stamp)
            executor.spin_once(timeout_sec=min(0.05, deadline - now))
            if now >= next_poll:
                bag_time = host.poll_recording()  # flushing the bag is not the controllers' time
                deadline += bag_time
                resend += bag_time
                next_poll = now + POLL_PERIOD
        host.close_tick(stamp)

    def await_wall(self, executor: Executor, until: float) -> None:
        """Free-running: spin until `until` (wall); the robots that did not answer are stale."""
        host = self.host
        while (remaining := until - time.monotonic()) > 0:
            self.spin(executor, min(0.05, remaining))
        stamp = host.world.t_ns
        for r in host.barrier.waiting(stamp, host.robots):
            host.world.stats[r].stale_ticks += 1

    def pace(self, executor: Executor, until: float) -> None:
        """Lockstep at a watchable pace: spin (the next tick's answers may not come before it is
        sent, so nothing is missed) until `until` (wall)."""
        while (remaining := until - time.monotonic()) > 0:
            self.spin(executor, min(0.05, remaining))

    def print_startup(self, missing: list[str], waited: float) -> None:
        """What the start-up is waiting for (nodes starting and discovering each other)."""
        host = self.host
        robots = [m for m in missing if m in host.robots]
        others = [m for m in missing if m not in host.robots]
        text = f"{len(host.robots) - len(robots)}/{len(host.robots)} controllers connected"
        if robots:
            text += f", waiting for {', '.join(robots[:3])}{' ...' if len(robots) > 3 else ''}"
        if others:
            text += f"; waiting for {', '.join(others)}"
        print(f"[world] start-up {waited:5.1f} s: {text} (gives up after {host.config.startup_timeout:.0f} s)",
              flush=True)

    def print_progress(self, wall: float) -> None:
        host = self.host
        t = host.world.t_ns / NS_PER_S
        stale = sum(s.stale_ticks for s in host.world.stats.values())
        print(
            f"[world] t={t:7.1f}/{host.scenario.sim.duration:.0f} s  rtf={t / max(wall, 1e-9):5.2f}x  "
            f"{host.progress_text()}  stale={stale}",
            flush=True,
        )
