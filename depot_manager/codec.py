"""The queue paper's protocol (`depot_manager.protocol`) on the graph: two record families.

| message | topic | from -> to |
|---|---|---|
| DepotReport | /depot/reports | robot -> depot manager |
| DepotGrant | /depot/grants | depot manager -> robots |
| RadioQuery, RadioReply | /radio | robot -> robots (receivers keep what is in range) |

All diagnostic_msgs/msg/DiagnosticArray (`swarm_msgs_py.records`), reliable, deep, volatile.
"""

from depot_manager.protocol import DepotGrant, DepotReport, RadioQuery, RadioReply
from swarm_msgs_py import topics
from swarm_msgs_py.records import RecordFamily

DEPOT = RecordFamily("depot", {DepotReport: topics.DEPOT_REPORTS, DepotGrant: topics.DEPOT_GRANTS})
RADIO = RecordFamily("radio", {RadioQuery: topics.RADIO, RadioReply: topics.RADIO})
