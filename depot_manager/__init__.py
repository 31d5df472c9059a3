"""depot_manager: docks, queue geometry and admission for the central depot.

Implements queue_depot_traffic.md. `docks` places the docks on the depot boundary (and makes the
``docks`` delivery kind's drop zones); `geometry` builds the ROS-free queue layouts of its sec. IV
(single spiral queue with inner queues, Figs. 3/6; multi-queue sector serpentines, Figs. 4/7)
from the scenario's `depot` section (`DepotGeometryConfig.from_scenario`); `draw` renders a
layout to PNG (`python -m depot_manager.draw --layout single|multi --out FILE.png`);
`admission` is the ROS-free slot authority (joins, grants, FCFS with the counter-clockwise tie
rule, keep-clear intersections, inner-queue and dock rules); `server` wraps it as a
`swarm_sim.protocol.Server` (the generic server node puts it on the graph: ``swarm-server
--channel depot``; `codec` declares its messages, state and markers).
"""
