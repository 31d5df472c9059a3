"""The world node's loop: start-up, then one tick after another, lockstep or free-running.

Lockstep (default): for each tick k the node publishes ``/clock`` and every robot's observations
stamped k, this loop spins until every live controller has answered with a ``cmd_vel`` stamped k
and every server with a ``/lockstep/ack`` stamped k (`swarm_sim.nodes.lockstep.LockstepBarrier`),
re-sending the tick to those that are slow every `resend_period`, and closes the tick after
`tick_timeout` wall seconds at the latest (the silent ones are stale; see `WorldNode.close_tick`);
then the world steps. Free-running (`realtime`): steps every dt / real_time_factor wall seconds
with whatever commands have arrived.

Time spent flushing the bag does not count against the controllers' deadline. A stop requested
by a signal (`WorldNode.stop_requested`) raises `Interrupted` at the next spin.
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING

from rclpy.executors import Executor

from swarm_msgs_py.types import NS_PER_S

if TYPE_CHECKING:
    from swarm_sim.nodes.world_node import WorldNode

_IMPORTED = time.monotonic()
"""When the world node's imports were done (start-up lines count from here)."""


POLL_PERIOD = 0.05
"""Wall seconds between the lockstep wait's polls of the bag (it flushes every second)."""


class Interrupted(Exception):
    """SIGINT or SIGTERM arrived: stop at the next safe point and close the bag."""


