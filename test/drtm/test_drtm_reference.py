"""reference/drtm_argos.py: the experiment file it writes and the log it reads (hand-made text)."""
import importlib.util
from pathlib import Path

import pytest

from swarm_sim.scenario.loading import load_scenario

_PATH = Path(__file__).resolve().parents[2] / "reference" / "drtm_argos.py"
_spec = importlib.util.spec_from_file_location("drtm_argos", _PATH)
da = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(da)

TEN_TICKS = load_scenario("drtm", ["sim.duration=1.0"])
"""Sec. 3.1's arena and ledger, 1 s = 10 ticks long."""


def _log(ticks):
    return "# clock\tactive\tdrops\tdeliveries\toaes\toaes_returning\n" + "".join(
        "\t".join(str(x) for x in t) + "\n" for t in ticks)


def _ticks(n=10):
    """Two robots foraging every tick; a drop at tick 4 booked at tick 5; 3 OAEs at tick 7."""
    return [(k, 2, int(k >= 4), int(k >= 5), 3 * int(k >= 7), int(k >= 7)) for k in range(1, n + 1)]


def test_the_ledger_is_charged_as_our_nest_charges_it():
    got = da.measures(da.read_log(_log(_ticks()), 10), TEN_TICKS)
    # 1500 (5 + 1) - 1 x 2 robots x 10 ticks - 10 x 3 OAEs - 1500 x 2 tokens/min x 1 s / 60
    assert got["nest_food_final"] == pytest.approx((9000 - 20 - 30 - 50) / 1500)
    assert got["food_collected"] == 1 and got["oae_total"] == 3 and got["oae_returning_total"] == 1
    assert got["oae_per_robot"] == pytest.approx(3 / 20)
    assert got["energy_efficiency"] == pytest.approx(got["nest_food_final"])
    assert got["active_robots_mean"] == 2.0
    # V_f: the mean over ticks 1..T of |F_d - F(t)|, F(t) below F_d throughout
    assert 14.0 < got["food_deviation"] < 15.1


@pytest.mark.parametrize("ticks, why", [
    (_ticks(9), "holds 9 ticks, not ticks 1..10"),
    (_ticks()[1:] + _ticks()[:1], "not ticks 1..10 in order"),
])
def test_a_log_missing_or_shuffling_ticks_is_refused(ticks, why):
    with pytest.raises(da.ReferenceError, match=why):
        da.read_log(_log(ticks), 10)


def test_a_line_that_is_no_tick_is_refused_by_its_number():
    with pytest.raises(da.ReferenceError, match="log line 3: not a tick"):
        da.read_log(_log(_ticks()).replace("2\t2\t0", "2\tx\t0", 1), 10)


def test_the_experiment_carries_the_scenario_and_the_examples_parameters(tmp_path):
    xml = da.experiment_xml(TEN_TICKS, 7, tmp_path, tmp_path / "log.tsv", occlusions=False)
    assert 'random_seed="7"' in xml and 'length="1"' in xml and 'ticks_per_second="10"' in xml
    assert 'nest_radius="0.75"' in xml and 'items="20"' in xml and 'quantity="20"' in xml
    assert 'check_occlusions="false"' in xml and 'minimum_resting_time="50"' in xml
    assert 'social_rule_rest_to_explore_delta_prob="0.01"' in xml
    assert 'position="0,2.05,0"' in xml  # the wall's inner face at L/2 = 2 m


def test_seed_zero_is_refused_as_argos_would_take_the_clock(tmp_path):
    with pytest.raises(da.ReferenceError, match="seed 0"):
        da.experiment_xml(TEN_TICKS, 0, tmp_path, tmp_path / "log.tsv", occlusions=True)


_vs_spec = importlib.util.spec_from_file_location("drtm_versus", _PATH.parent / "drtm_versus.py")
dv = importlib.util.module_from_spec(_vs_spec)
_vs_spec.loader.exec_module(dv)


def _row(scale, k):
    """A run whose every measure is `scale` x a base value, with some spread over k."""
    x = scale * (1.0 + 0.02 * (k % 5 - 2))
    return {"food_collected": 100 * x, "oae_total": 1000 * x, "oae_per_robot": 50 * x, "food_deviation": 5 * x,
            "energy_efficiency": 0.2 * x, "nest_food_final": 20 * x, "active_robots_series": [[0.0, 10 * x]]}


@pytest.mark.parametrize("scale, verdict", [(1.0, "holds"), (2.0, "contradicts")])
def test_ours_is_judged_against_the_reference_on_the_level_scale(scale, verdict):
    lines = dv.table([_row(scale, k) for k in range(20)], {"occlusions off": [_row(1.0, k) for k in range(20)]})
    assert len(lines) == 2 + len(dv.MEASURES)
    assert all(line.endswith(f"| {verdict} |") for line in lines[2:])
