"""The simulated world: the `World` core (physics, robots, scan) and its world tasks.

`World` is imported on first use, so that importing a task's sense type (as the controller
processes do) does not load pybullet.
"""

from typing import Any

__all__ = ["World"]


def __getattr__(name: str) -> Any:
    if name == "World":
        # lazy: a task's sense types live in this package; importing them must not load pybullet
        from swarm_sim.world.core import World

        return World
    raise AttributeError(name)
