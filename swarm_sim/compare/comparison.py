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
class Headline:
    """One headline claim of a paper and whether our runs bear it out (REPORT.md's summary)."""

    claim: str
    """The paper's claim, in its words or close to them."""
    paper: str
    """The paper's number or statement, short."""
    ours: str
    """What our runs give, short."""
    holds: bool | None
    """True / False; None when our runs cannot tell (a strategy or cell missing)."""


def no_headlines(rows: Sequence[dict], args: argparse.Namespace, strategies: list[str]) -> list[Headline]:
    return []


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
    reproduce: tuple[tuple[str, ...], ...] = ((),)
    """The subcommand's own options, one tuple per sweep, that together reproduce the paper
    (``swarm-compare all`` runs each; e.g. one per experiment). Default: one sweep with the
    defaults."""
    headlines: Callable[[Sequence[dict], argparse.Namespace, list[str]], list[Headline]] = no_headlines
    """(rows, args, strategies) -> the paper's headline claims checked on one sweep's rows."""
