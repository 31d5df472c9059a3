"""REPORT.md's opening: every paper's claims judged on every robot model (`swarm_sim.compare.verdicts`).

It leads with the truth: per paper and robot model the count of claims in each verdict class, then
every level cell (the paper's number, ours ± 95 % interval, n, the ratio), then the relations and
trends, then each claim that does not hold with its cause and the cause's grade, then where a
paper's text and its authors' code disagree, which rule each scenario follows. Where
``OUT/reference/<comparison>/**/results.jsonl`` holds runs of the authors' code, each level cell also
shows them and a verdict of ours against them. Nothing here knows a paper: the claims, rows and
rules come from each comparison's sweeps.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from swarm_sim.compare.reference import (
    evaluate_reference,
    evaluate_reference_relations,
    load_reference,
    matching,
)
from swarm_sim.compare.report import REFERENCE_LABEL, fmt_p, md_table
from swarm_sim.compare.verdicts import (
    ALPHA,
    BOOTSTRAP,
    CODE,
    GRADES,
    HOLDS,
    LEVEL,
    LEVEL_BAND,
    NOT_SHOWN,
    OPEN,
    POWER,
    VERDICTS,
    CellVerdict,
    Verdict,
    counts,
    evaluate,
)


def _num(x: float, digits: int = 3) -> str:
    if x is None or not math.isfinite(x):
        return "—"
    return f"{x:.{digits}g}" if abs(x) < 10 ** digits else f"{x:.0f}"


def _ci(cv: CellVerdict) -> str:
    """``mean ± half-width`` of a level cell's 95 % interval."""
    if not math.isfinite(cv.effect):
        return "—"
    return f"{_num(cv.effect)} ± {_num((cv.ci[1] - cv.ci[0]) / 2, 2)}"


def _verdict(cv: CellVerdict) -> str:
    text = cv.verdict if cv.verdict != "n/a" else f"n/a: {cv.reason}"
    if cv.verdict == NOT_SHOWN:
        text += f" (n ≈ {cv.seeds})" if cv.seeds else " (no size to power)"
    return text


def _bold(verdict: str) -> str:
    return verdict if verdict == HOLDS else f"**{verdict}**"


def _effect(cv: CellVerdict) -> str:
    """``cell: +12.3 % [+5.0, +20.1], p = 0.01, verdict``."""
    if not math.isfinite(cv.effect):
        return f"{cv.cell}: {_verdict(cv)}"
    return (f"{cv.cell}: {cv.effect:+.1f} % [{cv.ci[0]:+.1f}, {cv.ci[1]:+.1f}], p = {fmt_p(cv.p_adj)}, "
            f"{_verdict(cv)}")


def common_fields(pairs: Sequence[Mapping[str, Any]]) -> dict[str, Any]:
    """The fields every one of a sweep's plans shares (``experiment``), by which reference runs are
    matched to it."""
    if not pairs:
        return {}
    out = dict(pairs[0])
    for p in pairs[1:]:
        out = {k: v for k, v in out.items() if p.get(k) == v}
    return out


@dataclass(frozen=True)
class Judged:
    """One paper's claims on one robot model."""

    verdicts: list[Verdict]
    """Against the paper (one Holm family)."""
    levels: dict = field(default_factory=dict)
    """(claim id, cell) -> our level cell against the authors' code's runs (`evaluate_reference`)."""
    relations: dict = field(default_factory=dict)
    """claim id -> (the authors' code against the paper, ours against the authors' code)
    (`evaluate_reference_relations`)."""


