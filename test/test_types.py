"""The core types' fast constructors: `slot_constructor` builds what the dataclass constructor does."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np
import pytest

from swarm_controllers.cpfa.messages import PheromoneMessage
from swarm_msgs_py.types import Command, Observation, Pose2D, slot_constructor, slot_setters


def _same(fast: object, slow: object) -> None:
    assert type(fast) is type(slow)
    for f in dataclasses.fields(slow):
        assert getattr(fast, f.name) is getattr(slow, f.name), f.name


@pytest.mark.parametrize("args", [
    (Command, (0.1, -0.2, (PheromoneMessage(1, 2.0, 3.0),))),
    (Command, (0.1, -0.2)),
    (Command, ()),
    (Pose2D, (1.0, -2.0, 0.5)),
    (PheromoneMessage, (7, 1.5, -1.5)),
    (Observation, ("robot_3", 5, Pose2D(1.0, 2.0, 0.5), 0.1, -0.2, np.ones(3, np.float32), ("sensed",), ("m",))),
    (Observation, ("robot_3", 5, Pose2D(1.0, 2.0, 0.5), 0.1, -0.2, np.ones(3, np.float32), ("sensed",))),
])
def test_slot_constructor_builds_what_the_constructor_builds(args):
    cls, values = args
    make = slot_constructor(cls)
    assert make is not cls  # the fast path is taken for the core types
    fast, slow = make(*values), cls(*values)
    _same(fast, slow)
    assert fast == slow
    with pytest.raises(dataclasses.FrozenInstanceError):
        fast.__setattr__(dataclasses.fields(cls)[0].name, None)


def test_slot_constructor_needs_every_field_without_a_default():
    with pytest.raises(TypeError):
        slot_constructor(Pose2D)(1.0, 2.0)


@dataclass(frozen=True, slots=True)
class _Checked:
    x: float

    def __post_init__(self) -> None:
        if self.x < 0:
            raise ValueError("negative")


@dataclass(frozen=True, slots=True)
class _Listed:
    xs: list = field(default_factory=list)


@dataclass(frozen=True)
class _NoSlots:
    x: float


@dataclass(frozen=True, slots=True)
class _Derived:
    x: float
    y: float = field(init=False, default=0.0)


@pytest.mark.parametrize("cls", [_Checked, _Listed, _NoSlots, _Derived])
def test_slot_constructor_is_the_class_when_building_does_more_than_setting_fields(cls):
    assert slot_setters(cls) is None
    assert slot_constructor(cls) is cls
