"""swarm-analyze: a run's metrics (and its replay video) from its bag alone (no ROS running, no rclpy needed).

A path may be a bag directory, or a directory holding exactly one bag (what ``swarm-run --out DIR``
writes into), which is then used.
"""

from __future__ import annotations

import argparse
import json
import sys
import warnings
from pathlib import Path

from swarm_sim import registry
from swarm_sim.analysis.metrics import summarize
from swarm_sim.analysis.plots import plot_run, plot_trajectories
from swarm_sim.analysis.replay import load_run
from swarm_sim.analysis.text import summary_lines
from swarm_sim.analysis.video import render_video
from swarm_sim.cli import first_paragraph, number
from swarm_sim.recording import BagError, BagTruncatedWarning, repair_bag
from swarm_sim.recording.metadata import METADATA_FILE


def find_bag(path: Path) -> Path:
    """`path` if it is a bag; else its only subdirectory that is one (BagError naming what was found)."""
    if not path.is_dir() or (path / METADATA_FILE).exists() or any(path.glob("*.mcap")):
        return path
    bags = sorted(p for p in path.iterdir() if p.is_dir() and ((p / METADATA_FILE).exists() or any(p.glob("*.mcap"))))
    if len(bags) == 1:
        return bags[0]
    if not bags:
        raise BagError(f"{path}: not a bag, and holds no bag directory")
    names = ", ".join(p.name for p in bags[:5]) + (" ..." if len(bags) > 5 else "")
    raise BagError(f"{path}: not a bag, and holds {len(bags)} bags ({names}): name one")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="swarm-analyze", description=first_paragraph(__doc__))
    parser.add_argument("bags", nargs="+", type=Path, help="bag directories written by swarm-run")
    parser.add_argument("--json", action="store_true", help="print one JSON object per run")
    parser.add_argument("--plot", type=Path, help="PNG path (default: <bag>/summary.png)")
    parser.add_argument("--no-plot", action="store_true", help="write no summary.png")
    parser.add_argument("--trajectories", action="store_true",
                        help="also draw <bag>/trajectories.png (odometry over the planned paths) and the "
                             "algorithm's own figures (caging: <bag>/transport.png)")
    parser.add_argument("--repair", action="store_true",
                        help="first finalise a bag whose recorder was killed, in place, so that rosbags "
                             "and ros2 bag read it too (every recovered message kept)")
    video = parser.add_argument_group("replay video (one bag)")
    video.add_argument("--video", type=Path, metavar="OUT.mp4|OUT.gif", help="render the run from the bag")
    video.add_argument("--speedup", type=number(float, 0, 1e6, open_low=True), default=10.0,
                       help="sim seconds per video second (default 10)")
    video.add_argument("--fps", type=number(float, 0, 120, open_low=True), default=10.0,
                       help="video frames per second (default 10)")
    video.add_argument("--start", type=number(float, 0), default=0.0, help="first sim second (default 0)")
    video.add_argument("--end", type=number(float, 0), help="last sim second (default: the end of the run)")
    args = parser.parse_args(argv)
    # One line per warning (a bag's damage, its malformed messages), no source line of ours.
    warnings.showwarning = lambda message, *_: print(f"swarm-analyze: warning: {message}", file=sys.stderr)
    if args.video and len(args.bags) != 1:
        parser.error("--video renders one bag")
    status = 0
    for given in args.bags:
        try:
            bag = find_bag(given)
            if args.repair and repair_bag(bag):
                print(f"swarm-analyze: {bag}: repaired (its last file was cut off)", file=sys.stderr)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", BagTruncatedWarning)  # said once below, with what was lost
                trace = load_run(bag)
        except (BagError, ValueError) as exc:
            print(f"swarm-analyze: {exc}", file=sys.stderr)
            status = 1
            continue
        summary = summarize(trace)
        if trace.lost:  # the summary is printed still: it is what the bag holds
            print(f"swarm-analyze: {bag}: the bag lost data, its results are incomplete: {'; '.join(trace.lost)[:500]}",
                  file=sys.stderr)
            status = 1
        if trace.foreign:
            print(f"swarm-analyze: {bag}: the run is tainted, its results may hold what foreign publishers sent: "
                  f"{'; '.join(trace.foreign)[:500]}", file=sys.stderr)
            status = 1
        if not args.no_plot and (plot := plot_run(trace, args.plot or bag / "summary.png")) is not None:
            summary["plot"] = str(plot)
        if args.trajectories:
            summary["trajectories"] = str(plot_trajectories(bag, bag / "trajectories.png"))
            figures = registry.of(trace.config).figures
            if figures:  # the algorithm's own pictures (caging: the object's path, the cage)
                summary["figures"] = [str(p) for p in registry.resolve(figures)(trace, bag)]
        if args.video:
            try:
                rendered = render_video(bag, args.video, speedup=args.speedup, fps=args.fps, start=args.start,
                                        end=args.end)
            except (BagError, ValueError, OSError) as exc:
                print(f"swarm-analyze: {exc}", file=sys.stderr)
                return 1
            summary["video"] = str(rendered.path)
            summary["video_frames"] = rendered.frames
        if args.json:
            print(json.dumps(summary))
        else:
            print(f"{bag}:")
            print("\n".join(summary_lines(summary, trace.config)))
    return status


if __name__ == "__main__":
    sys.exit(main())
