"""Command-line options shared by swarm-run and swarm-batch (no heavy imports here)."""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable

from swarm_sim.scenario import DEFAULT_SCENARIO


def number(kind: type, low: float, high: float = math.inf, *, open_low: bool = False) -> Callable[[str], float]:
    """An argparse type: a finite `kind` in [low, high] ((low, high] with `open_low`); anything
    else is refused with one line naming the range (argparse adds the option's name)."""
    span = f"{'(' if open_low else '['}{low:g}, {high:g}]"

    def parse(text: str) -> float:
        try:
            value = kind(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected {'an integer' if kind is int else 'a number'}, got {text!r}") from None
        if not math.isfinite(value) or value > high or value < low or (open_low and value == low):
            raise argparse.ArgumentTypeError(f"{text} is outside {span}")
        return value

    return parse


def add_scenario_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--scenario", default=DEFAULT_SCENARIO,
                        help=f"scenario name or YAML path (default: {DEFAULT_SCENARIO})")
    parser.add_argument("--robots", type=number(int, 1), help="number of robots (robots.count)")
    parser.add_argument("--duration", type=number(float, 0, open_low=True), help="sim seconds (sim.duration)")
    parser.add_argument("--seed", type=number(int, 0, 2**63 - 1), help="random seed (default: the scenario's)")
    parser.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                        help="override any scenario field, e.g. --set resources.respawn=true")


def scenario_fields(args: argparse.Namespace) -> dict:
    """The dedicated options as `load_scenario` field overrides."""
    return {"robots__count": args.robots, "sim__duration": args.duration}
