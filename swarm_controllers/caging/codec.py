"""The caging paper's messages (`swarm_controllers.caging.protocol`) on the graph: one topic per
type, each a diagnostic_msgs/msg/DiagnosticArray (`swarm_msgs_py.records`) with one status per
message: name = the class, hardware_id = origin, values ``type``, ``origin``, ``destination``
and the payload, so ``ros2 topic echo /caging/type0_recruitment`` shows msg<type, origin,
destination, payload>.

| type | message | topic | payload |
|---|---|---|---|
| 0 | Recruitment | /caging/type0_recruitment | object_x, object_y, start_x, start_y, trajectory (landmark indices) |
| 1 | Summon | /caging/type1_summon | none |
| 2 | Positioned | /caging/type2_positioned | none |
| 3 | Oriented | /caging/type3_oriented | leg |
| 4 | Reached | /caging/type4_reached | leg |

Reliable, deep, volatile (`swarm_sim.nodes.qos.EVENTS`); delivered one tick later like every peer
message (`swarm_sim.messaging`).
"""

from swarm_controllers.caging.protocol import Oriented, Positioned, Reached, Recruitment, Summon
from swarm_msgs_py.records import RecordFamily

CAGING = RecordFamily("caging", {
    Recruitment: "/caging/type0_recruitment",
    Summon: "/caging/type1_summon",
    Positioned: "/caging/type2_positioned",
    Oriented: "/caging/type3_oriented",
    Reached: "/caging/type4_reached",
})
