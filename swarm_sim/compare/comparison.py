"""What `swarm-compare` needs to know about one paper comparison, so the CLI never names a paper."""

from __future__ import annotations

import argparse
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

from swarm_sim.compare.sweep import RunPlan
from swarm_sim.compare.verdicts import Claim


def given_out(args: argparse.Namespace) -> Path:
    """The ``--out`` directory as given: where most comparisons keep results.jsonl and the report."""
    return args.out


@dataclass(frozen=True)
class Rule:
    """A rule on which a paper's text and its authors' published code disagree, and which one a
    shipped scenario follows (REPORT.md's *Text vs the authors' code*)."""

    scenarios: str
    """The shipped scenarios concerned."""
    key: str
    """The scenario key that switches it (a dotted key, as `--set` takes it)."""
    text: str
    """What the paper's text says (and the key's value that reads it so, if any)."""
    code: str
    """What the authors' code does (and the key's value that does it), with the file."""
    shipped: str
    """``text``, ``code`` or ``neither``: which one the shipped scenario follows."""
    note: str = ""


def no_claims(args: argparse.Namespace) -> tuple[Claim, ...]:
    return ()


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
    claims: Callable[[argparse.Namespace], Sequence[Claim]] = no_claims
    """args -> the paper's claims one sweep's rows decide (`swarm_sim.compare.verdicts`); ids
    unique over all the comparison's sweeps, since they are judged (Holm) together."""
    rules: tuple[Rule, ...] = ()
    """Where the paper's text and its authors' code disagree, and which rule each scenario runs."""