def judged(by_model: Mapping[str, Sequence[Any]], out: Path) -> dict[str, dict[str, Judged]]:
    """comparison -> model -> its claims judged (`Judged`). `by_model`: model -> the sweeps of
    ``all`` (each with ``comparison``, ``claims``, ``rows``, ``extra``); one paper's claims on one
    model are judged together (one Holm family), and again against the authors' code's runs
    (``OUT/reference/<comparison>/``) where there are any."""
    result: dict[str, dict[str, Judged]] = {}
    for model, sweeps in by_model.items():
        names = list(dict.fromkeys(r.comparison.name for r in sweeps))
        for name in names:
            mine = [r for r in sweeps if r.comparison.name == name]
            claims = [c for r in mine for c in r.claims]
            ids = [c.id for c in claims]
            if len(set(ids)) != len(ids):
                raise ValueError(f"{name}: claim ids repeat: {sorted({i for i in ids if ids.count(i) > 1})}")
            rows = {c.id: r.rows for r in mine for c in r.claims}
            if not claims:  # a comparison that declares none has nothing to judge
                continue
            reference = load_reference(out, name)
            if reference is None:
                result.setdefault(name, {})[model] = Judged(evaluate(claims, rows))
                continue
            theirs = {c.id: matching(reference, r.extra) for r in mine for c in r.claims}
            result.setdefault(name, {})[model] = Judged(
                evaluate(claims, rows),
                {k: v for r in mine if r.claims for k, v in
                 evaluate_reference(r.claims, rows, theirs[r.claims[0].id]).items()},
                {k: v for r in mine if r.claims for k, v in
                 evaluate_reference_relations(r.claims, rows, theirs[r.claims[0].id]).items()})
    return result


def report_verdicts(by_model: Mapping[str, Sequence[Any]], out: Path, titles: Mapping[str, str]) -> list[str]:
    """The markdown lines of REPORT.md's verdicts (`judged`)."""
    models = list(by_model)
    title = {m: titles.get(m, m) for m in models}
    papers = judged(by_model, out)
    helps = {r.comparison.name: r.comparison.help for m in models for r in by_model[m]}
    rules = {r.comparison.name: r.comparison.rules for m in models for r in by_model[m]}
    lines = ["## Verdicts", "",
             "Every number and stated relation of each paper's results is a claim (`claims.py` in its package): a "
             "*level* (a table cell or a number in the text), a *relation* (B against A, with the paper's size) or a "
             "*trend* (one strategy from its first to its last cell). One scale for all "
             "(`swarm_sim.compare.verdicts`): *holds*: the direction is right, the difference significant and its "
             "size within the band; *direction only*: right and significant, the size outside the band; *not "
             "shown*: not significant (n ≈ the runs per group a power calculation says would show the paper's "
             f"effect at our spread, two-sided α = {ALPHA}, power {POWER:.0%}; for a level, the runs that would put "
             "its interval on one side of the band's nearer edge at our mean; none where the paper states no "
             "size); *contradicts*: significant the "
             "other way; *n/a*: too few runs. A level holds when its 95 % interval lies within the band, "
             "contradicts when it lies wholly outside. The band: the paper's stated range, else "
             f"±{LEVEL_BAND:.0%} of its number. One test everywhere: Welch's t, two-sided (one-sample against a "
             "level's band), every p-value of a paper on a robot model Holm-corrected together; effects with 95 % "
             f"intervals (a level's from t, a relation's by a seeded bootstrap of {BOOTSTRAP} resamples). The "
             "intervals shown are the plain 95 % ones; the verdicts use the Holm-corrected p, so an interval just "
             "clear of a band can still read *not shown*. A claim over several cells takes its worst cell.", ""]
    header = ["paper", "robot model", *VERDICTS, "claims"]
    body, totals = [], {m: dict.fromkeys(VERDICTS, 0) for m in models}
    for name, per in papers.items():
        for m in models:
            if m not in per:
                continue
            c = counts(per[m].verdicts)
            for k, v in c.items():
                totals[m][k] += v
            body.append([name, title[m], *(str(c[v]) for v in VERDICTS), str(sum(c.values()))])
    for m in models:
        body.append(["**all**", title[m], *(f"**{totals[m][v]}**" for v in VERDICTS), f"**{sum(totals[m].values())}**"])
    lines += md_table(header, body) + [""]
    for m in models:
        levels = [cv for per in papers.values() if m in per for v in per[m].verdicts if v.claim.kind == LEVEL
                  for cv in v.cells]
        within = sum(1 for cv in levels if math.isfinite(cv.effect) and cv.reason == "inside")
        lines.append(f"{title[m]}: {totals[m][HOLDS]} of {sum(totals[m].values())} claims hold; level cells whose "
                     f"mean lies within the band: {within} of {len(levels)} (holding: "
                     f"{sum(1 for cv in levels if cv.verdict == HOLDS)}).")
        lines.append("")
    lines += _against_code(papers, models, title)
    lines += _levels(papers, models, title, helps)
    lines += _relations(papers, models, title)
    lines += _causes(papers, models, title)
    lines += _rules(rules)
    return lines


