"""What `swarm-compare` needs to know about one paper comparison, so the CLI never names a paper."""

from __future__ import annotations

import argparse
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

from swarm_sim.compare.sweep import RunPlan


def given_out(args: argparse.Namespace) -> Path:
    """The ``--out`` directory as given: where most comparisons keep results.jsonl and the report."""
    return args.out


@dataclass(frozen=True)
class Comparison:
    """One ``swarm-compare`` subcommand: its own options, the runs to make and the report to write.

    The CLI adds the options every comparison shares (``--seeds``, ``--out``, ``--strategies``,
    ``--resume`` ...), checks ``--strategies`` against `strategies` and runs the sweep; everything
    else about the paper is behind these callables.
    """

    name: str
    """Subcommand name (``queue``, ``spiral``)."""
    help: str
    """One line for ``swarm-compare --help``."""
    default_out: str
    """Default ``--out`` directory."""
    strategies: tuple[str, ...]
    """Scenario names compared, in the paper's order (``--strategies`` picks a subset, kept in this order)."""
    add_arguments: Callable[[argparse.ArgumentParser], None]
    """Adds the comparison's own options to its subparser (before the shared ones)."""
    plans: Callable[[argparse.Namespace, list[str]], list[RunPlan]]
    """(args, chosen strategies) -> the runs of the sweep, each done for every seed."""
    write_report: Callable[[Sequence[dict], Path, argparse.Namespace, list[str]], list[Path]]
    """(rows, output directory, args, chosen strategies) -> the files written."""
    out_dir: Callable[[argparse.Namespace], Path] = given_out
    """args -> the directory for results.jsonl and the report (e.g. one per experiment)."""
