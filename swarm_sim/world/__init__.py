"""The simulated world: the `World` core (physics, robots, scan) and its world tasks."""

from swarm_sim.world.core import World

__all__ = ["World"]
