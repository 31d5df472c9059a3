"""Every registered algorithm through `swarm_sim.conformance.check_algorithm`: ROS-free cores,
seed determinism, codec round trips and graph == batch. An algorithm is covered by being
registered and having a shipped scenario; nothing here lists algorithms."""

from __future__ import annotations

import os

import pytest
import yaml

from swarm_sim import registry
from swarm_sim.conformance import ConformanceError, check_algorithm, sample_message


def _scenario_of(name: str) -> str:
    """The first shipped scenario (by file name) that runs algorithm `name`."""
    for stem, path in registry.scenario_files().items():
        if (yaml.safe_load(path.read_text()).get("controller") or {}).get("behaviour") == name:
            return stem
    raise AssertionError(f"no shipped scenario runs the registered algorithm {name!r}")


@pytest.mark.parametrize("name", registry.known())
def test_registered_algorithm_conforms(name, tmp_path):
    passed = check_algorithm(_scenario_of(name), graph_bag=tmp_path / "bag",
                             domain_id=int(os.environ["ROS_DOMAIN_ID"]))
    assert passed == ["ros_free", "determinism", "codecs", "graph_equals_batch"]


def test_the_checks_can_fail(monkeypatch):
    from swarm_sim import conformance

    real = conformance._batch
    runs = iter(range(100))

    def drifting(scenario):  # a second run that differs from the first
        summary, poses = real(scenario)
        return {**summary, "resources_delivered": next(runs)}, poses

    monkeypatch.setattr(conformance, "_batch", drifting)
    with pytest.raises(ConformanceError, match="determinism: the same seed gave different resources_delivered"):
        conformance.check_determinism(conformance.load_scenario("cpfa", ["robots.count=2", "sim.duration=1"]))


def test_sample_messages_fill_every_field_with_its_type():
    from depot_manager.protocol import DepotGrant, Refusal

    grant = sample_message(DepotGrant)
    assert isinstance(grant.reason, Refusal) and isinstance(grant.last, bool) and isinstance(grant.cell, int)
