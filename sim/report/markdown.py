"""``results/REPORT.md`` built from the Parquet files alone.

The report is a pure function of the result directories: it reads each study's
``claims.parquet`` (and whatever else the study's own ``report`` hook reads) and returns
Markdown. Nothing here runs a simulation.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Callable

import pyarrow as pa

from sim.mc.config import ConfigError
from sim.mc.storage import atomic_path, read_provenance, read_table
from sim.report.sweep import sweep_markdown
from sim.report.tables import fmt, md_table
from sim.report.verify import markdown as reproducibility_markdown

__all__ = [
    "build_report",
    "claims_markdown",
    "fmt",
    "md_table",
    "inputs_markdown",
    "number",
    "consistent_rows",
    "consistent_sets_sentence",
    "verdict_counts",
    "referee_summary",
]


_VERDICT_TEXT = {
    "holds": "holds",
    "fails": "**fails**",
    "inconclusive": "inconclusive",
    "depends": "depends",
    "undecidable": "undecidable",
    "erratum": "**erratum**",
    "input": "input",
    "self-check": "self-check",
    "finding": "finding",
    "not comparable": "not comparable",
}


def _ref_text(r) -> str:
    """The paper's reference as the decision zone it stands for."""
    lo, hi = r.get("zone_low"), r.get("zone_high")
    none = lambda x: x is None or (isinstance(x, float) and not math.isfinite(x))  # noqa: E731
    if none(lo) and none(hi):
        return ""
    f = (lambda x: f"{x:.10g}") if r["interval"] == "exact" else (lambda x: fmt(x, 4))  # noqa: E731
    form = r.get("form") or ""
    if form == "upper" or none(lo):
        return f"≤ {f(hi)}"
    if form == "lower" or none(hi):
        return f"≥ {f(lo)}"
    return f(lo) if lo == hi else f"{f(lo)}–{f(hi)}"


def _sim_text(r) -> str:
    val = f"{r['value']:.10g}" if r["interval"] == "exact" else fmt(r["value"])
    vh = r.get("value_high")
    if vh is not None and math.isfinite(vh):
        val += f"–{fmt(vh)}"
    return val


def _interval_text(r) -> str:
    if r["interval"] == "exact":
        return "exact"
    out = f"[{fmt(r['ci_low'])}, {fmt(r['ci_high'])}]" + (
        " plates" if r["interval"] == "spread" else ""
    )
    p = r.get("p_plate")
    if p is not None and math.isfinite(p):
        out += f", p = {fmt(p, 2)}"
    return out


def number(x):
    """A table cell as a number, or None where it is missing or NaN."""
    return None if x is None or (isinstance(x, float) and math.isnan(x)) else x


def consistent_rows(cons: dict) -> list[list]:
    """Rows ``[input, claim, kind, where it holds]`` of a ``consistent_set.parquet`` table
    (one-input sweeps: the range of values where each claim, and all together, hold)."""
    rows = []
    for i, c in enumerate(cons["claim"]):
        lo, hi = number(cons["holds_low"][i]), number(cons["holds_high"][i])
        where = "nowhere" if lo is None else f"{fmt(lo)} - {fmt(hi)}"
        if lo is not None and cons["n_holds"][i] != cons["n_values"][i]:
            where += f" ({cons['n_holds'][i]} of {cons['n_values'][i]} values)"
        rows.append(
            [cons["input"][i], "**all claims**" if c == "ALL" else f"`{c}`", cons["kind"][i], where]
        )
    return rows


def consistent_sets_sentence(cons: dict) -> str:
    """'Consistent sets: ...' -- per swept input, the values where all claims hold together
    (the ``ALL`` rows of a ``consistent_set.parquet`` table), or that they conflict."""
    parts = []
    for i, c in enumerate(cons["claim"]):
        if c != "ALL":
            continue
        lo, hi = number(cons["holds_low"][i]), number(cons["holds_high"][i])
        parts.append(
            f"`{cons['input'][i]}` "
            + ("none: the claims conflict" if lo is None else f"{fmt(lo)} - {fmt(hi)}")
        )
    return "Consistent sets: " + "; ".join(parts) + "."


def claims_markdown(path: Path) -> str:
    """The claims table of one study as Markdown, and its *not reproduced* list if any.

    Columns: the paper's words, the claim's form, the decision zone its printed number stands
    for (rounding widened by the claim's tolerance), the simulated value, its 95 % interval
    (``plates``: the spread of a one-plate statistic, with ``p`` the probability of a plate at
    least as extreme as the paper's), the verdict and its kind."""
    t = read_table(path).to_pylist()
    rows = []
    for r in t:
        if r["verdict"] == "not comparable":
            sim, ci = "", ""
        else:
            sim, ci = _sim_text(r), _interval_text(r)
        verdict = _VERDICT_TEXT.get(r["verdict"], r["verdict"])
        if r["kind"] in ("input", "self-check") and r.get("outcome"):
            verdict += f" ({r['outcome']})"
        rows.append(
            [
                f"`{r['claim']}`",
                r["paper"],
                r.get("form") or "",
                _ref_text(r),
                sim,
                ci,
                verdict,
                r["note"],
            ]
        )
    out = md_table(
        [
            "claim",
            "paper says",
            "form",
            "decision zone",
            "simulated",
            "95% interval",
            "verdict",
            "note",
        ],
        rows,
    )
    nr = Path(path).with_name("not_reproduced.parquet")
    if nr.is_file():
        n = read_table(nr).to_pylist()
        if n:
            out += "\n\nPrinted numbers not reproduced:\n\n" + md_table(
                ["source", "printed", "why not"], [[x["source"], x["printed"], x["why"]] for x in n]
            )
    return out


