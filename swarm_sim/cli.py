"""Command-line options shared by swarm-run and swarm-batch (no heavy imports here)."""

from __future__ import annotations

import argparse
import math
import re
import signal
import sys
from collections.abc import Callable

import yaml

from swarm_sim.registry import default_scenario, scenario_files


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


def _interrupt(*_: object) -> None:
    raise KeyboardInterrupt


def stop_on_signals() -> None:
    """Ctrl-C, SIGTERM and SIGHUP (a closed terminal) all raise KeyboardInterrupt in the main
    thread, so a command ends through its one "interrupted" line and exit code 130 whatever stops it,
    even when its parent started it with SIGINT ignored (nohup, some CI shells)."""
    signal.signal(signal.SIGINT, signal.default_int_handler)
    signal.signal(signal.SIGTERM, _interrupt)
    signal.signal(signal.SIGHUP, _interrupt)


def first_paragraph(doc: str | None) -> str:
    """A module docstring's first paragraph as one line: a command's ``--help`` description,
    whole (never its first line cut mid-sentence)."""
    return " ".join((doc or "").strip().split("\n\n")[0].split())


_SENTENCE_END = re.compile(r"(?<=[a-z0-9)]{4})\. (?=[A-Z])")
"""A full stop that ends a sentence: not after an abbreviation (Sec., et al.), not before a number."""


def _first_sentence(text: str, width: int = 72) -> str:
    """The first sentence of the comment block a YAML file opens with, cut to `width`."""
    comment = []
    for line in text.splitlines():
        if not line.startswith("#"):
            break
        comment.append(line.lstrip("#").strip())
    sentence = _SENTENCE_END.split(" ".join(comment))[0].rstrip(".")
    return sentence if len(sentence) <= width else sentence[: width - 3].rstrip() + "..."


def scenario_table(width: int = 120) -> list[str]:
    """One line per shipped scenario, at most `width` characters: its name, its algorithm, robots,
    sim seconds and the first sentence of the comment it opens with (cut to fit: an algorithm
    name longer than its column shortens that line's sentence)."""
    lines = [f"{'scenario':16s} {'algorithm':9s} {'robots':>5s} {'sim s':>7s}  about"]
    for name, path in scenario_files().items():
        text = path.read_text()
        data = yaml.safe_load(text) or {}
        controller = data.get("controller") or {}
        robots = (data.get("robots") or {}).get("count", "")
        duration = (data.get("sim") or {}).get("duration", "")
        row = f"{name:16s} {controller.get('behaviour', ''):9s} {robots!s:>5s} {duration!s:>7s}  "
        lines.append(row + _first_sentence(text, min(72, width - len(row))))
    return lines


class _ListScenarios(argparse.Action):
    def __init__(self, option_strings, dest, **kwargs) -> None:
        super().__init__(option_strings, dest, nargs=0, default=argparse.SUPPRESS, **kwargs)

    def __call__(self, parser, namespace, values, option_string=None) -> None:
        print("\n".join(scenario_table()))
        sys.exit(0)


def add_scenario_arguments(parser: argparse.ArgumentParser) -> None:
    default = default_scenario()
    parser.add_argument("--scenario", default=default,
                        help=f"scenario name or YAML path (default: {default}; --list-scenarios "
                             "shows the shipped ones)")
    parser.add_argument("--list-scenarios", action=_ListScenarios,
                        help="list the shipped scenarios (name, algorithm, robots, sim seconds, what it is) and exit")
    parser.add_argument("--robots", type=number(int, 1), help="number of robots (robots.count)")
    parser.add_argument("--duration", type=number(float, 0, open_low=True), help="sim seconds (sim.duration)")
    parser.add_argument("--seed", type=number(int, 0, 2**63 - 1), help="random seed (default: the scenario's)")
    parser.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                        help="override any scenario field, e.g. --set resources.respawn=true")


def scenario_fields(args: argparse.Namespace) -> dict:
    """The dedicated options as `load_scenario` field overrides."""
    return {"robots__count": args.robots, "sim__duration": args.duration}
