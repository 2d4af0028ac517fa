"""The leads of ``agnard_block``'s report section (seed ``003_5ce730a990a7ebc5.txt``): the
consistent region of the lost five-point layout and the projection-centres option, with the
5-control verdicts over it and the scanner's inputs together
(:func:`sim.report.section.region_lead`, as every study decided over a region), then the
scanner's region under Table 1 (its own table: an empty region
whose conflicting statements make Table 1 not comparable). Read from the study's Parquet
files alone."""

from __future__ import annotations

from pathlib import Path

from sim.report.markdown import fmt, md_table
from sim.report.section import figure, region_lead, rows, table
from sim.studies.agnard.schema import SCHEMA

__all__ = ["five_lead", "scanner_lead", "HOW"]

#: how the 21-control rows' notes begin to say how they were decided (run.py writes it; the
#: scanner lead's table keeps only what precedes it)
HOW = "; decided over the scanner's"


def five_lead(out: Path, cfg: dict) -> list[str]:
    """The five-point layout's region (``consistent_region.parquet``) and its figure; its
    verdict lines only for the rows decided over it together with the scanner's inputs
    (``joint_region.parquet``; the scanner's own rows are in :func:`scanner_lead`)."""
    joint = out / "joint_region.parquet"
    n = len(table(out, "joint_region.parquet")["five_inset_1"]) if joint.is_file() else 0
    lead = region_lead(
        out,
        "The 5-control predictions (Table 3, over the lost five-point layout of its "
        "control points and the program's option of projection centres as model points"
        + (", together with the scanner's unprinted inputs)" if n else ")"),
        values=f"{cfg['region.trials']} simulated blocks per option at the configured "
        "scanner, the same ones adjusted once per layout (common random numbers), whose "
        "noise enters the decision"
        + (
            f"; each prediction is decided over the {n // 2} of {n} joint (layout, scanner) "
            "points with the projection centres (the paper's program, SPACE-M, carries "
            "them), the finding of check Z without them over the other half, the layout's "
            "blocks moved by each scanner vector's paired shift at that layout "
            "(`joint_region.parquet`, sim.studies.agnard.joint); the region's columns "
            "below are at the configured scanner"
            if n
            else ""
        ),
        design=f"a Sobol design of {cfg['region.points']} layouts, each without and "
        "with the projection centres (centres_1 0 and 1), not refined (no printed "
        "statement bounds the region: Figure 5 is lost)",
    )
    scanner_rows = tuple(
        f"- `{r['claim']}`"
        for r in rows(out, "claims.parquet")
        if r["interval"] == "region" and not _five(r["claim"])
    )
    lead = "\n".join(ln for ln in lead.split("\n") if not ln.startswith(scanner_rows))
    return [lead, figure(out, "consistent_region.png", "consistent region")]


def peaks(cfg: dict) -> str:
    """The peaks every simulated scanner field is scaled to (``scan.max_*_um``): "the printed
    +-20 / +-40 um peaks", or the run's with the paper's beside them."""
    keys = ("scan.max_x_um", "scan.max_y_um")
    run = "+-{:g} / +-{:g} um".format(*(cfg[k] for k in keys))
    paper = "+-{:g} / +-{:g} um".format(*(SCHEMA[k].default for k in keys))
    return (
        f"the printed {paper} peaks"
        if run == paper
        else f"this run's {run} peaks (printed: {paper})"
    )


def scanner_lead(out: Path, cfg: dict) -> list[str]:
    """The scanner region's section and figure (none for results written before the scanner
    region existed)."""
    if not (out / "scanner_region.parquet").is_file():
        return []
    return [
        _scanner_region(out, cfg),
        figure(out, "scanner_region.png", "scanner region under Table 1"),
    ]


def _scanner_region(out: Path, cfg: dict) -> str:
    """The scanner's unprinted inputs under Table 1 (``scanner_region*.parquet``): per input its
    possible range, what Table 1 leaves, the design's resolution; then the conflicts."""
    inp = rows(out, "scanner_region_inputs.parquet")
    reg = table(out, "scanner_region.parquet")
    n, k = len(reg["accepted"]), sum(reg["accepted"])
    body = [
        [
            f"`{r['input']}`",
            f"{fmt(r['declared_low'])}-{fmt(r['declared_high'])}",
            "none" if not r["n_region"] else f"{fmt(r['region_low'])}-{fmt(r['region_high'])}",
            f"{fmt(r['resolution_interior'])} ({n} vectors)",
            r["why"],
        ]
        for r in inp
    ]
    ids = [c for c in reg if c.startswith("agnard.table1.") and not c.endswith("__value")]
    fails = [c.split(".")[-1] for c in ids if all(o == "fails" for o in reg[c])]
    verdict = (
        f"**No vector is consistent**: {', '.join(fails) or 'no statement alone'} "
        f"{'is' if len(fails) == 1 else 'are'} contradicted at every explored vector, so Table 1 "
        "is *not comparable* (not a failed prediction): the simulated scanner is not the "
        "set-up that produced it."
        if k == 0
        else f"{k} of {n} vectors are consistent with Table 1."
    )
    verdicts = [
        [f"`{c['claim']}`", c["verdict"], c["note"].split(HOW)[0].split("; at the configured")[0]]
        for c in rows(out, "claims.parquet")
        if c["interval"] == "region" and not _five(c["claim"])
    ]
    return "\n".join(
        [
            f"**Scanner region under Table 1** (`scanner_region.parquet`, {n} vectors explored "
            "jointly, each adjusting the same simulated blocks without and with the grid "
            f"correction; every field scaled to {peaks(cfg)}): " + verdict,
            "",
            md_table(["input", "possible", "left by Table 1", "resolution", "why"], body),
        ]
        + (_scanner_predictions(verdicts) if verdicts else [])
    )


def _scanner_predictions(verdicts: list[list[str]]) -> list[str]:
    return [
        "",
        "**Predictions over the scanner's inputs** (Table 1 set aside as not comparable, "
        "so no printed statement constrains them and every explored vector counts; the "
        "21-control pass hangs on the scanner through the residual after the grid "
        "correction). Each vector runs the same blocks as the configured scanner (common "
        "random numbers); a row's blocks at the vector are the configured scanner's main "
        "blocks shifted in logarithms by the paired shift, over its interval, so a vector "
        "is decided only where the shift's own uncertainty does not straddle the decision "
        "(`scanner_shift.parquet`, sim.studies.agnard.paired):",
        "",
        md_table(["claim", "verdict", "where"], verdicts),
    ]


def _five(cid: str) -> bool:
    """A row decided over the five-point layout's region (not the scanner's)."""
    return cid.startswith(
        ("agnard.control_5.", "agnard.max_residual.control_5_", "agnard.finding.control_5_")
    )