def verdict_counts(claims: list[dict]) -> dict[str, int]:
    """Counts per class: predictions by verdict, errata, inputs, self-checks (and how many of
    them failed their own rule), findings, not comparable."""
    c = {
        k: 0
        for k in (
            "holds",
            "fails",
            "inconclusive",
            "depends",
            "undecidable",
            "erratum",
            "paper ok",
            "input",
            "self-check",
            "self-check failed",
            "finding",
            "not comparable",
        )
    }
    for r in claims:
        v, k = r["verdict"], r["kind"]
        if k == "prediction":
            c[
                v
                if v in ("holds", "fails", "inconclusive", "depends", "undecidable")
                else "finding"
            ] += 1
        elif k == "paper-check":
            c["erratum" if v == "erratum" else "paper ok"] += 1
        elif k == "self-check":
            c["self-check"] += 1
            c["self-check failed"] += r.get("outcome") == "fails"
        else:
            c[k] += 1
    return c


def inputs_markdown(cfg: dict, schema) -> str:
    """List the config values marked as paper-matched inputs."""
    rows = [[f"`{k}`", fmt(cfg.get(k)), f.doc] for k, f in schema.items() if f.input]
    if not rows:
        return ""
    return (
        "Inputs set to match the paper (agreement with these is by construction, not a "
        "prediction):\n\n" + md_table(["key", "value", "meaning"], rows)
    )


_COUNT_COLS = [
    ("holds", "holds"),
    ("fails", "fails"),
    ("inconclusive", "inconclusive"),
    ("depends", "depends"),
    ("undecidable", "undecidable"),
    ("not comparable", "not comparable"),
    ("erratum", "errata"),
    ("paper ok", "paper consistent"),
    ("input", "inputs"),
    ("self-check", "self-checks"),
    ("finding", "findings"),
]


def referee_summary(entries: list[tuple]) -> str:
    """Per paper: the headline claims with their verdicts, then counts per verdict class."""
    by_seed: dict[str, list] = {}
    for _, name, study, claims, _ in entries:
        if not study.seed_file:  # a user's network: no paper to referee
            continue
        by_seed.setdefault(study.seed_file, []).append((name, study, claims))
    parts = [
        "## Referee's summary\n",
        "Each claim is decided by its stated rule (see *How verdicts are decided* below). "
        "Predictions are counted apart from inputs (set to match the paper), self-checks "
        "(Monte Carlo against analytic, coverage, posterior against least squares), paper "
        "checks (the paper's printed numbers recomputed from its own printed data: a "
        "disagreement is an *erratum*) and findings (no paper number).\n",
    ]
    for seed in sorted(by_seed):
        rows = []
        for name, study, claims in by_seed[seed]:
            for r in claims:
                if r.get("headline"):
                    rows.append(
                        [
                            f"[`{r['claim']}`](#{name})",
                            r["paper"],
                            _ref_text(r),
                            "" if r["verdict"] == "not comparable" else _sim_text(r),
                            "" if r["verdict"] == "not comparable" else _interval_text(r),
                            _VERDICT_TEXT.get(r["verdict"], r["verdict"]),
                        ]
                    )
        titles = "; ".join(study.title for _, study, _ in by_seed[seed])
        parts.append(f"**`{seed}`** ({titles})\n")
        parts.append(
            md_table(
                [
                    "headline claim",
                    "paper says",
                    "decision zone",
                    "simulated",
                    "95% interval",
                    "verdict",
                ],
                rows,
            )
            if rows
            else "_no headline claim declared_"
        )
        parts.append("")
    return "\n".join(parts)


def _claims_of(d: Path, get_study: Callable):
    """``(study, provenance, claim rows)`` of a results directory, or one line naming the file
    when its ``claims.parquet`` is not a claims table written by the suite."""
    f = d / "claims.parquet"
    try:
        prov = read_provenance(f) or {}
        claims = read_table(f).to_pylist()
    except (OSError, ValueError, pa.ArrowException) as e:
        raise ConfigError("--results", f"{f} cannot be read: {str(e).splitlines()[0]}") from None
    if "study" not in prov or (claims and not {"claim", "verdict"} <= set(claims[0])):
        raise ConfigError("--results", f"{f} is not a claims table written by sim")
    return get_study(prov["study"]), prov, claims


