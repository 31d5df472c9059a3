"""The queue paper's protocol (`depot_manager.protocol`) on the graph: two record families.

| message | topic | from -> to |
|---|---|---|
| DepotReport | /depot/reports | robot -> depot manager |
| DepotGrant | /depot/grants | depot manager -> robots |
| RadioQuery, RadioReply | /radio | robot -> robots (receivers keep what is in range) |

All diagnostic_msgs/msg/DiagnosticArray (`swarm_msgs_py.records`), reliable, deep, volatile.

Besides its messages the depot manager publishes (`OUTPUTS`) its state on ``/depot/state``
whenever it changes and its markers on ``/depot/markers`` (every line, dock, entry and exit
point, and which slots are owned) after a change at most once per `MARKER_PERIOD` of sim time,
both reliable + transient-local; the run trace's ``queue_lengths`` (robots queued per entry
line, a point whenever they change) is read from the state.
"""

from depot_manager.protocol import DepotGrant, DepotReport, RadioQuery, RadioReply
from depot_manager.server import MARKER_PERIOD, draw
from depot_manager.state import DepotView, decode_depot_state, encode_depot_state
from swarm_msgs_py.diagnostics import TYPE_NAME
from swarm_msgs_py.records import RecordFamily
from swarm_sim.outputs import LivePlot, Series, ServerMarkers, ServerOutputs, ServerState

DEPOT_REPORTS = "/depot/reports"
DEPOT_GRANTS = "/depot/grants"
DEPOT_STATE = "/depot/state"
DEPOT_MARKERS = "/depot/markers"
RADIO_TOPIC = "/radio"

DEPOT = RecordFamily("depot", {DepotReport: DEPOT_REPORTS, DepotGrant: DEPOT_GRANTS})
RADIO = RecordFamily("radio", {RadioQuery: RADIO_TOPIC, RadioReply: RADIO_TOPIC})


def _queue_lengths(depot: DepotView) -> dict[str, tuple[int, ...]]:
    return {"queue_lengths": tuple(n for _, n in depot.queues)}


_QUEUES_SCRIPT = """\
// /depot/state: the status named "queues" holds each entry line's queue length -> numbers.
import {{ Input }} from "./types";

type Output = {{ total: number; longest: number; lines: number }};

export const inputs = ["/depot/state"];
export const output = "{prefix}depot_queues";

export default function script(event: Input<"/depot/state">): Output | undefined {{
  const queues = event.message.status.find((s) => s.name === "queues");
  if (queues === undefined) return undefined;
  const lengths = queues.values.map((kv) => Number(kv.value));
  return {{
    total: lengths.reduce((a, b) => a + b, 0),
    longest: lengths.length ? Math.max(...lengths) : 0,
    lines: lengths.length,
  }};
}}
"""


OUTPUTS = ServerOutputs(
    state=(ServerState(DEPOT_STATE, TYPE_NAME, "depot", encode_depot_state, decode_depot_state),),
    markers=ServerMarkers(DEPOT_MARKERS, draw, MARKER_PERIOD),
    series=(Series(DEPOT_STATE, _queue_lengths, on_change=True),),
    live=(LivePlot("depot_queues", "depot queues", "depot queue lengths [robots]", _QUEUES_SCRIPT,
                   (("total", "robots queued (all entry lines)"), ("longest", "longest entry line"))),),
)
