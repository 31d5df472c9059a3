"""The DRTM paper's protocol (`swarm_controllers.drtm.protocol`) on the graph: one record family.

| message | topic | from -> to | QoS |
|---|---|---|---|
| NestReport | /nest/reports | robot -> nest | reliable, deep, volatile |
| NestState | /nest/state | nest -> robots (and ``ros2 topic echo``) | reliable, transient-local |

Both diagnostic_msgs/msg/DiagnosticArray (`swarm_msgs_py.records`): ``ros2 topic echo
/nest/state`` shows ``food`` (F(t) [tokens]), ``waiting`` (N_W), ``recent_oaes`` (M_T2) and
``total_oaes`` of every tick.

The run trace's nest series are read off the states the nest sends (`OUTPUTS`), a point per
tick: ``nest_food`` F(t) [tokens], ``nest_waiting`` N_W and ``nest_oaes`` the OAEs heard so far.
"""

from swarm_controllers.drtm.protocol import NestReport, NestState
from swarm_msgs_py.records import RecordFamily
from swarm_sim.outputs import Series, ServerOutputs

NEST_REPORTS = "/nest/reports"
NEST_STATE = "/nest/state"

NEST = RecordFamily("nest", {NestReport: NEST_REPORTS, NestState: NEST_STATE}, latched=(NEST_STATE,))


def _nest_series(state: NestState) -> dict[str, float]:
    return {"nest_food": state.food, "nest_waiting": state.waiting, "nest_oaes": state.total_oaes}


OUTPUTS = ServerOutputs(series=(Series(NEST_STATE, _nest_series),))
