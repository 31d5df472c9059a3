"""Run the ARGoS foraging example's controller in the DRTM paper's arena and record it in our
results schema.

The DRTM paper's code is not public; its set-up follows the ARGoS foraging example
(ilpincy/argos3-examples: 4 x 4 m, 20 foot-bots, 10 ticks/s, one energy unit per walking robot
and tick, a minimum resting time of 50 ticks = the paper's T_1). The example's controller
(``controllers/footbot_foraging``) decides when to forage by its own rule: per-robot
rest-to-explore and explore-to-rest probabilities moved by food found, collisions and what
resting robots hear of others' last exploration (Labella et al.'s rule). It has no parameter
that gives a response threshold P = S^n / (S^n + theta^n), so it cannot run DRTM or ARTM; it is
the reference for the *robot*: the same foot-bot, ARGoS's physics and the example's motion in
the paper's arena, beside our ``drtm_example`` scenario (the example's rule on our side). The
difference between the two is what our robot, world and port add; the difference between our
``drtm_example`` and our ``drtm`` is what the rule does.

This script takes an already built checkout of argos3-examples (nothing of it is committed, and
nothing here builds it: reference/README.md), compiles our loop functions
(``reference/drtm_arena/``: the paper's arena, which the example's own loop functions cannot
give: their nest is the strip x < -1), writes an experiment file with the example's controller
parameters, the scenario's arena and a seed, runs ``argos3``, and turns the per-tick log into a
row of ``results/reference/drtm_example/results.jsonl``. The energy ledger (F(t), V_f, E_e) is computed
from that log by our own `NestLedger`, so both columns use one formula.
"""
from __future__ import annotations

import argparse
import json
import re
import subprocess
import sys
from pathlib import Path

_HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(_HERE))  # run as a script or loaded by path
sys.path.insert(1, str(_HERE.parent))  # our package, for the scenario and the nest ledger
from argos_run import done_keys, ReferenceError, run_argos  # noqa: E402

from swarm_controllers.drtm.config import NestConfig  # noqa: E402
from swarm_controllers.drtm.metrics import SERIES_PERIOD  # noqa: E402
from swarm_controllers.drtm.nest import NestLedger  # noqa: E402
from swarm_sim.scenario import Scenario  # noqa: E402
from swarm_sim.scenario.loading import load_scenario  # noqa: E402

CONTROLLER = "build/controllers/footbot_foraging/libfootbot_foraging.so"
"""The example's controller library in a built checkout."""
SOURCE = _HERE / "drtm_arena" / "drtm_arena_loop_functions.cpp"
LIBRARY = "build/swarmforage_drtm_arena/libdrtm_arena_loop_functions.so"
"""Where our loop functions are compiled to, inside the checkout's build folder."""

STATE = {
    "initial_rest_to_explore_prob": "0.1", "initial_explore_to_rest_prob": "0.1",
    "food_rule_explore_to_rest_delta_prob": "0.01", "food_rule_rest_to_explore_delta_prob": "0.01",
    "collision_rule_explore_to_rest_delta_prob": "0.01",
    "social_rule_explore_to_rest_delta_prob": "0.01", "social_rule_rest_to_explore_delta_prob": "0.01",
    "minimum_resting_time": "50", "minimum_unsuccessful_explore_time": "600",
    "minimum_search_for_place_in_nest_time": "50",
}
"""The example's controller parameters, as its ``experiments/foraging.argos`` sets them."""

GO_STRAIGHT_DEG, DELTA = 5.0, 0.1
"""Its ``<diffusion go_straight_angle_range="-5:5" delta="0.1">``: our loop functions count an
OAE with the same two thresholds."""

LOG = re.compile(r"^(\d+)\t(\d+)\t(\d+)\t(\d+)\t(\d+)\t(\d+)$")
"""A tick of our loop functions' log: clock, robots not resting, drops, deliveries booked at
rest, OAEs, OAEs of returning robots (the last four cumulative)."""