def _against_code(papers: Mapping, models: list[str], title: Mapping[str, str]) -> list[str]:
    """The counts of the second judgement, for the papers whose authors' code was run here
    (`swarm_sim.compare.reference`): ours against those runs, level cells and relations, and the
    authors' code against its own paper's relations."""
    body = []
    for name, per in papers.items():
        for m in models:
            if m not in per or not (per[m].levels or per[m].relations):
                continue
            levels = counts_of(cv.verdict for cv in per[m].levels.values())
            ours = counts_of(v.verdict for _, v in per[m].relations.values())
            theirs = counts_of(v.verdict for v, _ in per[m].relations.values())
            body.append([name, title[m], _tally(levels), _tally(ours), _tally(theirs)])
    if not body:
        return []
    return ["### Against the authors' code run here", "",
            "Where a paper's published code was built and run on this machine (`reference/`, "
            "`results/reference/`), ours is judged against its runs as well as against the paper, on the same "
            "scale: a level cell holds when our mean is within ±25 % of theirs (the interval within); a relation "
            "when ours shows the size and direction theirs shows. The last column judges the authors' code's "
            "runs against their own paper's relations.", "",
            *md_table(["paper", "robot model", "level cells: ours vs authors' code",
                       "relations: ours vs authors' code", f"relations: {REFERENCE_LABEL} vs the paper"], body), ""]


def counts_of(verdicts: Iterable[str]) -> dict[str, int]:
    out = dict.fromkeys(VERDICTS, 0)
    for v in verdicts:
        out[v] += 1
    return out


def _tally(c: Mapping[str, int]) -> str:
    """``3 holds, 1 not shown of 4`` (the classes present)."""
    return ", ".join(f"{n} {v}" for v, n in c.items() if n) + f" of {sum(c.values())}" if sum(c.values()) else "—"


def _levels(papers: Mapping, models: list[str], title: Mapping[str, str], helps: Mapping[str, str]) -> list[str]:
    lines = ["## Levels: every number the papers print", "",
             "`paper`: the paper's number (the band ±25 % unless the claim says); `ours`: mean ± the half-width of "
             "its 95 % interval (n runs); `ratio`: ours / paper.", ""]
    for name, per in papers.items():
        lines += [f"### {name}: {helps.get(name, '')}", ""]
        for m in models:
            cells = [cv for v in (per[m].verdicts if m in per else []) if v.claim.kind == LEVEL for cv in v.cells]
            lines.append(f"- {title[m]}: mean within the band in {sum(cv.reason == 'inside' for cv in cells)} of "
                         f"{len(cells)} cells, holding (the interval within) in "
                         f"{sum(cv.verdict == HOLDS for cv in cells)}.")
        lines.append("")
        ref = any(per[m].levels for m in models if m in per)
        header = ["claim", "where", "paper"]
        for m in models:
            header += [f"ours ({title[m]})", "n", "ratio", f"verdict ({title[m]})"]
            if ref:
                header += [f"{REFERENCE_LABEL} ({title[m]})", "ours vs authors' code"]
        first = per[models[0]].verdicts if models[0] in per else []
        body = []
        for i, v in enumerate(first):
            if v.claim.kind != LEVEL:
                continue
            for j, cv in enumerate(v.cells):
                cell = "" if len(v.cells) == 1 else f" ({cv.cell})"
                row = [f"`{v.claim.id}`{cell}: {v.claim.text}" + (f" ({v.claim.note})" if v.claim.note else ""),
                       v.claim.where, v.claim.paper_text()]
                for m in models:
                    if m not in per:
                        row += ["—"] * (6 if ref else 4)
                        continue
                    mine = per[m].verdicts[i].cells[j]
                    ratio = mine.effect / mine.means[1] if mine.means[1] and math.isfinite(mine.effect) else math.nan
                    row += [_ci(mine), str(mine.n[0]), _num(ratio, 2), _bold(_verdict(mine))]
                    if ref:
                        against = per[m].levels.get((v.claim.id, cv.cell))
                        row += _against(against)
                body.append(row)
        lines += md_table(header, body) + [""]
    return lines


