"""World tasks: an experiment's world logic, in the manner of ARGoS loop functions.

The `World` core owns physics, the robots and the scan. A task owns everything specific to one
experiment: what it places (resources, a light, a movable object, landmarks), what each robot
additionally senses (its *sense*: one reading per robot and tick, carried by the observation as
``Observation.sensed``), the events it emits and its per-step bookkeeping. Foraging
(`swarm_sim.world.tasks.foraging`) is the first task. Which task a scenario runs is the
registered algorithm's choice (`swarm_sim.registry`); how a sense travels on the graph (one
message a robot and tick, a status per field) is `swarm_msgs_py.sensing`, and each task's
`Sensing` record names its fields' codecs.

The hooks, called by the world in this order:

- construction (inside `World` building tick 0, after the robots and walls exist): place things
  (bodies of its own included), with two seed sequences of the run's seed that belong to the
  task; it may move the robots to where they start (`World.place_robots`);
- optionally ``after_substep(h)`` after every physics substep of h seconds (forces of its own,
  e.g. floor friction on a body it added);
- `post_step(stamp_ns)` after every tick's physics and odometry (ARGoS PostStep);
- `sense()` when the world builds the observations of the current tick;
- `moved()` when robots were teleported (scripted set-ups);
- `drain_events()`, `placed()`, `progress()` for the nodes, the batch runner and markers;
- optionally ``state()``: named values of the current tick that the world node publishes on
  world-level topics and the batch runner keeps as time series (the task's ``state`` record,
  `swarm_msgs_py.sensing.StateTopic`; the transport task: the object's and the robots' true
  positions).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any, Protocol

import numpy as np


class WorldTask(Protocol):
    """One experiment's world logic."""

    def post_step(self, stamp_ns: int) -> None:
        """Bookkeeping for the tick that ends at `stamp_ns` (robots already moved)."""
        ...

    def sense(self) -> Sequence[Any]:
        """Each robot's extra reading for the current tick, in the world's robot order."""
        ...

    def moved(self) -> None:
        """Robots were put somewhere else outside a step: drop what depends on positions."""
        ...

    def drain_events(self) -> list[Any]:
        """Events since the last drain, in the order they happened."""
        ...

    def placed(self) -> Mapping[str, np.ndarray]:
        """Named (M, 2) point sets the task has placed in the world now [m, world frame]."""
        ...

    def progress(self) -> str:
        """A few words for progress lines (``delivered=12``)."""
        ...
