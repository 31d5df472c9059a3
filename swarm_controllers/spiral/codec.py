"""The spiral paper's protocol (`swarm_controllers.spiral.protocol`) on the graph.

| message | topic | from -> to |
|---|---|---|
| ProgressReport | /center/reports | robot -> center |
| RegionAssignment | /center/assignments | center -> robots |

Both diagnostic_msgs/msg/DiagnosticArray (`swarm_msgs_py.records`), reliable, deep, volatile.
"""

from swarm_controllers.spiral.protocol import ProgressReport, RegionAssignment
from swarm_msgs_py import topics
from swarm_msgs_py.records import RecordFamily

CENTER = RecordFamily("center", {ProgressReport: topics.CENTER_REPORTS, RegionAssignment: topics.CENTER_ASSIGNMENTS})
