"""Replay video from a real bag (a short Q_MT graph run, written with ``--out DIR``): ``swarm-analyze
DIR --video`` finds the one bag in DIR and writes an .mp4 that decodes to the expected frames; a .gif
too; a DIR with two bags or none is refused in one line. The legend beside the arena lists every
state and server overlay from the first frame; a scale bar of a round length."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import imageio.v2 as imageio
import numpy as np
import pytest

from depot_manager.server import DOCK_COLOUR
from swarm_sim.analysis import video_canvas
from swarm_sim.analysis.cli import main as analyze
from swarm_sim.analysis.video import SIZE_PX, WIDTH_PX, render_video, save_frame
from swarm_sim.scenario import load_scenario

ROOT = Path(__file__).resolve().parents[1]
pytestmark = pytest.mark.xdist_group("video")  # one worker makes the module's run (`out_dir`) for all


@pytest.fixture(scope="module")
def out_dir(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("runs")
    cmd = [sys.executable, "-m", "launch_py.run", "--out", str(out), "--scenario", "queue_qmt", "--robots", "6",
           "--duration", "20", "--tick-timeout", "20", "--domain-id", os.environ["ROS_DOMAIN_ID"]]
    result = subprocess.run(cmd, capture_output=True, text=True, timeout=300, cwd=ROOT)
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr[-2000:]
    return out


def test_analyze_dir_with_one_bag_renders_an_mp4(out_dir, tmp_path, capsys):
    video = tmp_path / "run.mp4"
    assert analyze([str(out_dir), "--json", "--no-plot", "--video", str(video), "--speedup", "4",
                    "--fps", "5", "--end", "10"]) == 0
    summary = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert summary["video"] == str(video) and summary["video_frames"] == 13  # t = 0, 0.8, ..., 9.6
    frames = imageio.mimread(video, memtest=False)
    assert len(frames) == 13 and frames[0].shape == (SIZE_PX, WIDTH_PX, 3)
    assert np.abs(frames[-1].astype(int) - frames[0].astype(int)).sum() > 0  # the robots moved


def test_gif_frames_show_the_robots_and_the_depot(out_dir, tmp_path, capsys):
    (bag,) = out_dir.iterdir()
    info = render_video(bag, tmp_path / "run.gif", speedup=10, fps=2, start=5, max_frames=3, progress=True)
    err = capsys.readouterr().err
    assert "rendering run.gif" in err and "0/3" in err and "frame/s" in err  # the progress bar
    assert (info.frames, info.start_s, info.end_s) == (3, 5.0, 15.0)
    frames = imageio.mimread(tmp_path / "run.gif")
    assert len(frames) == 3
    png = save_frame(bag, 12.0, tmp_path / "frame.png")
    image = imageio.imread(png)[..., :3].reshape(-1, 3).astype(int)
    states = np.array([[31, 119, 180], [255, 127, 14], [44, 160, 44]])  # departing, searching, returning
    docks = np.round(255 * np.array(DOCK_COLOUR[:3]))  # drawn in the colour the depot manager gives them
    assert (np.abs(image[:, None, :] - states[None]).sum(axis=2) < 10).any(axis=1).sum() > 20
    assert (np.abs(image - docks).sum(axis=1) < 10).sum() > 20


def test_a_dir_with_two_bags_or_none_is_refused_naming_them(out_dir, tmp_path, capsys):
    (bag,) = out_dir.iterdir()
    two = tmp_path / "two"
    shutil.copytree(bag, two / "a")
    shutil.copytree(bag, two / "b")
    (tmp_path / "none").mkdir()
    assert analyze([str(two), "--no-plot"]) == 1
    assert analyze([str(tmp_path / "none"), "--no-plot"]) == 1
    err = capsys.readouterr().err.splitlines()
    assert err == [f"swarm-analyze: {two}: not a bag, and holds 2 bags (a, b): name one",
                   f"swarm-analyze: {tmp_path / 'none'}: not a bag, and holds no bag directory"]
    with pytest.raises(ValueError, match="expected a file ending in .mp4 or .gif"):
        render_video(bag, tmp_path / "x.avi")
    with pytest.raises(ValueError, match="time window"):
        render_video(bag, tmp_path / "x.gif", start=1000)


def test_the_legend_names_every_state_and_overlay_from_the_first_frame():
    from matplotlib.legend import Legend

    canvas = video_canvas.Canvas(load_scenario("queue_qmt", ["robots.count=6"]), 6, {})
    try:
        texts = {t.get_text() for artist in canvas.key.get_children() if isinstance(artist, Legend)
                 for t in artist.get_texts()}
    finally:
        canvas.close()
    assert {"departing", "searching", "returning", "to entry", "queued", "no status yet"} <= texts
    assert {"depot: entry lines", "depot: docks", "depot: slots owned", "resource", "carried resource"} <= texts
    colours = [video_canvas.PALETTE[canvas.states.index(s)] for s in ("QUEUED", "SEARCHING")]
    assert colours[0] != colours[1]


def test_the_scale_bar_is_a_round_length_of_about_a_fifth_of_the_arena():
    assert [video_canvas.scale_bar_m(size) for size in (4.0, 5.0, 8.0, 10.0, 12.0, 100.0)] == [0.5, 1, 2, 2, 2, 20]
