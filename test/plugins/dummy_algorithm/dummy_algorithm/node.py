"""The dummy's counter server on the graph: all it declares is its channel."""

from __future__ import annotations

import sys

from dummy_algorithm.messages import COUNTER
from swarm_sim.nodes.server_node import ServerNode, ServerNodeConfig, run_server


class CounterNode(ServerNode):
    CHANNEL = COUNTER

    def __init__(self, config: ServerNodeConfig | None = None, **kwargs) -> None:
        super().__init__("counter", config, **kwargs)


def main(argv: list[str] | None = None) -> int:
    return run_server(CounterNode, "dummy-counter", argv)


if __name__ == "__main__":
    sys.exit(main())
