"""The robots' behaviour statuses as the world node hears them (``/<robot>/status``).

The world records each status as it arrives (the recorder's own discovery would otherwise) and
keeps every robot's last one, checked like any bus message (`swarm_sim.inbound`: within the size
cap, tagged with the run's credential (`swarm_msgs_py.auth`), decodable, from the robot whose
namespace it came on, stamped for a tick the world has sent). Two things read them: the progress
line, where the algorithm's registry record says what to make of them
(`swarm_sim.registry.Algorithm.progress`, e.g. the caging stage), and the end of a run with
``sim.stop_when_finished``, once every live robot's status says its task is over
(``BehaviourStatus.finished``), as the batch runner stops once every behaviour is ``finished``.

A controller publishes its status of tick k before its command k, on another topic, so the
status can arrive after the command that closes the tick; `settle` lets the executor take what
is already there before the world looks, which makes the stop land on the batch runner's tick
(and one tick later at worst).
"""

from __future__ import annotations

from collections.abc import Collection, Mapping

from rclpy.executors import Executor
from rclpy.node import Node

from swarm_msgs_py import auth, diagnostics, topics
from swarm_msgs_py.types import BehaviourStatus, RobotId
from swarm_sim.inbound import Inbound, Reason
from swarm_sim.nodes.qos import EVENTS
from swarm_sim.nodes.world_recording import WorldRecording

_DECODE_STATUS = auth.verified(diagnostics.decode_status)
"""A status must carry the run's tag: a forged `finished` would end the run early."""


class StatusWatch:
    def __init__(self, node: Node, robots: tuple[RobotId, ...], inbound: Inbound, recording: WorldRecording,
                 dt_ns: int) -> None:
        self._robots = robots
        self._inbound = inbound
        self._recording = recording
        self._dt_ns = dt_ns
        self._max_bytes = inbound.bounds.message_bytes if inbound.bounds is not None else None
        self.statuses: dict[RobotId, BehaviourStatus] = {}
        """Each robot's last admitted status."""
        self.subscriptions = {}
        """Topic -> the world's subscription to it (for the foreign-publisher watch)."""
        for robot in robots:
            topic = topics.robot_topic(robot, topics.STATUS)
            recording.add(topic, topics.type_string(topic))
            self.subscriptions[topic] = node.create_subscription(topics.type_of(topic), topic,
                lambda data, r=robot, t=topic: self._on_status(r, t, data), EVENTS, raw=True)

    def _on_status(self, robot: RobotId, topic: str, data: bytes) -> None:
        """Check a status as the world checks any bus message; record it where analysis reads
        what the run took, or on the topic's refused channel."""
        self._recording.write_taken(topic, data, self._take(robot, topic, data))

    def _take(self, robot: RobotId, topic: str, data: bytes) -> bool:
        status = self._inbound.decode(topic, _DECODE_STATUS, data, self._max_bytes)
        if status is None:
            return False
        if status.robot != robot:
            self._inbound.reject(topic, Reason.UNKNOWN_ROBOT, f"status of {status.robot[:40]!r} on {topic}")
            return False
        if not 0 <= status.stamp_ns <= self._inbound.now_ns or status.stamp_ns % self._dt_ns:
            self._inbound.reject(topic, Reason.WRONG_TICK, f"stamped {status.stamp_ns} ns at tick {self._inbound.now_ns} ns")
            return False
        self.statuses[robot] = status
        return True

    def settle(self, executor: Executor, spins: int = 8) -> None:
        """Take what has already arrived (statuses sent just before the commands of this tick)."""
        for _ in range(spins):
            executor.spin_once(timeout_sec=0.0)

    def all_finished(self, dead: Collection[str]) -> bool:
        """Every robot not declared dead has reported that its task is over."""
        live = [r for r in self._robots if r not in dead]
        return bool(live) and all(r in self.statuses and self.statuses[r].finished for r in live)

    def by_robot(self) -> Mapping[RobotId, BehaviourStatus]:
        return self.statuses
