"""A run ends everywhere (`swarm_sim.nodes.run_watch`): the ``/world/run`` codec and the watch's
rules, by hand (the graph across hosts: test/network/test_run_ends.py)."""

from __future__ import annotations

import pytest

from swarm_msgs_py import auth, run_state
from swarm_sim.inbound import Inbound, Rejections
from swarm_sim.nodes.run_watch import FIRST_HEARD_WAIT, VANISHED, WORLD_RUN, RunWatch, end_code


class _Node:
    def create_subscription(self, *args, **kwargs):
        return None


class _Clock:
    t = 100.0

    def __call__(self) -> float:
        return self.t


def _watch(timeout: float = 4.0) -> tuple[RunWatch, _Clock, Rejections]:
    clock, rejections = _Clock(), Rejections()
    watch = RunWatch(_Node(), Inbound(["robot_0"], 10**8, rejections, lambda _: None), timeout, clock=clock)
    return watch, clock, rejections


def _say(watch: RunWatch, run: str, state: str) -> None:
    watch.on_message(auth.sign(run_state.encode_run_state(run, state, 0)))


@pytest.fixture(autouse=True)
def _no_key():
    auth.set_key(None)
    yield
    auth.set_key(None)


def test_codec_round_trip_and_refusals():
    data = run_state.encode_run_state("ab12", "server depot died", 5)
    assert run_state.decode_run_state(data) == ("ab12", "server depot died")
    with pytest.raises(ValueError):
        run_state.encode_run_state("two words", "running", 0)
    with pytest.raises(ValueError):
        run_state.decode_run_state(run_state.encode_run_state("ab12", "", 0))


@pytest.mark.parametrize("state, code", [("complete", 0), ("finished", 0), ("interrupted", 130),
                                         ("server depot died", 3), ("world failed", 3)])
def test_an_end_said_by_the_world_gives_its_exit_code(state, code):
    watch, _, _ = _watch()
    _say(watch, "r1", "running")
    assert watch.current() and watch.verdict() is None
    _say(watch, "r1", state)
    assert not watch.current()
    assert watch.verdict()[0] == code == end_code(state)


def test_silence_longer_than_the_timeout_is_a_vanished_world():
    watch, clock, _ = _watch(4.0)
    clock.t += FIRST_HEARD_WAIT - 1
    assert watch.verdict() is None  # not heard yet: the world may still be starting
    _say(watch, "r1", "running")
    clock.t += 3.9
    assert watch.verdict() is None
    _say(watch, "r1", "running")
    clock.t += 4.1
    code, why = watch.verdict()
    assert code == VANISHED and "4.1 s" in why and "--world-timeout 4" in why


def test_a_world_never_heard_is_given_up_after_the_first_wait():
    watch, clock, _ = _watch(4.0)
    clock.t += FIRST_HEARD_WAIT + 0.1
    assert watch.verdict()[0] == VANISHED


def test_another_runs_world_holds_the_answers_until_ours_speaks_again():
    watch, _, _ = _watch()
    _say(watch, "old", "complete")  # the last word of a run before ours: ignored
    assert watch.run is None and watch.verdict() is None
    _say(watch, "r1", "running")
    _say(watch, "r2", "running")  # a new world on the domain: a leftover of r1 never answers it
    assert not watch.current() and watch.verdict() is None
    _say(watch, "r2", "complete")  # and r2's end is not ours
    assert watch.verdict() is None
    _say(watch, "r1", "running")
    assert watch.current()


def test_with_a_key_only_the_runs_own_word_counts():
    auth.set_key(b"k" * 32)
    watch, clock, rejections = _watch(4.0)
    _say(watch, "r1", "running")
    assert watch.current()
    forged = run_state.encode_run_state("r1", "complete", 0)  # untagged: a forger cannot end the run
    watch.on_message(forged)
    assert rejections.counts[(WORLD_RUN, "unauthenticated")] == 1
    assert not watch.current() and watch.verdict() is None
    watch.on_message(b"\x00\x01garbage")  # no tag either
    assert rejections.counts[(WORLD_RUN, "unauthenticated")] == 2
    _say(watch, "r1", "running")
    assert watch.current()
    clock.t += 5
    assert watch.verdict()[0] == VANISHED  # forged words do not keep a dead world alive