class WorldLoop:
    def __init__(self, node: WorldNode) -> None:
        self.node = node
        self._next_discovery = 0.0

    def spin(self, executor: Executor, timeout: float) -> float:
        """Spin once; returns the wall seconds the bag took (flush/split), which must not
        count against the controllers' deadline. Raises Interrupted once a stop is requested."""
        if self.node.stop_requested:
            raise Interrupted
        executor.spin_once(timeout_sec=timeout)
        return self.node.recording.poll()

    def run(self, executor: Executor) -> None:
        node = self.node
        cfg, sim, world = node.config, node.scenario.sim, node.world
        node.discover()
        self.wait_for_controllers(executor)
        node.check_foreign()  # at every foreign node; at every topic's count within minutes at 1000 robots
        node.outputs.start_live_view(node.discover)
        obs = world.reset()
        wall0 = last_progress = time.monotonic()
        node.wall_start = wall0
        for k in range(node.scenario.ticks):
            now = time.monotonic()
            if now >= self._next_discovery:
                node.discover()
                self._next_discovery = now + 1.0
            node.publish_tick(obs)
            if cfg.mode == "lockstep":
                self.await_commands(executor)
                if cfg.pace > 0:
                    self.pace(executor, wall0 + (k + 1) * sim.dt / cfg.pace)
            else:
                self.await_wall(executor, wall0 + (k + 1) * sim.dt / cfg.real_time_factor)
            obs = world.step(node.commands())
            node.publish_world_state()
            node.check_finished(executor)
            if now - last_progress >= cfg.progress_period:
                last_progress = now
                self.print_progress(now - wall0)
            if node.ended != "complete":
                break
        node.publish_tick(obs, send=False)
        node.publish_world_state(final=True)
        # Let the controllers' last status messages reach the recorder.
        end = time.monotonic() + 0.5
        while time.monotonic() < end:
            self.spin(executor, 0.05)

    def wait_for_controllers(self, executor: Executor) -> None:
        node = self.node
        robots, servers = node.robots, node.servers
        start = time.monotonic()
        print(f"[world] up ({start - _IMPORTED:.1f} s after its imports to build the world and the topics of "
              f"{len(robots)} robots); waiting for the controllers{' and servers' if servers else ''} to connect",
              flush=True)
        deadline = start + node.config.startup_timeout
        missing = list(robots)
        said = checked = counted = start
        while missing and time.monotonic() < deadline:
            self.spin(executor, 0.1)
            now = time.monotonic()
            if now - checked >= 1.0:
                checked = now
                node.check_foreign()  # foreign nodes by name, counts within the budget
            if now - counted >= 0.1:  # not at each of the start-up's many wake-ups: 5 counts a robot
                counted = now
                missing = node.unconnected(missing)
            if missing and time.monotonic() - said >= node.config.progress_period:
                said = time.monotonic()
                self.print_startup(missing, said - start)
        print(f"[world] {len(robots) - len([m for m in missing if m in robots])}/{len(robots)} "
              f"controllers connected after {time.monotonic() - start:.1f} s: starting", flush=True)
        if missing:
            node.get_logger().warning(
                f"starting without {len(missing)} controller(s) that did not connect: {missing[:5]}"
            )

    def await_commands(self, executor: Executor) -> None:
        """Lockstep barrier: spin until every live controller and server answered this tick.
        One wake-up dispatches one message (the EventsExecutor), so the loop does as little as
        it can per wake-up: the barrier keeps the set of those outstanding, the stop flag is a
        read, and the bag is polled every `POLL_PERIOD`."""
        node = self.node
        stamp = node.world.t_ns
        barrier = node.barrier
        barrier.open_tick(stamp)
        outstanding = barrier.outstanding
        now = time.monotonic()
        deadline, resend = now + node.config.tick_timeout, now + node.config.resend_period
        next_poll = now + POLL_PERIOD
        while outstanding:
            if node.stop_requested:
                raise Interrupted
            now = time.monotonic()
            if now >= deadline:  # take what has already arrived before calling anyone stale
                for _ in range(4 * len(outstanding)):
                    executor.spin_once(timeout_sec=0.0)
                break
            if now >= resend:  # a sample lost (e.g. while discovery settles): ask again
                resend = now + node.config.resend_period
                node.resend([p for p in barrier.live() if p in outstanding], stamp)
            executor.spin_once(timeout_sec=min(0.05, deadline - now))
            if now >= next_poll:
                bag_time = node.recording.poll()  # flushing the bag is not the controllers' time
                deadline += bag_time
                resend += bag_time
                next_poll = now + POLL_PERIOD
        node.close_tick(stamp)

    def await_wall(self, executor: Executor, until: float) -> None:
        """Free-running: spin until `until` (wall); the robots that did not answer are stale."""
        node = self.node
        while (remaining := until - time.monotonic()) > 0:
            self.spin(executor, min(0.05, remaining))
        stamp = node.world.t_ns
        for r in node.barrier.waiting(stamp, node.robots):
            node.world.stats[r].stale_ticks += 1

    def pace(self, executor: Executor, until: float) -> None:
        """Lockstep at a watchable pace: spin (the next tick's answers may not come before it is
        sent, so nothing is missed) until `until` (wall)."""
        while (remaining := until - time.monotonic()) > 0:
            self.spin(executor, min(0.05, remaining))

    def print_startup(self, missing: list[str], waited: float) -> None:
        """What the start-up is waiting for (nodes starting and discovering each other)."""
        node = self.node
        robots = [m for m in missing if m in node.robots]
        others = [m for m in missing if m not in node.robots]
        text = f"{len(node.robots) - len(robots)}/{len(node.robots)} controllers connected"
        if robots:
            text += f", waiting for {', '.join(robots[:3])}{' ...' if len(robots) > 3 else ''}"
        if others:
            text += f"; waiting for {', '.join(others)}"
        print(f"[world] start-up {waited:5.1f} s: {text} (gives up after {node.config.startup_timeout:.0f} s)",
              flush=True)

    def print_progress(self, wall: float) -> None:
        node = self.node
        t = node.world.t_ns / NS_PER_S
        stale = sum(s.stale_ticks for s in node.world.stats.values())
        print(
            f"[world] t={t:7.1f}/{node.scenario.sim.duration:.0f} s  rtf={t / max(wall, 1e-9):5.2f}x  "
            f"{node.progress_text()}  stale={stale}",
            flush=True,
        )
