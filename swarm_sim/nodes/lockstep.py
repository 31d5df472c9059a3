"""The lockstep barrier's bookkeeping: who must answer tick k, who did, who is stale or dead.

ROS-free. The world node waits (spinning) until `waiting(k)` is empty or the tick timeout has
passed, then calls `close_tick(k)`. Participants are the robots and the servers' channels. One
that misses `dead_after` ticks in a row is no longer waited for (its ticks still count as
stale) until it answers again.
"""

from __future__ import annotations

from collections.abc import Iterable


class LockstepBarrier:
    def __init__(self, participants: Iterable[str], dead_after: int) -> None:
        self.missed: dict[str, int] = dict.fromkeys(participants, 0)
        """Participant -> ticks missed in a row."""
        self._answered: dict[str, int] = {}
        self.dead_after = dead_after

    def answered(self, who: str, stamp_ns: int) -> None:
        """`who` answered tick `stamp_ns` (unknown participants are ignored)."""
        if who in self.missed:
            self._answered[who] = stamp_ns

    def has_answered(self, who: str, stamp_ns: int) -> bool:
        return self._answered.get(who) == stamp_ns

    def live(self) -> list[str]:
        """The participants waited for at the next tick."""
        return [p for p, n in self.missed.items() if n < self.dead_after]

    def waiting(self, stamp_ns: int, among: Iterable[str]) -> list[str]:
        """Those of `among` that have not answered tick `stamp_ns` yet."""
        return [p for p in among if self._answered.get(p) != stamp_ns]

    def close_tick(self, stamp_ns: int) -> tuple[list[str], list[str]]:
        """End tick `stamp_ns`: (participants stale at it, those that just went dead)."""
        stale, dead = [], []
        for p in self.missed:
            if self._answered.get(p) == stamp_ns:
                self.missed[p] = 0
            else:
                self.missed[p] += 1
                stale.append(p)
                if self.missed[p] == self.dead_after:
                    dead.append(p)
        return stale, dead
