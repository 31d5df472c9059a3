"""The nest node: the DRTM paper's nest server (`swarm_controllers.drtm.nest.NestServer`) on the graph.

Robots report on ``/nest/reports``; every tick the nest publishes its state on ``/nest/state``
(reliable + transient-local, so ``ros2 topic echo /nest/state`` shows F(t), N_W and the recent
OAE count at once).
"""

from __future__ import annotations

import sys

from swarm_controllers.drtm.protocol import NEST
from swarm_sim.nodes.server_node import ServerNode, ServerNodeConfig, run_server


class NestNode(ServerNode):
    CHANNEL = NEST

    def __init__(self, config: ServerNodeConfig | None = None, **kwargs) -> None:
        super().__init__("nest", config, **kwargs)


def main(argv: list[str] | None = None) -> int:
    return run_server(NestNode, "swarm-nest", argv)


if __name__ == "__main__":
    sys.exit(main())
