"""``swarm-compare``: one subcommand per paper comparison, each a sweep then a report.

The subcommands come from a mapping of name -> `Comparison` (by default
`swarm_sim.compare.comparisons()`); nothing here knows a paper.
"""

from __future__ import annotations

import sys
from collections.abc import Mapping
from contextlib import nullcontext

from swarm_sim import compare
from swarm_sim.compare.commands import ALL, build_parser, run_comparison, strategies_of
from swarm_sim.compare.comparison import Comparison
from swarm_sim.compare.reproduce import reproduce_all
from swarm_sim.cli import stop_on_signals
from swarm_sim.compare.sweep import RunFunction
from swarm_sim.executors import Executor, executor_from_args


def main(argv: list[str] | None = None, run: RunFunction | None = None,
         comparisons: Mapping[str, Comparison] | None = None, executor: Executor | None = None) -> int:
    """`run` replaces `swarm_sim.batch.run_one` (tests); with the real one every scenario is loaded
    first. `comparisons` replaces `swarm_sim.compare.comparisons()`; `executor` the one the
    options ask for."""
    comparisons = compare.comparisons() if comparisons is None else comparisons
    parser = build_parser(comparisons)
    args = parser.parse_args(argv)
    if argv is None:  # the command itself, not a caller's function call
        stop_on_signals()
    try:
        if args.command == ALL:
            return reproduce_all(args, comparisons, run=run, executor=executor)
        comparison = comparisons[args.command]
        strategies = strategies_of(args.strategies, comparison.strategies, parser)
        with nullcontext(executor) if executor else executor_from_args(args) as ex:
            return run_comparison(comparison, args, strategies, run=run, executor=ex)[0]
    except (RuntimeError, OSError) as exc:  # no Dask, scheduler unreachable
        print(f"swarm-compare: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:  # outside a sweep (the sweeps say where their runs are and return 130)
        print("swarm-compare: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
