"""Paper comparisons: sweep seeds and settings, then write tables, box plots and tests next to the papers' numbers.

``swarm-compare queue`` reproduces the queue paper's evaluation (Zaman et al.,
queue_depot_traffic.md: Table II, Figs 8-10, independent two-sample t-tests) and
``swarm-compare spiral`` the MDBSA paper's experiments 1-3 (Lu & Luna 2023,
mdbsa_spiral_search.md: Figs 6-10, two-sided Mann-Whitney U tests).

`sweep` runs the plans and keeps ``results.jsonl`` resumable, `stats` and `report` hold what both
papers share, `queue_paper` and `spiral_paper` what is one paper's, and `cli` is ``swarm-compare``.
The report functions take plain lists of result dicts, so they work on any results file and tests
feed them synthetic data.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from swarm_sim.compare.comparison import Comparison


def comparisons() -> dict[str, Comparison]:
    """Every paper comparison by subcommand name: the one list of them."""
    from swarm_sim.compare.queue_paper import QUEUE_COMPARISON
    from swarm_sim.compare.spiral_paper import SPIRAL_COMPARISON

    return {c.name: c for c in (QUEUE_COMPARISON, SPIRAL_COMPARISON)}
