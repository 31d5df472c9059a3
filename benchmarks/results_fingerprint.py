"""Fingerprint every shipped scenario's batch result, to check that a refactoring changed nothing.

Runs each shipped scenario (`swarm_sim.registry.scenario_files`) for a short, fixed sim time with its own robot
count and seed, and prints one JSON object per scenario: the run's summary without wall-clock
fields, plus a SHA-256 of every robot's odometry pose at every tick. Two fingerprints written
before and after a change must be identical line for line:

    .venv/bin/python benchmarks/results_fingerprint.py --out before.jsonl
    ... change ...
    .venv/bin/python benchmarks/results_fingerprint.py --compare before.jsonl

--compare judges the poses hash and every field present on both sides. A field on one side only
is not a change of result: a row carries only its own paper's fields (issue 38), so a file
written before that holds other papers' fields as None. Those are counted as padding; any other
one-sided field is named (a probe the run no longer asks for, say).
"""

from __future__ import annotations

import argparse
import hashlib
import json
import sys
from pathlib import Path

WALL_FIELDS = ("wall_seconds", "real_time_factor")


def fingerprint(name: str, duration: float) -> dict:
    from swarm_sim.analysis.metrics import summarize
    from swarm_sim.batch import run_batch
    from swarm_sim.scenario import load_scenario

    scenario = load_scenario(name, (f"sim.duration={duration}",))
    run = run_batch(scenario, record_poses=True)
    summary = {k: v for k, v in summarize(run.trace).items() if k not in WALL_FIELDS}
    summary["poses_sha256"] = hashlib.sha256(run.poses.tobytes()).hexdigest()
    return summary


def main(argv: list[str] | None = None) -> int:
    from swarm_sim.registry import scenario_files

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--duration", type=float, default=240.0, help="sim seconds per scenario")
    parser.add_argument("--out", type=Path, help="write the fingerprints here (JSON lines)")
    parser.add_argument("--compare", type=Path, help="compare with fingerprints written earlier")
    parser.add_argument("scenarios", nargs="*", help="default: every shipped scenario")
    args = parser.parse_args(argv)
    names = args.scenarios or list(scenario_files())
    rows = []
    for name in names:
        rows.append(fingerprint(name, args.duration))
        print(json.dumps(rows[-1], sort_keys=True), flush=True)
    if args.out:
        args.out.write_text("".join(json.dumps(r, sort_keys=True) + "\n" for r in rows))
    if args.compare:
        before = {r["scenario"]: r for r in map(json.loads, args.compare.read_text().splitlines())}
        changed = []
        for new in rows:
            old = before.get(new["scenario"], {})
            keys = sorted(k for k in set(old) & set(new) if old[k] != new[k])
            if keys or not old:
                changed.append(new["scenario"])
                print(f"CHANGED {new['scenario']}: {', '.join(keys) or 'not in the earlier file'}", file=sys.stderr)
            elif set(old) != set(new):
                padding = [k for k in set(old) ^ set(new) if {**old, **new}[k] is None]
                only_before = sorted(k for k in set(old) - set(new) if k not in padding)
                only_now = sorted(k for k in set(new) - set(old) if k not in padding)
                print(f"{new['scenario']}: identical on the {len(set(old) & set(new))} fields of both; "
                      f"{len(padding)} None fields on one side only; other fields only before {only_before}, "
                      f"only now {only_now}", file=sys.stderr)
        print(f"{len(rows) - len(changed)}/{len(rows)} scenarios identical (poses and every field of both)",
              file=sys.stderr)
        return 1 if changed else 0
    return 0


if __name__ == "__main__":
    sys.exit(main())
