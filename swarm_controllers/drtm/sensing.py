"""The nest task's sense (`swarm_controllers.drtm.task.NestSense`) on the graph: ``/<robot>/sense``
(`swarm_msgs_py.sensing`), one status per field.

| status | values |
|---|---|
| ``resources`` | pair i: (``"i"``, ``"x y"``) per food token within the detection radius, nearest first [m, world frame] |
| ``carrying`` | (``carrying``, ``true`` or ``false``) |
| ``light`` | (``light``, ``"x y"``): the light vector [robot frame, x forward], length = intensity, ``0.0 0.0`` when not detected |
"""

from __future__ import annotations

from swarm_controllers.drtm.task import NestSense
from swarm_msgs_py.sensing import Sensing, flag, vector, vectors

SENSING = Sensing(NestSense, (vectors("resources", 2), flag("carrying"), vector("light", 2)))
