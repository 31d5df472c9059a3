"""What the network did to each robot's commands: late, lost, re-sent, stopped by the timeout.

ROS-free bookkeeping for the world node. Every command taken is `taken` with its stamp (the tick
it answers) and the tick at which it arrived. In realtime mode, a robot whose newest command is
older than ``sim.command_timeout`` is stopped (`fresh`), as a real robot driver does after its
command timeout (diff_drive_controller's ``cmd_vel_timeout``, which also measures the age from the
command's stamp); it drives again with the next fresh command. Counts per robot (`counts`):

- ``late``: commands that arrived after the tick they answer was stepped (lockstep refuses them;
  realtime takes the newest, an older one arriving after a newer one is dropped);
- ``lost``: ticks the run stepped for which no command of the robot ever arrived;
- ``resent``: lockstep: times the world sent a tick's observations again to the robot;
- ``stale``: the world's own count (`RobotStats.stale_ticks`), copied in by the caller;
- ``stopped``: times the timeout stopped the robot, ``stopped_ticks`` the ticks it stood still
  for it, and ``stops`` each stop as [stamp of its last command, tick it was stopped at, tick it
  drove again at or -1] [ns].
"""

from __future__ import annotations

from collections.abc import Iterable

from swarm_msgs_py.types import Command, RobotId


class CommandWatch:
    def __init__(self, robots: Iterable[RobotId], dt_ns: int, ticks: int, timeout_ns: int) -> None:
        """`timeout_ns`: the command timeout (0: never stop a robot)."""
        self.robots = tuple(robots)
        self.dt_ns = dt_ns
        self.timeout_ns = timeout_ns
        self._heard = {r: bytearray(ticks + 1) for r in self.robots}
        """Per robot, 1 at every tick index a command stamped with it arrived."""
        self.newest: dict[RobotId, int] = {}
        """Per robot, the stamp of its newest command taken [ns]."""
        self.late = dict.fromkeys(self.robots, 0)
        self.resent = dict.fromkeys(self.robots, 0)
        self.stops: dict[RobotId, list[list[int]]] = {r: [] for r in self.robots}
        self.stopped_ticks = dict.fromkeys(self.robots, 0)
        self._stopped: set[RobotId] = set()
        self.ticks_run = 0

    def taken(self, robot: RobotId, stamp_ns: int, now_ns: int) -> bool:
        """A command of `robot` stamped `stamp_ns` arrived at tick `now_ns`; False if it is older
        than one already taken (realtime: it must not replace the newer one)."""
        index = stamp_ns // self.dt_ns
        heard = self._heard[robot]
        if 0 <= index < len(heard):
            heard[index] = 1
        if stamp_ns < now_ns:
            self.late[robot] += 1
        if stamp_ns < self.newest.get(robot, -1):
            return False
        self.newest[robot] = stamp_ns
        return True

    def fresh(self, commands: dict[RobotId, Command], now_ns: int) -> dict[RobotId, Command]:
        """`commands` with every robot whose newest command is older than the timeout at tick
        `now_ns` stopped (counted); call once per tick stepped."""
        self.ticks_run += 1
        if self.timeout_ns <= 0:
            return commands
        out = dict(commands)
        for robot in commands:
            newest = self.newest.get(robot, now_ns)
            if now_ns - newest > self.timeout_ns:
                out[robot] = Command()
                self.stopped_ticks[robot] += 1
                if robot not in self._stopped:
                    self._stopped.add(robot)
                    self.stops[robot].append([newest, now_ns, -1])
            elif robot in self._stopped:
                self._stopped.discard(robot)
                self.stops[robot][-1][2] = now_ns
        return out

    def counts(self, stale: dict[RobotId, int]) -> dict[RobotId, dict]:
        """Per robot, what the module docstring lists (`stale`: the world's stale ticks)."""
        return {r: {"stale": stale.get(r, 0), "late": self.late[r],
                    "lost": self.ticks_run - sum(self._heard[r][:self.ticks_run]), "resent": self.resent[r],
                    "stopped": len(self.stops[r]), "stopped_ticks": self.stopped_ticks[r], "stops": self.stops[r]}
                for r in self.robots}
