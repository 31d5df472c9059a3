"""The lockstep barrier's bookkeeping: stale and dead participants; death is final."""

from swarm_sim.nodes.lockstep import LockstepBarrier


def test_a_silent_participant_is_stale_every_tick_and_dead_after_n():
    b = LockstepBarrier(["robot_0", "robot_1", "depot"], dead_after=3)
    deaths = []
    for k in range(5):
        b.answered("robot_0", k)
        b.answered("depot", k)
        b.answered("robot_7", k)  # not a participant: ignored
        assert b.waiting(k, b.live()) == (["robot_1"] if k < 3 else [])
        stale, dead = b.close_tick(k)
        assert stale == ["robot_1"]
        deaths += dead
    assert deaths == ["robot_1"] and b.live() == ["robot_0", "depot"] and b.dead == {"robot_1"}
    # robot_1 answers again: refused, still dead and stale (the others have written it off)
    assert [b.answered(who, 5) for who in ("robot_0", "robot_1", "depot")] == [True, False, True]
    assert b.close_tick(5) == (["robot_1"], []) and b.live() == ["robot_0", "depot"]


def test_an_answer_for_another_tick_does_not_count():
    b = LockstepBarrier(["robot_0"], dead_after=2)
    b.answered("robot_0", 4)
    assert b.waiting(5, ["robot_0"]) == ["robot_0"]
    assert b.close_tick(5) == (["robot_0"], [])


def test_a_late_answer_means_slow_not_dead():
    """A participant whose answers arrive after their ticks closed stays stale at each tick but
    is never declared dead; silence counts from its last late answer."""
    b = LockstepBarrier(["robot_0", "robot_1"], dead_after=2)
    for k in range(6):
        b.answered("robot_0", k)
        if k:
            b.heard("robot_1")  # its answer to tick k - 1, after that tick closed
        assert b.close_tick(k) == (["robot_1"], [])
    assert b.dead == set()
    # silent from now on: robot_1 had missed tick 5 already (its count restarted before it)
    assert b.close_tick(6) == (["robot_0", "robot_1"], ["robot_1"])
    assert b.close_tick(7) == (["robot_0", "robot_1"], ["robot_0"])
    b.heard("robot_1")  # too late: death is final
    assert b.dead == {"robot_0", "robot_1"}
    b.heard("robot_9")  # not a participant: ignored