def _against(cv: CellVerdict | None) -> list[str]:
    """The authors' code's cell and ours against it: its mean (n), our difference in % of it with
    its interval and the verdict; a cell without enough runs for a test says only that."""
    if cv is None:
        return ["—", "—"]
    mean = f"{_num(cv.means[1])} (n={cv.n[1]})"
    if not math.isfinite(cv.effect):
        return [mean, _verdict(cv)]
    return [mean, f"{cv.effect:+.1f} % [{cv.ci[0]:+.1f}, {cv.ci[1]:+.1f}]: {_verdict(cv)}"]


def _theirs(per: Mapping, models: list[str], claim_id: str) -> Verdict | None:
    """The authors' code's runs judged against the paper on one relation or trend (`Judged.relations`),
    None where they were not run or do not cover it."""
    return next((per[m].relations[claim_id][0] for m in models if m in per and claim_id in per[m].relations), None)


def _relations(papers: Mapping, models: list[str], title: Mapping[str, str]) -> list[str]:
    intro = ("Each cell: B against A in % of A [95 % bootstrap interval], the Holm-corrected p, the cell's verdict; "
             "a trend's cell is its first → last.")
    if any(per[m].relations for per in papers.values() for m in per):
        intro += (" Where the authors' code was run here, its runs are judged against the paper "
                  f"(*{REFERENCE_LABEL}*) and ours against its runs (*ours vs authors' code*: the size and direction "
                  "their runs show take the paper's place; where their difference is not significant, \"no "
                  "difference\"), in the cells their runs cover; where their controller counts the measure its own "
                  "way (a collision rule), both sides are judged on their count.")
    lines = ["## Relations and trends", "", intro, ""]
    for name, per in papers.items():
        lines += [f"### {name}", ""]
        ref = any(per[m].relations for m in models if m in per)
        header = ["claim", "where", "kind", "paper"] + ([REFERENCE_LABEL] if ref else [])
        for m in models:
            header += [f"ours ({title[m]})", f"verdict ({title[m]})"]
            header += [f"ours vs authors' code ({title[m]})"] if ref else []
        first = per[models[0]].verdicts if models[0] in per else []
        body = []
        for i, v in enumerate(first):
            if v.claim.kind == LEVEL:
                continue
            c = v.claim
            who = f"{c.b} vs {c.a}" if c.b else c.a
            row = [f"`{c.id}`: {c.text} ({who})", c.where, c.kind, c.paper_text()]
            if ref:
                theirs = _theirs(per, models, c.id)
                counted = f"(their count, `{c.code_measure}`) " if c.code_measure else ""
                row.append(counted + _cells(theirs) if theirs else "—")
            for m in models:
                if m not in per:
                    row += ["—"] * (3 if ref else 2)
                    continue
                mine = per[m].verdicts[i]
                row += ["; ".join(_effect(cv) for cv in mine.cells), _bold(mine.verdict)]
                if ref:
                    against = per[m].relations.get(c.id)
                    row.append(_cells(against[1], brief=True) if against else "—")
            body.append(row)
        lines += md_table(header, body) + [""]
    return lines


