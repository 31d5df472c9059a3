"""Paper comparisons: sweep seeds and settings, then write tables, box plots and tests next to the papers' numbers.

Each paper's comparison (a `comparison.Comparison`) lives in its own package and is named by its
registry record; ``swarm-compare NAME`` runs one, ``swarm-compare all`` every one and REPORT.md.

`sweep` runs the plans on an executor (`swarm_sim.executors`: local pool or Dask) and keeps
``results.jsonl`` resumable, `stats` and `report` hold what the papers' comparisons share,
`commands` the parser and one comparison's run, `cli` is ``swarm-compare`` and `reproduce` its
``all`` subcommand (every registered comparison, then REPORT.md). The report functions take plain
lists of result dicts, so they work on any results file and tests feed them synthetic data.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from swarm_sim import registry

if TYPE_CHECKING:
    from swarm_sim.compare.comparison import Comparison


def comparisons() -> dict[str, Comparison]:
    """Every paper comparison by subcommand name, as the registered algorithms name them
    (`swarm_sim.registry.Algorithm.comparison`), in registry order."""
    out: dict[str, Comparison] = {}
    for a in registry.algorithms():
        if a.comparison:
            c = registry.resolve(a.comparison)
            out.setdefault(c.name, c)
    return out
