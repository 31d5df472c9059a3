"""reference/speed_anchor.py: the authors' experiment file scaled to a bigger swarm and arena
(hand-made text in the shape of theirs; their file is not committed)."""
import importlib.util
import re
from pathlib import Path

import pytest

_DIR = Path(__file__).resolve().parents[2] / "reference"
_spec = importlib.util.spec_from_file_location("speed_anchor", _DIR / "speed_anchor.py")
sa = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(sa)

WALLS = "".join(
    f'<box id="wall_{n}" movable="false" size="{s}">\n      <body orientation="0,0,0" position="{p}"/>\n    </box>\n'
    for n, s, p in (("north1", "12,0.02,0.5", "0,6,0"), ("south", "12,0.02,0.5", "0,-6,0"),
                    ("east", "0.02, 12,0.5", "6,0,0"), ("west", "0.02, 12,0.5", "-6,0,0")))
GROUPS = "".join(
    f'<distribute>\n<position center="{c}" distances="0.3, 0.3, 0.0" layout="6, 6, 1" method="grid"/>\n'
    f'<entity max_trials="100" quantity="28"><foot-bot id="F{i}-"/></entity></distribute>\n'
    for i, c in enumerate(("3.0, 0.0, 0.0", "0.0, 3.0, 0.0", "-3.0, 0.0, 0.0", "0.0, -3.0, 0.0")))
XML = ('<argos-configuration><framework><experiment length="0" random_seed="513568" ticks_per_second="32"/>'
       '</framework><loop_functions><settings FoodItemCount="320" NumberOfClusters="5"/></loop_functions>'
       '<placement lens_focal_length="29"/>'
       f'<arena center="0,0,0.5" size="12.0, 12.0, 1">\n{WALLS}{GROUPS}</arena></argos-configuration>')


def test_the_file_is_scaled_to_the_swarm_and_the_arena():
    out = sa.scaled_xml(XML, 1000, 7, 38.0, 120.0, 3200, 50)
    assert '<experiment length="120"' in out and 'random_seed="7"' in out
    assert 'size="38, 38, 1"' in out and 'lens_focal_length="29"' in out
    assert out.count('quantity="250"') == 4 and out.count('layout="16, 16, 1"') == 4  # 256 places for 250
    assert re.findall(r'position center="([^"]+)"', out) == ["9.5, 0, 0.0", "0, 9.5, 0.0", "-9.5, 0, 0.0",
                                                            "0, -9.5, 0.0"]
    assert 'position="0,19,0"' in out and 'position="0,-19,0"' in out
    assert 'position="19,0,0"' in out and 'position="-19,0,0"' in out
    assert out.count('size="38,0.02,0.5"') == 2 and out.count('size="0.02, 38,0.5"') == 2
    assert 'FoodItemCount="3200"' in out and 'NumberOfClusters="50"' in out


def test_a_file_not_shaped_as_theirs_is_refused_by_what_is_missing():
    with pytest.raises(sa.ReferenceError, match="expected 1 wall_east, found 0"):
        sa.scaled_xml(XML.replace("wall_east", "wall_e"), 1000, 7, 38.0, 120.0, 3200, 50)
