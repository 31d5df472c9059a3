"""The foraging task's sense (`swarm_sim.world.tasks.foraging.ForagingSense`) on the graph:
``/<robot>/sense`` (`swarm_msgs_py.sensing`), one status per field.

| status | values |
|---|---|
| ``resources`` | pair i: (``"i"``, ``"x y"``) per resource within the detection radius, nearest first [m, world frame] |
| ``carrying`` | (``carrying``, ``true`` or ``false``) |
"""

from __future__ import annotations

from swarm_msgs_py.sensing import Sensing, flag, vectors
from swarm_sim.world.tasks.foraging import ForagingSense

SENSING = Sensing(ForagingSense, (vectors("resources", 2), flag("carrying")))
