"""depot_manager: docks, queue geometry and admission for the central depot.

Implements queue_depot_traffic.md. `geometry` builds the ROS-free queue layouts of its sec. IV
(single spiral queue with inner queues, Figs. 3/6; multi-queue sector serpentines, Figs. 4/7)
from a `DepotGeometryConfig`; `draw` renders a layout to PNG for checking by eye
(`python -m depot_manager.draw --layout single|multi --out FILE.png`). Admission and the
depot-manager node come later; until then the central depot is only the CPFA nest, a drop zone
described by `swarm_sim.scenario.DepotConfig`.
"""
