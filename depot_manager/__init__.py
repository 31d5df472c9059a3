"""depot_manager: docks, queue geometry and admission for the central depot.

Filled by the depot-manager issue (queue_depot_traffic.md). Until then the central depot is
only the CPFA nest: a drop zone described by `swarm_sim.scenario.DepotConfig`.
"""