def compile_loop_functions(prefix: Path, tree: Path) -> Path:
    """Our loop functions as a library next to the checkout's build (rebuilt when the source is
    newer); the compiler's first error line names a failure."""
    lib = tree / LIBRARY
    if lib.exists() and lib.stat().st_mtime >= SOURCE.stat().st_mtime:
        return lib
    lib.parent.mkdir(parents=True, exist_ok=True)
    controller_dir = (tree / CONTROLLER).parent
    argos_lib = prefix / "lib" / "argos3"
    done = subprocess.run(
        ["g++", "-std=c++17", "-O2", "-fPIC", "-shared", "-o", str(lib), str(SOURCE),
         f"-I{tree}", f"-I{prefix / 'include'}", "-I/usr/include/lua5.3",
         f"-L{controller_dir}", "-lfootbot_foraging", f"-L{argos_lib}", "-largos3core_simulator",
         "-largos3plugin_simulator_footbot", "-largos3plugin_simulator_entities",
         "-largos3plugin_simulator_genericrobot", f"-Wl,-rpath,{controller_dir}:{argos_lib}"],
        capture_output=True, text=True, stdin=subprocess.DEVNULL)
    if done.returncode != 0:
        errors = [line for line in done.stderr.splitlines() if "error" in line] or ["(no message)"]
        raise ReferenceError(f"compiling {SOURCE.name}: {errors[0]}")
    return lib


def experiment_xml(scenario: Scenario, seed: int, tree: Path, log: Path, occlusions: bool) -> str:
    """The example's controller in the scenario's arena: walls with their inner faces at +-L/2,
    one light above the nest's centre (the example's height and intensity), the robots placed by
    our loop functions. ``occlusions``: whether robots block range-and-bearing messages (ARGoS's
    default; off, every resting robot in the 3-m range hears every announcement)."""
    if seed <= 0:
        raise ReferenceError(f"seed {seed}: ARGoS draws a seed from the clock for 0; give 1 or more")
    s = scenario
    half, cx, cy = s.arena.size / 2.0, *s.depot.center
    if (cx, cy) != (0.0, 0.0):
        raise ReferenceError(f"{s.name}: our loop functions put the nest at the arena's centre, not at {cx}, {cy}")
    ticks = round(1.0 / s.sim.dt)
    long_, out = 2 * half + 0.2, half + 0.05  # 0.1 m thick, inner faces at +-L/2, closing the corners
    walls = "\n".join(
        f'<box id="wall_{i}" size="{sx},{sy},0.5" movable="false">'
        f'<body position="{px},{py},0" orientation="0,0,0"/></box>'
        for i, (sx, sy, px, py) in enumerate(((long_, 0.1, 0, out), (long_, 0.1, 0, -out),
                                              (0.1, long_, out, 0), (0.1, long_, -out, 0))))
    state = " ".join(f'{k}="{v}"' for k, v in STATE.items())
    return f"""<?xml version="1.0" ?>
<argos-configuration>
  <framework><system threads="0"/>
    <experiment length="{s.sim.duration:g}" ticks_per_second="{ticks}" random_seed="{seed}"/></framework>
  <controllers>
    <footbot_foraging_controller id="ffc" library="{tree / CONTROLLER}">
      <actuators><differential_steering implementation="default"/><leds implementation="default" medium="leds"/>
        <range_and_bearing implementation="default"/></actuators>
      <sensors><footbot_proximity implementation="default" show_rays="false"/>
        <footbot_light implementation="rot_z_only" show_rays="false"/>
        <footbot_motor_ground implementation="rot_z_only"/>
        <range_and_bearing implementation="medium" medium="rab"/></sensors>
      <params><diffusion go_straight_angle_range="-{GO_STRAIGHT_DEG:g}:{GO_STRAIGHT_DEG:g}" delta="{DELTA:g}"/>
        <wheel_turning hard_turn_angle_threshold="90" soft_turn_angle_threshold="70" no_turn_angle_threshold="10"
                       max_speed="10"/>
        <state {state}/></params>
    </footbot_foraging_controller>
  </controllers>
  <loop_functions library="{tree / LIBRARY}" label="drtm_arena_loop_functions">
    <drtm_arena half_side="{half:g}" nest_radius="{s.depot.radius:g}" items="{s.resources.count}"
                margin="{s.resources.margin:g}" clearance="{s.resources.min_depot_clearance:g}"
                pickup_radius="{s.sensors.pickup_radius:g}" go_straight_deg="{GO_STRAIGHT_DEG:g}" delta="{DELTA:g}"
                output="{log}"/>
  </loop_functions>
  <arena size="{2 * half + 1:g}, {2 * half + 1:g}, 2" center="0,0,1">
    <floor id="floor" source="loop_functions" pixels_per_meter="50"/>
    {walls}
    <light id="light" position="0,0,1.0" orientation="0,0,0" color="yellow" intensity="3.0" medium="leds"/>
    <distribute><position method="uniform" min="{-half + 0.1:g},{-half + 0.1:g},0" max="{half - 0.1:g},{-half + 0.9:g},0"/>
      <orientation method="uniform" min="0,0,0" max="360,0,0"/>
      <entity quantity="{s.robots.count}" max_trials="1000"><foot-bot id="fb"><controller config="ffc"/></foot-bot></entity>
    </distribute>
  </arena>
  <physics_engines><dynamics2d id="dyn2d"/></physics_engines>
  <media><range_and_bearing id="rab" check_occlusions="{str(occlusions).lower()}"/><led id="leds"/></media>
</argos-configuration>
"""


