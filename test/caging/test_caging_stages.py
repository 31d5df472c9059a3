"""The caging run's stage as the world's progress line says it, from the robots' statuses
(`swarm_controllers.caging.stages`, the caging record's ``progress``)."""

from __future__ import annotations

from swarm_controllers.caging.stages import progress, stage
from swarm_msgs_py.types import BehaviourStatus
from swarm_sim import registry


def _statuses(*phases: str, leg: str = "0/0", recruiter: str = "") -> dict:
    return {f"robot_{i}": BehaviourStatus(f"robot_{i}", 0, p, 0, 0, (("recruiter", recruiter), ("leg", leg),
                                                                     ("cage", str(len(phases)))), p == "done")
            for i, p in enumerate(phases)}


def test_the_stage_follows_the_phases():
    assert stage({}) == "search"
    assert stage(_statuses("search", "search")) == "search"
    assert stage(_statuses("search", "approach", "search")) == "recruitment"
    assert stage(_statuses("placed", "summoning", "to_cage")) == "recruitment"
    assert stage(_statuses("spin", "wait_oriented", "placed")) == "transport"
    assert stage(_statuses("done", "wait_reached")) == "transport"
    assert stage(_statuses("done", "done")) == "delivered"


def test_the_progress_line_names_the_leg_and_the_cage():
    assert progress(_statuses("search", "search")) == "stage=search"
    assert progress(_statuses("move", "move", "wait_reached", leg="2/9", recruiter="robot_0")) == \
        "stage=transport leg 3/9 cage=3"
    assert registry.resolve(registry.algorithm("caging").progress) is progress
