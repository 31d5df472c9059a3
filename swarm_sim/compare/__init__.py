"""Paper comparisons: sweep seeds and settings, then write tables, box plots and tests next to the papers' numbers.

``swarm-compare queue`` reproduces the queue paper's evaluation (Zaman et al.,
queue_depot_traffic.md: Table II, Figs 8-10, independent two-sample t-tests) and
``swarm-compare spiral`` the MDBSA paper's experiments 1-3 (Lu & Luna 2023,
mdbsa_spiral_search.md: Figs 6-10, two-sided Mann-Whitney U tests).

`sweep` runs the plans on an executor (`swarm_sim.executors`: local pool or Dask) and keeps
``results.jsonl`` resumable, `stats` and `report` hold what both papers share, `queue_paper` and
`spiral_paper` what is one paper's, `cli` is ``swarm-compare`` and `reproduce` its ``all``
subcommand (every registered comparison, then REPORT.md).
The report functions take plain lists of result dicts, so they work on any results file and tests
feed them synthetic data.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from swarm_sim.compare.comparison import Comparison


def comparisons() -> dict[str, Comparison]:
    """Every paper comparison by subcommand name, as the registered algorithms name them
    (`swarm_sim.registry.Algorithm.comparison`), in registry order."""
    from swarm_sim import registry

    out: dict[str, Comparison] = {}
    for a in registry.algorithms():
        if a.comparison:
            c = registry.resolve(a.comparison)
            out.setdefault(c.name, c)
    return out
