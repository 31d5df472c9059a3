"""A dummy algorithm packaged apart from swarmforage, as a third-party plug-in is: its own
behaviour, world task, server, message family, metric and scenario, registered through the
``swarmforage.algorithms`` entry point (`dummy_algorithm.registration`)."""
