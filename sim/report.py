"""``results/REPORT.md`` built from the Parquet files alone.

The report is a pure function of the result directories: it reads each study's
``claims.parquet`` (and whatever else the study's own ``report`` hook reads) and returns
Markdown. Nothing here runs a simulation.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from .storage import atomic_path, read_provenance, read_table

__all__ = ["build_report", "claims_markdown", "fmt", "md_table", "inputs_markdown"]


def fmt(x, digits: int = 3) -> str:
    if x is None:
        return ""
    if isinstance(x, (bool, np.bool_)):
        return "yes" if x else "no"
    if isinstance(x, (int, np.integer)):
        return str(int(x))
    if isinstance(x, (float, np.floating)):
        if not math.isfinite(x):
            return ""
        if x == 0:
            return "0"
        mag = math.floor(math.log10(abs(x)))
        dec = max(0, digits - 1 - mag)
        return f"{x:.{min(dec, 9)}f}"
    return str(x)


def md_table(header: list[str], rows: list[list]) -> str:
    esc = lambda s: str(s).replace("|", "\\|").replace("\n", " ")  # noqa: E731
    out = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    out += ["| " + " | ".join(esc(c) for c in r) + " |" for r in rows]
    return "\n".join(out)


def _verdict(h) -> str:
    return {True: "holds", False: "**does not hold**"}.get(h, "no paper number")


def claims_markdown(path: Path) -> str:
    """The claims table of one study as Markdown."""
    t = read_table(path).to_pylist()
    rows = []
    for r in t:
        ref = ""
        if r["ref_low"] is not None and math.isfinite(r["ref_low"]):
            f = (lambda x: f"{x:.10g}") if r["interval"] == "exact" else (lambda x: fmt(x, 4))  # noqa: E731
            ref = (f(r["ref_low"]) if r["ref_low"] == r["ref_high"]
                   else f"{f(r['ref_low'])}–{f(r['ref_high'])}")
        ci = ("exact" if r["interval"] == "exact" else
              f"[{fmt(r['ci_low'])}, {fmt(r['ci_high'])}]" + (" range" if r["interval"] == "spread" else ""))
        val = f"{r['value']:.10g}" if r["interval"] == "exact" else fmt(r["value"])
        rows.append([f"`{r['claim']}`", r["paper"], ref, val, ci, _verdict(r["holds"]),
                     r["kind"], r["note"]])
    return md_table(["claim", "paper says", "paper ref.", "simulated", "95% interval", "verdict",
                     "kind", "note"], rows)


def inputs_markdown(cfg: dict, schema) -> str:
    """List the config values marked as paper-matched inputs."""
    rows = [[f"`{k}`", fmt(cfg.get(k)), f.doc] for k, f in schema.items() if f.input]
    if not rows:
        return ""
    return ("Inputs set to match the paper (agreement with these is by construction, not a "
            "prediction):\n\n" + md_table(["key", "value", "meaning"], rows))


def build_report(results: Path) -> str:
    from .studies import get_study

    results = Path(results)
    sections = []
    summary = []
    for d in sorted(p for p in results.iterdir() if (p / "claims.parquet").is_file()):
        prov = read_provenance(d / "claims.parquet")
        study = get_study(prov["study"])
        claims = read_table(d / "claims.parquet").to_pylist()
        held = sum(r["holds"] is True for r in claims)
        failed = sum(r["holds"] is False for r in claims)
        summary.append((study.order, d.name, [f"[{study.title}](#{d.name})", f"`{study.seed_file}`",
                                              len(claims), held, failed,
                                              prov.get("git_commit", "")[:12]]))
        body = study.report(d)
        sections.append((study.order, d.name,
                         f'<a id="{d.name}"></a>\n\n## {study.title}\n\nStudy `{d.name}` '
                         f"(seed paper `{study.seed_file}`), results in `{d.name}/`.\n\n{body}\n"))
    for d in sorted(p for p in results.iterdir()
                    if (p / "sweep.parquet").is_file() and not (p / "claims.parquet").is_file()):
        from .sweep import sweep_markdown

        prov = read_provenance(d / "sweep.parquet")
        study = get_study(prov["study"])
        sections.append((study.order + 1, d.name,
                         f'<a id="{d.name}"></a>\n\n## Sweep: {study.title}\n\nSweep `{d.name}` over '
                         f"study `{prov['study']}`, results in `{d.name}/`.\n\n"
                         f"{sweep_markdown(d, d.name)}\n"))
    summary.sort()
    sections.sort()
    head = ("# Reproducibility report\n\n"
            "Every number below was produced by a run of the code (`make reproduce`); paper values "
            "appear only in the *paper* columns. A claim *holds* when the 95 % interval of the "
            "simulated value overlaps the interval the paper's printed number stands for "
            "(its rounding). `input` rows are simulation inputs set to match the paper: agreement "
            "there is by construction. This file is rebuilt from the Parquet files alone by "
            "`sim report`.\n\n")
    table = md_table(["study", "seed", "claims", "hold", "do not hold", "code commit"],
                     [s[2] for s in summary])
    return head + table + "\n\n" + "\n".join(s[2] for s in sections)


def write_report(results: Path) -> Path:
    text = build_report(results)
    out = Path(results) / "REPORT.md"
    with atomic_path(out) as tmp:
        tmp.write_text(text)
    return out
