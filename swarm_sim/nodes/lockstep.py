"""The lockstep barrier's bookkeeping: who must answer tick k, who did, who is stale or dead.

ROS-free. The world node waits (spinning) until `waiting(k)` is empty or the tick timeout has
passed, then calls `close_tick(k)`. Participants are the robots and the servers' channels. One
that misses `dead_after` ticks in a row, with nothing heard from it meanwhile, is declared dead,
for good. Dead means silent, not slow: an answer to a tick already closed (`heard`) restarts the
count, so robots that fall behind in the start-up storm of a hundred processes on two cores are
not written off. A dead participant is no longer waited for, its later answers are refused
(`answered` returns False) and every later tick counts as stale for it. Death is final because
the others act on it (the servers give a dead robot's dock, slots or region to others; a dead
server ends the run), so a controller that comes back after a long stall must not resume
driving on a state the rest of the graph has written off.
"""

from __future__ import annotations

from collections.abc import Iterable


class LockstepBarrier:
    def __init__(self, participants: Iterable[str], dead_after: int) -> None:
        if dead_after < 1:
            raise ValueError(f"dead_after must be at least 1, got {dead_after}")
        self.missed: dict[str, int] = dict.fromkeys(participants, 0)
        """Participant -> ticks missed in a row."""
        self.dead: set[str] = set()
        """Participants declared dead (final)."""
        self._answered: dict[str, int] = {}
        self.dead_after = dead_after
        self._open: int | None = None
        self.outstanding: set[str] = set()
        """The live participants that have not answered the open tick (`open_tick`) yet: kept
        as answers arrive, so the world's wait loop asks in O(1) per wake-up (with a thousand
        robots, rebuilding the list of those waiting at each of a tick's ~1000 wake-ups cost
        more than the tick's physics)."""

    def open_tick(self, stamp_ns: int) -> None:
        """Tick `stamp_ns` went out: `outstanding` follows its answers from now on."""
        self._open = stamp_ns
        self.outstanding = {p for p in self.live() if self._answered.get(p) != stamp_ns}

    def answered(self, who: str, stamp_ns: int) -> bool:
        """`who` answered tick `stamp_ns`; False (and nothing recorded) for a participant that
        is unknown or dead."""
        if who not in self.missed or who in self.dead:
            return False
        self._answered[who] = stamp_ns
        if stamp_ns == self._open:
            self.outstanding.discard(who)
        return True

    def heard(self, who: str) -> None:
        """`who` answered a tick already closed: it is alive, only late; its count of ticks
        missed in a row restarts (it stays stale at the ticks it missed)."""
        if who in self.missed and who not in self.dead:
            self.missed[who] = 0

    def has_answered(self, who: str, stamp_ns: int) -> bool:
        return self._answered.get(who) == stamp_ns

    def live(self) -> list[str]:
        """The participants waited for at the next tick."""
        return [p for p in self.missed if p not in self.dead]

    def waiting(self, stamp_ns: int, among: Iterable[str]) -> list[str]:
        """Those of `among` that have not answered tick `stamp_ns` yet."""
        return [p for p in among if self._answered.get(p) != stamp_ns]

    def close_tick(self, stamp_ns: int) -> tuple[list[str], list[str]]:
        """End tick `stamp_ns`: (participants stale at it, those declared dead at it)."""
        stale, dead = [], []
        for p in self.missed:
            if self._answered.get(p) == stamp_ns:
                self.missed[p] = 0
            else:
                self.missed[p] += 1
                stale.append(p)
                if self.missed[p] == self.dead_after:
                    self.dead.add(p)
                    dead.append(p)
        return stale, dead