def read_log(text: str, ticks: int) -> list[tuple[int, ...]]:
    """The log's ticks 1..``ticks``, each (clock, active, drops, deliveries, oaes, oaes_returning)."""
    rows = []
    for n, line in enumerate(text.splitlines(), 1):
        if line.startswith("#") or not line.strip():
            continue
        m = LOG.match(line)
        if not m:
            raise ReferenceError(f"log line {n}: not a tick of our loop functions: {line[:60]!r}")
        rows.append(tuple(int(x) for x in m.groups()))
    if [r[0] for r in rows] != list(range(1, ticks + 1)):
        raise ReferenceError(f"the log holds {len(rows)} ticks, not ticks 1..{ticks} in order")
    return rows


def measures(rows: list[tuple[int, ...]], scenario: Scenario) -> dict:
    """The DRTM paper's measures (Sec. 2.4) of a run, as our metrics name them: the ledger is
    charged, tick by tick, for the robots not resting, the deliveries booked so far and the
    OAEs so far, as our nest server is."""
    config = NestConfig.of(scenario)
    ledger = NestLedger(config, scenario.sim.dt)
    robots, dt = scenario.robots.count, scenario.sim.dt
    food, every = [], round(SERIES_PERIOD / dt)
    foods, actives, oaes = [[0.0, config.initial_food]], [[0.0, 0]], [[0.0, 0]]
    for clock, active, _drops, deliveries, total_oaes, _ in rows:
        ledger.advance(1, active)
        ledger.deliveries, ledger.avoidances = deliveries, total_oaes
        food.append(ledger.food)
        if clock % every == 0:
            t = round(clock * dt, 6)
            foods.append([t, round(ledger.food, 6)])
            actives.append([t, active])
            oaes.append([t, total_oaes])
    last = rows[-1]
    drops, m_t = last[2], last[4]
    return {
        "food_collected": drops, "resources_delivered": drops, "oae_total": m_t,
        "oae_per_robot": round(m_t / robots, 6), "oae_returning_total": last[5],
        "food_deviation": round(sum(abs(config.desired_food - f) for f in food) / len(food), 6),
        "nest_food_final": round(food[-1], 6),
        "energy_efficiency": round(food[-1] / drops, 6) if drops else None,
        "active_robots_mean": round(sum(r[1] for r in rows) / len(rows), 6),
        "nest_food_series": foods, "active_robots_series": actives, "oae_series": oaes,
    }


