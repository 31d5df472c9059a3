"""Command-line options shared by swarm-run and swarm-batch (no heavy imports here)."""

from __future__ import annotations

import argparse

from swarm_sim.scenario import DEFAULT_SCENARIO


def add_scenario_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--scenario", default=DEFAULT_SCENARIO,
                        help=f"scenario name or YAML path (default: {DEFAULT_SCENARIO})")
    parser.add_argument("--robots", type=int, help="number of robots (robots.count)")
    parser.add_argument("--duration", type=float, help="sim seconds (sim.duration)")
    parser.add_argument("--seed", type=int, help="random seed (default: the scenario's)")
    parser.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                        help="override any scenario field, e.g. --set resources.respawn=true")


def scenario_fields(args: argparse.Namespace) -> dict:
    """The dedicated options as `load_scenario` field overrides."""
    return {"robots__count": args.robots, "sim__duration": args.duration}
