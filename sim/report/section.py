"""The skeleton of a study's report section, read from its Parquet files alone.

Every study's section of ``REPORT.md`` has the same shape, in this order:

1. the *lead*: for the studies that decide claims over the unprinted inputs, the consistent
   region sentence, its table and the verdicts over it (:func:`region_lead`, part by part for
   a region explored per part);
2. the *intro*: the study's own paragraphs (model, geometry, trials, seed);
3. the claims table and the printed numbers not reproduced
   (:func:`sim.report.markdown.claims_markdown` of ``claims.parquet``);
4. the inputs set to match the paper (the schema's ``input`` keys, values from the
   provenance's config);
5. the *body*: the study's particular tables and subsections;
6. the figures, one ``![alt](<dir>/<file>)`` line each.

A study's ``report(out)`` hook builds only what is particular to it (intro, body, figures)
and calls :func:`section`, which joins the non-empty blocks with blank lines. Numbers come only
from the files under ``out`` (:func:`table`, :func:`rows`, :func:`config`), never from live
model code.

Every study's report is built this way: ``section(out, lead=[...], intro=[...],
schema=SCHEMA, body=[...], figures=[(alt, file), ...])``. A study decided over the region of its
unprinted inputs (:mod:`sim.claims.inference`) leads with ``region_lead(out, what,
values=how)``, ``how`` saying how the values at an input vector were obtained (analytic, or
simulated draws whose noise enters the decision); subsections with their own figures go into ``body``
(with :func:`figure`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from sim.claims.region import REGION_MIN_POINTS
from sim.mc.file_kind import odd_file
from sim.mc.publish import drawn
from sim.mc.storage import read_provenance, read_record
from sim.report.inputs import inputs_markdown
from sim.report.markdown import claims_markdown
from sim.report.read import columns, records
from sim.report.tables import fmt, md_table

__all__ = [
    "config",
    "errata",
    "figure",
    "printed",
    "recomputed",
    "region_lead",
    "region_verdicts",
    "rows",
    "section",
    "span",
    "table",
]


def table(out: Path, name: str) -> dict[str, list]:
    """The columns of ``out/name`` (a Parquet table the study wrote); a missing file or
    column raises :class:`sim.report.read.TableError` naming it."""
    return columns(Path(out) / name)


def rows(out: Path, name: str) -> list[dict[str, Any]]:
    """The rows of ``out/name`` (a Parquet table the study wrote); a missing file or column
    raises :class:`sim.report.read.TableError` naming it."""
    return records(Path(out) / name)


def config(out: Path) -> dict[str, Any]:
    """The provenance of the study's ``claims.parquet`` (its ``config`` and the run's facts)."""
    return read_provenance(Path(out) / "claims.parquet")


def figure(out: Path, file: str, alt: str) -> str:
    """The Markdown line of one figure of the study, relative to the report; a line saying
    so when the run drew no figures (``sim run --no-figures``)."""
    if (odd := odd_file(Path(out) / file)) is not None:  # a FIFO: not "removed since?"
        return f"*{alt}: not shown (`{file}` is {odd}, not the figure its run drew)*"
    if not (Path(out) / file).is_file():
        drew = (read_record(Path(out)) or {}).get("figure_sha256")  # the run drew it: not
        if isinstance(drew, dict) and file in drew:  # "a run with --no-figures?" of its run
            return f"*{alt}: not shown (`{file}` is missing: its run drew it; removed since?)*"
        return f"*{alt}: not drawn (`{file}` is missing: a run with `--no-figures`?)*"
    if not drawn(Path(out), file):  # put there by hand: not the run's figure
        return f"*{alt}: not drawn by this run (`{file}` is not the figure its run.json records)*"
    return f"![{alt}]({Path(out).name}/{file})"


def span(lo, hi, unit: str = "") -> str:
    """``lo–hi`` (or one value when they are equal), ``nowhere`` when missing or NaN."""
    if lo is None or (isinstance(lo, float) and math.isnan(lo)):
        return "nowhere"
    return (f"{fmt(lo)}" if lo == hi else f"{fmt(lo)}–{fmt(hi)}") + unit


def _digits(r: dict) -> int | None:
    """Decimals of the paper's printed number of a claims row (from the width of its rounding
    zone ``ref_low``-``ref_high``), or None when the zone has no width."""
    width = r["ref_high"] - r["ref_low"]
    return max(0, -math.floor(math.log10(width) + 1e-9)) if width > 0 else None


def printed(r: dict) -> str:
    """The paper's printed number of a claims row: the middle of its rounding zone, at the
    decimals it was printed with."""
    mid, d = (r["ref_low"] + r["ref_high"]) / 2, _digits(r)
    return fmt(mid) if d is None else f"{mid:.{d}f}"


def recomputed(r: dict) -> str:
    """The row's recomputed value, one decimal beyond the printed number's."""
    d = _digits(r)
    return fmt(r["value"]) if d is None else f"{r['value']:.{d + 1}f}"


def errata(claims: Sequence[dict]) -> str:
    """The paragraph of the paper-checks the paper's own printed data contradict: per
    erratum, the printed and the recomputed number and the row's note (``none`` without)."""
    return (
        "**Errata** (the paper against its own printed data): "
        + (
            "; ".join(
                f"`{r['claim']}`: printed {printed(r)}, recomputed {recomputed(r)} "
                f"({r['note'].rstrip('.')})"
                for r in claims
                if r["verdict"] == "erratum"
            )
            or "none"
        )
        + "."
    )