def row(scenario: Scenario, seed: int, got: dict, wall_s: float, cpu_s: float, occlusions: bool,
        provenance: dict) -> dict:
    sim_s = scenario.sim.duration
    return {
        "strategy": "foraging_example", "cell": 0, "condition": "3.1", "scenario": scenario.name,
        "settings": json.dumps({"rab_occlusions": occlusions}), "seed": seed, "robots": scenario.robots.count,
        "mode": "reference", "reference": True, "sim_seconds": sim_s, "wall_seconds": round(wall_s, 3),
        "cpu_seconds": round(cpu_s, 3), "real_time_factor": round(sim_s / wall_s, 2) if wall_s > 0 else None,
        "total_resources": scenario.resources.count, **got, **provenance,
    }


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                epilog="Appends one row per run to --out; runs already there are skipped.")
    p.add_argument("--argos", required=True, type=Path, help="the argos3 executable built here (PREFIX/bin/argos3)")
    p.add_argument("--tree", required=True, type=Path, help="a built checkout of ilpincy/argos3-examples")
    p.add_argument("--commit", required=True, help="the checkout's commit (40 hex digits)")
    p.add_argument("--argos-commit", required=True, help="ARGoS 3's commit it was built from")
    p.add_argument("--scenario", default="drtm_example",
                   help="our scenario whose arena, swarm and ledger to use (the example's rule on our side)")
    p.add_argument("--seeds", type=int, default=20, help="seeds 1..N (ARGoS takes 0 as 'from the clock')")
    p.add_argument("--no-occlusions", action="store_true",
                   help="robots do not block range-and-bearing messages (our nest relays every announcement)")
    p.add_argument("--timeout", type=float, default=600.0, help="wall seconds one run may take")
    p.add_argument("--out", type=Path, default=Path("results/reference/drtm_example/results.jsonl"))
    a = p.parse_args(argv)
    try:
        if not re.fullmatch(r"[0-9a-f]{40}", a.commit) or not re.fullmatch(r"[0-9a-f]{40}", a.argos_commit):
            raise ReferenceError("--commit and --argos-commit take 40 hex digits")
        if not (a.tree / CONTROLLER).is_file():
            raise ReferenceError(f"--tree {a.tree}: no {CONTROLLER} (build the checkout first)")
        if a.seeds < 1:
            raise ReferenceError(f"--seeds {a.seeds}: give 1 or more")
        scenario = load_scenario(a.scenario)
        prefix = a.argos.resolve().parent.parent
        compile_loop_functions(prefix, a.tree)
        occlusions = not a.no_occlusions
        provenance = {"repository": "ilpincy/argos3-examples", "branch": "master", "commit": a.commit,
                      "xml": "experiments/foraging.argos (its controller's parameters) in our arena "
                             "(reference/drtm_arena)", "argos_commit": a.argos_commit, "build_fixes": "none"}
        a.out.parent.mkdir(parents=True, exist_ok=True)
        done = done_keys(a.out, lambda r: (r["scenario"], r["settings"], int(r["seed"]), r["commit"]))
        settings = json.dumps({"rab_occlusions": occlusions})
        env = {"LD_LIBRARY_PATH": str(prefix / "lib" / "argos3"), "ARGOS_PLUGIN_PATH": str(prefix / "lib" / "argos3"),
               "PATH": "/usr/bin:/bin"}
        ticks = round(scenario.sim.duration / scenario.sim.dt)
        for seed in range(1, a.seeds + 1):
            if (scenario.name, settings, seed, a.commit) in done:
                continue
            log = a.tree / f".swarmforage_drtm_s{seed}.tsv"
            try:
                xml = experiment_xml(scenario, seed, a.tree, log, occlusions)
                _, wall, cpu = run_argos([str(a.argos), "-z"], a.tree, xml, f".swarmforage_drtm_s{seed}.argos",
                                         f"seed {seed}", a.timeout, env)
                got = measures(read_log(log.read_text(), ticks), scenario)
            finally:
                log.unlink(missing_ok=True)
            r = row(scenario, seed, got, wall, cpu, occlusions, provenance)
            with a.out.open("a") as f:
                f.write(json.dumps(r) + "\n")
            print(f"[reference] foraging_example seed {seed}: F_t {got['food_collected']}, M_T {got['oae_total']}, "
                  f"{got['active_robots_mean']:.1f} robots foraging, {wall:.1f} s wall", flush=True)
    except (ReferenceError, OSError, ValueError) as e:
        print(f"reference: {e}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
