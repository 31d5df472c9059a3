"""The behaviour API's helpers: the fast Command constructor builds what the constructor does."""

from __future__ import annotations

import dataclasses

import pytest
from hypothesis import given
from hypothesis import strategies as st

from swarm_controllers.api import new_command
from swarm_sim.types import Command, PheromoneMessage

speeds = st.floats(allow_nan=True, allow_infinity=True)
messages = st.lists(
    st.builds(PheromoneMessage, st.integers(0, 10**12), st.floats(-20, 20), st.floats(-20, 20)), max_size=3
).map(tuple)


@given(speeds, speeds, messages)
def test_new_command_equals_the_constructor(linear, angular, sent):
    fast, slow = new_command(linear, angular, sent), Command(linear, angular, sent)
    assert type(fast) is Command and fast.messages is sent
    assert repr(fast) == repr(slow)  # every field, NaN included
    if linear == linear and angular == angular:
        assert fast == slow and hash(fast) == hash(slow)


def test_new_command_defaults_to_no_messages_and_stays_frozen():
    c = new_command(0.1, -0.2)
    assert c == Command(0.1, -0.2) and c.messages == ()
    with pytest.raises(dataclasses.FrozenInstanceError):
        c.linear = 1.0  # type: ignore[misc]