def region_verdicts(out: Path) -> list[str]:
    """One line per claim decided over the region: verdict and where it holds."""
    return [
        f"- `{r['claim']}`{' (headline)' if r['headline'] else ''}: **{r['verdict']}** — "
        f"{r['note']}"
        for r in rows(out, "claims.parquet")
        if r["interval"] == "region"
    ]


#: the joint exploration most studies run (:func:`sim.claims.inference.explore` with rounds)
REFINED = "a Sobol design plus refinement at the boundaries"


def _region_how(design: str, values: str) -> str:
    return (
        f"The unprinted inputs are explored jointly (`sim.claims.inference`: {design}; "
        f"{values}). The region holds the input "
        "vectors that the hardware and the printed inputs allow; a prediction *holds* or "
        f"*fails* over all of it (at {REGION_MIN_POINTS} or more of its points, else "
        "*inconclusive*), else "
        "*depends* (holds in one part, fails in another; where "
        "is given), *holds or undecided* / *fails or undecided* (one side nowhere) or "
        "*undecidable* "
        "(`consistent_region.parquet`, `region_inputs.parquet`)."
    )


def _together(ins: list[dict]) -> str:
    """Where every prediction holds together over the region rows ``ins`` (one exploration)."""
    r0 = ins[0]
    if not r0["n_together"]:
        return (
            f"hold together for no input of the region "
            f"({r0['n_region']} input vectors of {r0['n_points']} explored)"
        )
    imp = ", ".join(
        f"{r['input']} {span(r['together_low'], r['together_high'])}"
        for r in ins
        if r["declared_low"] != r["declared_high"]
    )
    return (
        f"hold together for {imp} "
        f"({r0['n_together']} of the {r0['n_region']} input vectors of the region; "
        f"{r0['n_points']} explored)"
    )


def _region_sentence(ins: list[dict], what: str) -> str:
    parts = list(dict.fromkeys(r.get("part") for r in ins))
    if parts == [None]:
        return f"**Consistent region.** {what} {_together(ins)}."
    return (
        f"**Consistent region.** {what}, explored per part: "
        + "; ".join(
            f"in part `{p}` they {_together([r for r in ins if r['part'] == p])}" for p in parts
        )
        + "."
    )


def region_lead(out: Path, what: str, *, values: str, design: str = REFINED) -> str:
    """The lead of a study decided over a region of unprinted inputs: where ``what`` (the
    predictions, in words) hold together, how the input vectors were chosen (``design``)
    and how the values at one were obtained (``values``, e.g. ``"every value analytic"`` or
    the simulated draws per vector whose noise enters the decision), the region per input,
    and the verdicts over it (``region_inputs.parquet``, ``claims.parquet``). A region
    explored per part (a ``part`` column) is given part by part."""
    ins = rows(out, "region_inputs.parquet")
    by_part = "part" in ins[0]
    table_rows = [
        [
            *([f"`{r['part']}`"] if by_part else []),
            f"`{r['input']}`",
            f"{fmt(r['declared_low'])}–{fmt(r['declared_high'])}: {r['why']}",
            span(r["region_low"], r["region_high"]),
            span(r["together_low"], r["together_high"]),
            f"{fmt(r['resolution_interior'])} / {fmt(r['resolution_boundary'])}",
        ]
        for r in ins
    ]
    header = [
        *(["part"] if by_part else []),
        "input",
        "possible (hardware)",
        "region",
        "every prediction holds",
        "resolution (interior / boundary)",
    ]
    return "\n".join(
        [
            _region_sentence(ins, what),
            "",
            _region_how(design, values),
            "",
            md_table(header, table_rows),
            "",
            "Verdicts over the region:",
            "",
            *region_verdicts(out),
        ]
    )


def section(
    out: Path,
    *,
    lead: Sequence[str] = (),
    intro: Sequence[str] = (),
    schema: Any = None,
    body: Sequence[str] = (),
    figures: Sequence[tuple[str, str]] = (),
) -> str:
    """A study's report section in the fixed order (lead, intro, claims table with the
    numbers not reproduced, inputs of ``schema``, body, figures ``(alt, file)``); empty
    blocks are left out, the others separated by one blank line."""
    out = Path(out)
    cfg = config(out)["config"]
    blocks = [
        *lead,
        *intro,
        claims_markdown(out / "claims.parquet"),
        inputs_markdown(cfg, schema) if schema is not None else "",
        *body,
        "\n".join(figure(out, f, alt) for alt, f in figures),
    ]
    return "\n\n".join(b for b in blocks if b)