def build_report(results: Path, get_study: Callable) -> str:
    """The report of every results directory under ``results``; ``get_study(name)`` gives the
    registered study (its title, seed file, order and ``report`` section)."""
    results = Path(results)
    if not results.is_dir():
        raise ConfigError("--results", f"{results} is not a results directory")
    sections = []
    entries = []
    for d in sorted(p for p in results.iterdir() if (p / "claims.parquet").is_file()):
        study, prov, claims = _claims_of(d, get_study)
        c = verdict_counts(claims)
        nr = d / "not_reproduced.parquet"
        n_nr = read_table(nr).num_rows if nr.is_file() else 0
        row = [f"[{study.title}](#{d.name})", f"`{study.seed_file}`" if study.seed_file else "—"]
        row += [c[k] for k, _ in _COUNT_COLS]
        if c["self-check failed"]:
            row[2 + [k for k, _ in _COUNT_COLS].index("self-check")] = (
                f"{c['self-check']} ({c['self-check failed']} failed)"
            )
        row += [n_nr, prov.get("git_commit", "")[:12]]
        entries.append((study.order, d.name, study, claims, row))
        body = study.report(d)
        sections.append(
            (
                study.order,
                d.name,
                f'<a id="{d.name}"></a>\n\n## {study.title}\n\nStudy `{d.name}` '
                + (
                    f"(seed paper `{study.seed_file}`)"
                    if study.seed_file
                    else "(a declared network, no seed paper)"
                )
                + f", results in `{d.name}/`.\n\n{body}\n",
            )
        )
    for d in sorted(
        p
        for p in results.iterdir()
        if (p / "sweep.parquet").is_file() and not (p / "claims.parquet").is_file()
    ):
        prov = read_provenance(d / "sweep.parquet")
        study = get_study(prov["study"])
        sections.append(
            (
                study.order + 1,
                d.name,
                f'<a id="{d.name}"></a>\n\n## Sweep: {study.title}\n\nSweep `{d.name}` over '
                f"study `{prov['study']}`, results in `{d.name}/`.\n\n"
                f"{sweep_markdown(d, d.name)}\n",
            )
        )
    entries.sort(key=lambda e: (e[0], e[1]))
    sections.sort()
    head = (
        "# Reproducibility report\n\n"
        "Every number below was produced by a run of the code (`make reproduce`); paper values "
        "appear only as the reference of a claim. This file is rebuilt from the Parquet files "
        "alone by `sim report`.\n\n"
    )
    rules = (
        "### How verdicts are decided\n\n"
        "Each claim declares its *form* and the half-width that decides (`tol`); the *decision "
        "zone* is the interval the paper's printed number stands for (its rounding) widened by "
        "that tolerance. For a value, share, count or bound the claim **holds** when the 95 % "
        "interval of the simulated value lies inside the zone, **fails** when the two do not "
        "meet, and is **inconclusive** otherwise (the interval covers both agreeing and "
        'contradicting values). A *range* ("from 5 to 15 %") holds when every element\'s '
        "interval lies inside it and fails when some element's interval lies wholly outside. "
        "A *one-plate* statistic (the paper's one plate) fails when fewer than 5 % of "
        "simulated plates are at least as extreme (`p < 0.05`) and holds when, besides, the "
        "central 95 % of simulated plates lies inside the zone. A paper check whose "
        "recomputation from the paper's own printed data fails is an **erratum**.\n\n"
    )
    table = md_table(
        ["study", "seed"] + [t for _, t in _COUNT_COLS] + ["not reproduced", "code commit"],
        [e[4] for e in entries],
    )
    summary = referee_summary(entries)
    repro = reproducibility_markdown(results)
    repro = "\n" + repro if repro else ""
    return (
        head
        + summary
        + "\n### Counts per study\n\n"
        + table
        + "\n\n"
        + rules
        + repro
        + "\n"
        + "\n".join(s[2] for s in sections)
    )


#: the first line of every REPORT.md the suite writes: a file without it is the user's
MARK = "<!-- written by `sim report` from the Parquet files alone; edits are overwritten -->"


def _ours(path: Path) -> bool:
    """True for a REPORT.md the suite wrote (its mark, or the heading the reports had before)."""
    try:
        with open(path, encoding="utf-8", errors="replace") as f:
            first = f.readline().rstrip("\n")
    except OSError:
        return False
    return first in (MARK, "# Reproducibility report")


def write_report(results: Path, get_study: Callable) -> Path:
    """Write ``results/REPORT.md``; a REPORT.md there that the suite did not write is refused
    (one line naming it), never replaced."""
    out = Path(results) / "REPORT.md"
    if out.is_symlink() or (out.exists() and not _ours(out)):
        raise ConfigError(
            "--results", f"{out} was not written by sim report; sim never replaces it"
        )
    text = MARK + "\n" + build_report(results, get_study)
    with atomic_path(out) as tmp:
        tmp.write_text(text)
    return out
