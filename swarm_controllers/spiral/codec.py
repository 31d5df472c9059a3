"""The spiral paper's protocol (`swarm_controllers.spiral.protocol`) on the graph.

| message | topic | from -> to |
|---|---|---|
| ProgressReport | /center/reports | robot -> center |
| RegionAssignment | /center/assignments | center -> robots |
| WalkProgress | /spiral/walk_progress | robot -> robots (the walkers of a region) |

All diagnostic_msgs/msg/DiagnosticArray (`swarm_msgs_py.records`), reliable, deep, volatile;
the world relays the robots' WalkProgress to every robot one tick later (`swarm_sim.messaging`).

Besides its messages the center publishes (`OUTPUTS`) the regions' walkers and progress on
``/center/state`` whenever they change, and the regions and their planned spirals on
``/center/markers`` once (both reliable + transient-local).
"""

from swarm_controllers.spiral.center import draw
from swarm_controllers.spiral.protocol import ProgressReport, RegionAssignment, WalkProgress
from swarm_controllers.spiral.state import decode_center_state, encode_center_state
from swarm_msgs_py.diagnostics import TYPE_NAME
from swarm_msgs_py.records import RecordFamily
from swarm_sim.outputs import ServerMarkers, ServerOutputs, ServerState

CENTER_REPORTS = "/center/reports"
CENTER_ASSIGNMENTS = "/center/assignments"
CENTER_STATE = "/center/state"
CENTER_MARKERS = "/center/markers"

CENTER = RecordFamily("center", {ProgressReport: CENTER_REPORTS, RegionAssignment: CENTER_ASSIGNMENTS})
WALK_PROGRESS = "/spiral/walk_progress"
WALKERS = RecordFamily("walkers", {WalkProgress: WALK_PROGRESS})
"""The MDBSA robots' peer radio (`WalkProgress`)."""

OUTPUTS = ServerOutputs(
    state=(ServerState(CENTER_STATE, TYPE_NAME, "regions", encode_center_state, decode_center_state),),
    markers=ServerMarkers(CENTER_MARKERS, draw),
)
