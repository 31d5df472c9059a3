"""The layouts shipped for watching a run, live (``swarm-run --foxglove``) or from its bag.

Two files of one layout: `LAYOUT_FILE` for the current Foxglove app, built with
`foxglove.layouts` (the SDK's typed layout model, so it stays valid as the SDK evolves), and
`LICHTBLICK_FILE` in the classic layout format (``configById`` panels in a mosaic ``layout``,
``userNodes``) that Lichtblick and Foxglove Studio up to 1.87 import. ``python -m
swarm_sim.nodes.foxglove_layout`` rewrites both (the tests check them against this code). Left: a
top-down 3D panel with the world's markers and every registered server's (`ServerOutputs.markers`:
the depot's, the center's) and every robot's odometry in the ``world`` frame. Right: plots of the
swarm's deliveries and pick-ups, every registered server's live plots (`ServerOutputs.live`: the
depot's queue lengths) and the mean collision time over sim time.

Our state topics are diagnostic_msgs/DiagnosticArray with numbers as strings, which Foxglove's
plots do not read, so the layout carries small user scripts (TypeScript, run inside Foxglove)
that turn ``/world/robot_stats`` and each server's state into numbers; they work the same on a
live connection and on a bag.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

from swarm_msgs_py import topics
from swarm_sim import registry
from swarm_sim.outputs import LivePlot, outputs_of

LAYOUT_FILE = Path(__file__).resolve().parents[2] / "launch_py" / "foxglove_layout.json"
LICHTBLICK_FILE = LAYOUT_FILE.with_name("lichtblick_layout.json")
FOXGLOVE_SCRIPTS = "/foxglove_script/"
STUDIO_SCRIPTS = "/studio_script/"
"""Where a user script's output topic must start: in Foxglove, and in Lichtblick (Studio's name)."""
TOTALS = FOXGLOVE_SCRIPTS + "swarm_totals"
ODOMETRY_ROBOTS = 128
"""Robots whose odometry the 3D panel shows as poses (every tick; the world's robot markers come
every 5 s of sim time): robot_0 ... robot_127."""

def marker_topics() -> tuple[str, ...]:
    """The world's markers, then every registered server's, in registry order."""
    servers = {s.channel: s for a in registry.algorithms() for s in a.servers}
    drawn = [outputs_of(s).markers for s in servers.values()]
    return (topics.WORLD_MARKERS, *dict.fromkeys(m.topic for m in drawn if m is not None))


_TOTALS_SCRIPT = """\
// /world/robot_stats (one status per robot, numbers as strings) -> swarm totals.
import {{ Input }} from "./types";

type Output = {{ deliveries: number; pickups: number; collision_time_s_mean: number; stale_ticks: number }};

export const inputs = ["/world/robot_stats"];
export const output = "{prefix}swarm_totals";

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

def _live_plots() -> tuple[LivePlot, ...]:
    """Every registered server's live plots, in registry order."""
    servers = {s.channel: s for a in registry.algorithms() for s in a.servers}
    return tuple(plot for s in servers.values() for plot in outputs_of(s).live)


def plot_specs() -> tuple[tuple[str, str, tuple[tuple[str, str], ...]], ...]:
    """(id, title, [(script output.field, label)]): the plots on the right, top to bottom: the
    swarm's deliveries, every server's live plots, the collision time."""
    return (
        ("deliveries", "deliveries and pick-ups", (("swarm_totals.deliveries", "resources delivered"),
                                                   ("swarm_totals.pickups", "pick-ups"))),
        *((p.key.rpartition("_")[2], p.title, tuple((f"{p.key}.{field}", label) for field, label in p.series))
          for p in _live_plots()),
        ("collisions", "collision time per robot [s]", (("swarm_totals.collision_time_s_mean", "mean over robots"),)),
    )


def script_specs() -> tuple[tuple[str, str, str], ...]:
    """(key, name, TypeScript source with ``{prefix}``): the swarm totals, then the servers'."""
    return (("swarm_totals", "swarm totals", _TOTALS_SCRIPT), *((p.key, p.name, p.script) for p in _live_plots()))
SCENE_TITLE = "swarm (markers)"
CAMERA = {"perspective": False, "distance": 18.0, "phi": 0.0, "thetaOffset": 0.0, "target": (0.0, 0.0, 0.0)}
"""Top-down over the arena's centre."""


