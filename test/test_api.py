"""The behaviour API's helpers: the fast Command constructor builds what the constructor does."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from swarm_controllers.api import new_command, uniform_draws
from swarm_controllers.cpfa.messages import PheromoneMessage
from swarm_msgs_py.types import Command

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


@given(st.integers(0, 2**32), st.lists(st.sampled_from(["random", "normal", "uniform", "integers", "bytes"]), max_size=60))
def test_uniform_draws_are_rng_random_interleaved_with_other_draws(seed, kinds):
    """The fast draws give `Generator.random`'s numbers and leave the generator where it would
    be, whatever other draws come between (a behaviour's walk legs and sites)."""
    fast_rng, slow_rng = np.random.default_rng(seed), np.random.default_rng(seed)
    draw = uniform_draws(fast_rng)
    for kind in kinds:
        if kind == "random":
            a, b = draw(), slow_rng.random()
            assert type(a) is float and a == b
        else:
            args = {"normal": (0.0, 0.7), "uniform": (-3.0, 3.0), "integers": (0, 7), "bytes": (3,)}[kind]
            assert getattr(fast_rng, kind)(*args) == getattr(slow_rng, kind)(*args)
    assert fast_rng.bit_generator.state == slow_rng.bit_generator.state


def test_uniform_draws_fall_back_to_rng_random_for_other_bit_generators():
    rng = np.random.Generator(np.random.MT19937(3))
    assert uniform_draws(rng) == rng.random