def _cells(v: Verdict, brief: bool = False) -> str:
    """A verdict's cells and then the claim's verdict, in one table cell; `brief`: each cell's
    verdict only (its effect stands in another column)."""
    return "; ".join(f"{cv.cell}: {_verdict(cv)}" if brief else _effect(cv) for cv in v.cells) + \
        f" → {_bold(v.verdict)}"


def _causes(papers: Mapping, models: list[str], title: Mapping[str, str]) -> list[str]:
    lines = ["## Causes of the claims that do not hold", "",
             "Each claim that does not hold on a robot model, with its cause and the cause's grade: "
             f"*{GRADES['measured']}* (that factor alone switched, at least 10 seeds, the gap closes by half or the "
             f"verdict flips; numbers in FACTORS.md), *{GRADES['code']}* (the authors' own code, run here, at least "
             "10 runs a cell, misses it too: checked against its runs' verdict), "
             f"*{GRADES['partial']}* (a factor sweep points to it, with fewer "
             f"seeds or without closing the gap), *{GRADES['open']}* (not measured; what the text says is a lead, "
             "not a cause). The evidence is in CAUSES.md below.", ""]
    if any(per[m].relations for per in papers.values() for m in per):
        lines[-2] += (f" Where the authors' code was run here, *{REFERENCE_LABEL}* is its runs' verdict against the "
                      "paper on the same relation or trend: a claim their own code misses too is a gap between the "
                      "paper and its code.")
    for name, per in papers.items():
        body, grades = [], {}
        ref = any(per[m].relations for m in models if m in per)
        first = per[models[0]].verdicts if models[0] in per else []
        for i, v in enumerate(first):
            mine = {m: per[m].verdicts[i] for m in models if m in per}
            failing = [m for m, x in mine.items() if x.verdict != HOLDS]
            if not failing:
                continue
            causes = {m: v.claim.cause(m) for m in failing}
            judged_theirs = _theirs(per, models, v.claim.id)
            theirs = judged_theirs.verdict if judged_theirs else "—"
            if any(c is not None and c.grade == CODE for c in causes.values()) and theirs == HOLDS:
                raise ValueError(f"{name}: claim {v.claim.id}: its cause says the authors' code misses it too, "
                                 f"but their runs' verdict is {theirs}")
            for m, cause in causes.items():
                grade = cause.grade if cause else OPEN
                grades[(m, grade)] = grades.get((m, grade), 0) + 1
            texts = {}
            for m, cause in causes.items():  # one line per distinct cause, naming its models
                key = (cause.grade, cause.text) if cause else (OPEN, "no cause named")
                texts.setdefault(key, []).append(title[m])
            cause_text = "<br>".join((f"{', '.join(who)}: " if len(texts) > 1 else "") + f"*{GRADES[g]}*: {t}"
                                     for (g, t), who in texts.items())
            body.append([f"`{v.claim.id}`", *(mine[m].verdict if m in mine else "—" for m in models),
                         *([theirs] if ref else []), cause_text])
        if not body:
            continue
        summary = "; ".join(f"{title[m]}: " + ", ".join(f"{grades.get((m, g), 0)} {GRADES[g]}" for g in GRADES)
                            for m in models)
        lines += [f"### {name}", "", f"Claims not holding, by the grade of their cause: {summary}.", ""]
        lines += md_table(["claim", *(f"verdict ({title[m]})" for m in models), *([REFERENCE_LABEL] if ref else []),
                           "cause (grade)"], body) + [""]
    return lines


def _rules(rules: Mapping[str, Sequence[Any]]) -> list[str]:
    body = [[name, r.scenarios, f"`{r.key}`", r.text, r.code, f"**{r.shipped}**", r.note]
            for name, found in rules.items() for r in found]
    lines = ["## Text vs the authors' code", "",
             "Where a paper's text and its authors' published code disagree (or the text is silent and the code "
             "decides), the rule each shipped scenario follows and the key that switches it.", ""]
    if not body:
        return lines + ["No comparison declares one.", ""]
    return lines + md_table(["paper", "scenarios", "key", "the text", "the authors' code", "shipped follows", "note"],
                            body) + [""]
