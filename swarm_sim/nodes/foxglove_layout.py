"""The Foxglove layout shipped for watching a run, live (``swarm-run --foxglove``) or from its bag.

Built with `foxglove.layouts` (the SDK's typed layout model), so it stays a valid layout as the
SDK evolves; ``python -m swarm_sim.nodes.foxglove_layout [OUT]`` rewrites the shipped file
(`LAYOUT_FILE`, checked against this code by the tests). Left: a top-down 3D panel with every
marker topic (world, depot, center) and every robot's odometry in the ``world`` frame. Right: plots of the swarm's
deliveries and pick-ups and of the depot's queue lengths over sim time.

Our state topics are diagnostic_msgs/DiagnosticArray with numbers as strings, which Foxglove's
plots do not read, so the layout carries two small user scripts (TypeScript, run inside Foxglove)
that turn ``/world/robot_stats`` and ``/depot/state`` into numbers; they work the same on a live
connection and on a bag.
"""

from __future__ import annotations

import sys
from pathlib import Path

LAYOUT_FILE = Path(__file__).resolve().parents[2] / "launch_py" / "foxglove_layout.json"
TOTALS = "/foxglove_script/swarm_totals"
QUEUES = "/foxglove_script/depot_queues"
MARKER_TOPICS = ("/world/markers", "/depot/markers", "/center/markers")
ODOMETRY_ROBOTS = 128
"""Robots whose odometry the 3D panel shows as poses (every tick; the world's robot markers come
every 5 s of sim time): robot_0 ... robot_127."""

_TOTALS_SCRIPT = f"""\
// /world/robot_stats (one status per robot, numbers as strings) -> swarm totals.
import {{ Input }} from "./types";

type Output = {{ deliveries: number; pickups: number; collision_time_s_mean: number; stale_ticks: number }};

export const inputs = ["/world/robot_stats"];
export const output = "{TOTALS}";

export default function script(event: Input<"/world/robot_stats">): Output {{
  const out = {{ deliveries: 0, pickups: 0, collision_time_s_mean: 0, stale_ticks: 0 }};
  for (const status of event.message.status) {{
    for (const kv of status.values) {{
      const v = Number(kv.value);
      if (kv.key === "deliveries") out.deliveries += v;
      else if (kv.key === "pickups") out.pickups += v;
      else if (kv.key === "avoidance_time_s") out.collision_time_s_mean += v;  // the papers' collision time
      else if (kv.key === "stale_ticks") out.stale_ticks += v;
    }}
  }}
  out.collision_time_s_mean /= Math.max(1, event.message.status.length);
  return out;
}}
"""

_QUEUES_SCRIPT = f"""\
// /depot/state: the status named "queues" holds each entry line's queue length -> numbers.
import {{ Input }} from "./types";

type Output = {{ total: number; longest: number; lines: number }};

export const inputs = ["/depot/state"];
export const output = "{QUEUES}";

export default function script(event: Input<"/depot/state">): Output | undefined {{
  const queues = event.message.status.find((s) => s.name === "queues");
  if (queues === undefined) return undefined;
  const lengths = queues.values.map((kv) => Number(kv.value));
  return {{
    total: lengths.reduce((a, b) => a + b, 0),
    longest: lengths.length ? Math.max(...lengths) : 0,
    lines: lengths.length,
  }};
}}
"""


def build_layout() -> str:
    """The layout as JSON text."""
    import foxglove.layouts as fl

    scene = fl.ThreeDeePanel(
        title="swarm (markers)",
        config=fl.ThreeDeeConfig(
            follow_tf="world",
            fixed_frame="world",
            camera_state=fl.ThreeDeeCameraState(perspective=False, distance=18.0, phi=0.0, theta_offset=0.0,
                                                target=(0.0, 0.0, 0.0)),
            topics={
                **{t: fl.BaseRendererRosMarkerTopicSettings(visible=True) for t in MARKER_TOPICS},
                **{f"/robot_{i}/odom": fl.BaseRendererPoseTopicSettings(visible=True) for i in range(ODOMETRY_ROBOTS)},
            },
        ),
    )

    def plot(title: str, series: list[tuple[str, str]]) -> object:
        return fl.PlotPanel(title=title, config=fl.PlotConfig(
            paths=[fl.PlotSeries(value=value, label=label, enabled=True) for value, label in series],
            show_legend=True, x_axis_val="timestamp",
        ))

    totals = plot("deliveries and pick-ups", [(f"{TOTALS}.deliveries", "resources delivered"),
                                                (f"{TOTALS}.pickups", "pick-ups")])
    queues = plot("depot queue lengths", [(f"{QUEUES}.total", "robots queued (all entry lines)"),
                                          (f"{QUEUES}.longest", "longest entry line")])
    collisions = plot("collision time per robot [s]", [(f"{TOTALS}.collision_time_s_mean", "mean over robots")])
    layout = fl.Layout(
        content=fl.SplitContainer(direction="row", items=[
            fl.SplitItem(proportion=3, content=scene),
            fl.SplitItem(proportion=2, content=fl.SplitContainer(direction="column", items=[
                fl.SplitItem(content=totals), fl.SplitItem(content=queues), fl.SplitItem(content=collisions),
            ])),
        ]),
        user_scripts={
            "swarm_totals": fl.UserScript(name="swarm totals", source_code=_TOTALS_SCRIPT),
            "depot_queues": fl.UserScript(name="depot queues", source_code=_QUEUES_SCRIPT),
        },
    )
    return layout.to_json()


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else argv
    out = Path(args[0]) if args else LAYOUT_FILE
    out.write_text(build_layout() + "\n")
    print(f"wrote {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