def _scene_topics() -> list[str]:
    return [*marker_topics(), *(f"/robot_{i}/odom" for i in range(ODOMETRY_ROBOTS))]


def build_layout() -> str:
    """The layout for the current Foxglove app, as JSON text."""
    import foxglove.layouts as fl

    scene = fl.ThreeDeePanel(
        title=SCENE_TITLE,
        config=fl.ThreeDeeConfig(
            follow_tf="world",
            fixed_frame="world",
            camera_state=fl.ThreeDeeCameraState(perspective=CAMERA["perspective"], distance=CAMERA["distance"],
                                                phi=CAMERA["phi"], theta_offset=CAMERA["thetaOffset"],
                                                target=CAMERA["target"]),
            topics={t: (fl.BaseRendererPoseTopicSettings(visible=True) if t.endswith("/odom")
                        else fl.BaseRendererRosMarkerTopicSettings(visible=True)) for t in _scene_topics()},
        ),
    )
    plots = [fl.PlotPanel(title=title, config=fl.PlotConfig(
        paths=[fl.PlotSeries(value=FOXGLOVE_SCRIPTS + path, label=label, enabled=True) for path, label in series],
        show_legend=True, x_axis_val="timestamp",
    )) for _, title, series in plot_specs()]
    layout = fl.Layout(
        content=fl.SplitContainer(direction="row", items=[
            fl.SplitItem(proportion=3, content=scene),
            fl.SplitItem(proportion=2, content=fl.SplitContainer(direction="column", items=[
                fl.SplitItem(content=plot) for plot in plots])),
        ]),
        user_scripts={key: fl.UserScript(name=name, source_code=code.format(prefix=FOXGLOVE_SCRIPTS))
                      for key, name, code in script_specs()},
    )
    return layout.to_json()


def _column(ids: list[str]) -> object:
    """A mosaic column of panels of equal height."""
    if len(ids) == 1:
        return ids[0]
    return {"direction": "column", "first": ids[0], "second": _column(ids[1:]), "splitPercentage": 100 / len(ids)}


def build_lichtblick_layout() -> str:
    """The same layout in the classic format (Lichtblick, Foxglove Studio <= 1.87), as JSON text:
    panels by ``Type!id`` in ``configById``, a react-mosaic tree in ``layout``, the user scripts
    in ``userNodes`` writing under ``/studio_script/``."""
    def titled(title: str, config: dict) -> dict:
        return {"lichtblickPanelTitle": title, "foxglovePanelTitle": title, **config}

    scene = titled(SCENE_TITLE, {
        "cameraState": {**CAMERA, "target": list(CAMERA["target"]), "targetOffset": [0, 0, 0],
                        "targetOrientation": [0, 0, 0, 1], "fovy": 45, "near": 0.5, "far": 5000},
        "followMode": "follow-pose", "followTf": "world", "scene": {}, "transforms": {}, "layers": {},
        "topics": {t: {"visible": True} for t in _scene_topics()},
    })
    plots = {f"Plot!{key}": titled(title, {
        "paths": [{"value": STUDIO_SCRIPTS + path, "label": label, "enabled": True, "timestampMethod": "receiveTime"}
                  for path, label in series],
        "showLegend": True, "legendDisplay": "floating", "showXAxisLabels": True, "showYAxisLabels": True,
        "xAxisVal": "timestamp", "isSynced": True,
    }) for key, title, series in plot_specs()}
    layout = {
        "configById": {"3D!swarm": scene, **plots},
        "globalVariables": {},
        "userNodes": {key: {"name": name, "sourceCode": code.format(prefix=STUDIO_SCRIPTS)}
                      for key, name, code in script_specs()},
        "playbackConfig": {"speed": 1},
        "layout": {"direction": "row", "first": "3D!swarm", "second": _column(list(plots)), "splitPercentage": 60},
    }
    return json.dumps(layout, indent=1)


def main(argv: list[str] | None = None) -> int:
    """Rewrite both shipped layouts (or write them into the directory given)."""
    args = sys.argv[1:] if argv is None else argv
    folder = Path(args[0]) if args else LAYOUT_FILE.parent
    for name, text in ((LAYOUT_FILE.name, build_layout()), (LICHTBLICK_FILE.name, build_lichtblick_layout())):
        (folder / name).write_text(text + "\n")
        print(f"wrote {folder / name}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
