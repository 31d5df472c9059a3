"""The caging run's stage as the robots report it: what the world node's progress line says
(`swarm_sim.registry.Algorithm.progress`). The paper's three stages (sec. 3): search until a
robot detects the object, recruitment until the cage is complete, transport leg by leg along
T_r* reversed; then the object is delivered."""

from __future__ import annotations

from collections.abc import Mapping

from swarm_controllers.caging.behaviour import Phase
from swarm_msgs_py.types import BehaviourStatus, RobotId

RECRUITMENT = frozenset(p.value for p in (Phase.APPROACH, Phase.WAIT_SUMMON, Phase.TO_CAGE, Phase.SUMMONING,
                                          Phase.PLACED))
TRANSPORT = frozenset(p.value for p in (Phase.SPIN, Phase.WAIT_ORIENTED, Phase.MOVE, Phase.WAIT_REACHED))


def stage(statuses: Mapping[RobotId, BehaviourStatus]) -> str:
    """``search``, ``recruitment``, ``transport`` or ``delivered`` from the robots' phases."""
    phases = {s.state for s in statuses.values()}
    if phases and phases <= {Phase.DONE.value}:
        return "delivered"
    if phases & TRANSPORT or Phase.DONE.value in phases:
        return "transport"
    if phases & RECRUITMENT:
        return "recruitment"
    return "search"


def progress(statuses: Mapping[RobotId, BehaviourStatus]) -> str:
    """``stage=transport leg 3/9 cage=8``: the stage; in transport the furthest leg a robot is on
    (its status's ``leg``, 0-based of the path's legs), the cage's size as the recruiter sees it."""
    now = stage(statuses)
    text = f"stage={now}"
    extras = [dict(s.extra) for s in statuses.values()]
    if now == "transport":
        legs = [e["leg"].split("/") for e in extras if "/" in e.get("leg", "")]
        if legs:
            leg, total = max((int(a), int(b)) for a, b in legs)
            text += f" leg {leg + 1}/{total}"
    cages = [int(e["cage"]) for e in extras if e.get("recruiter") and e.get("cage", "").isdigit()]
    if now != "search" and cages:
        text += f" cage={max(cages)}"
    return text
