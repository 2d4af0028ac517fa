"""Figure of a consistent region (issue 21 item 5): pairwise projections of the explored
input vectors, the consistent ones (no printed statement contradicted) in green, the
excluded ones in grey, the box of physically possible ranges as the frame, an optional
hardware boundary (a curve) and the configured nominal inputs as a labelled example."""

from __future__ import annotations

from itertools import combinations
from pathlib import Path
from typing import Callable, Mapping

import numpy as np

from sim.claims.inference import Region
from sim.mc.storage import read_table
from sim.report.plotting import plt, save
from sim.report.tables import md_table

__all__ = ["fig_region", "region_markdown"]


def fig_region(
    region: Region,
    path: Path,
    *,
    title: str = "",
    nominal: Mapping[str, float] | None = None,
    boundary: Mapping[tuple[str, str], Callable[[np.ndarray], np.ndarray]] | None = None,
    labels: Mapping[str, str] | None = None,
) -> None:
    """Pairwise projections of ``region`` (inputs with ``low < high``).

    boundary : ``{(x input, y input): f}``, a hardware limit ``y = f(x)`` drawn as a line.
    nominal : the configured values, drawn as a star (an example, not a verdict).
    """
    free = [i for i in region.inputs if i.high > i.low]
    pairs = list(combinations(free, 2)) or [(free[0], free[0])]
    n = len(pairs)
    cols = min(3, n)
    rows = int(np.ceil(n / cols))
    fig, axs = plt.subplots(rows, cols, figsize=(4.2 * cols, 3.8 * rows), squeeze=False)
    acc = region.accepted
    lab = dict(labels or {})
    for ax, (a, b) in zip(axs.ravel(), pairs):
        xa, xb = region.x[a.name], region.x[b.name]
        ax.scatter(xa[~acc], xb[~acc], s=6, color="0.75", label="contradicted")
        ax.scatter(xa[acc], xb[acc], s=8, color="tab:green", label="consistent")
        ax.set_xlim(a.low, a.high)
        ax.set_ylim(b.low, b.high)
        ax.set_xlabel(lab.get(a.name, a.name))
        ax.set_ylabel(lab.get(b.name, b.name))
        f = (boundary or {}).get((a.name, b.name))
        if f is not None:
            t = np.linspace(a.low, a.high, 200)
            ax.plot(t, f(t), "k--", lw=1, label="hardware limit")
        if nominal and a.name in nominal and b.name in nominal:
            ax.plot(nominal[a.name], nominal[b.name], "k*", ms=10, label="nominal (example)")
    for ax in axs.ravel()[n:]:
        ax.set_visible(False)
    axs[0, 0].legend(fontsize=7, loc="best")
    if title:
        fig.suptitle(title, fontsize=10)
    save(fig, path)


def region_markdown(out: Path, claims: list[dict]) -> str:
    """The report's opening for a study decided over its consistent region: the region (per
    input, its possible range and what the printed statements leave, with the resolution),
    then the verdicts of the predictions over it (from ``region_inputs.parquet``
    and the claims rows whose interval is ``region``; ``region_inputs.parquet`` as brown's
    studies write it)."""

    t = read_table(out / "region_inputs.parquet").to_pylist()
    n = read_table(out / "consistent_region.parquet").num_rows
    rows = [
        [
            f"`{r['input']}`",
            f"{_g(r['declared_low'])}-{_g(r['declared_high'])}",
            "none" if r["region_low"] is None else f"{_g(r['region_low'])}-{_g(r['region_high'])}",
            f"{_g(r['resolution_interior'])} ({_g(r['resolution_boundary'])})",
            r["why"],
        ]
        for r in t
        if r["declared_high"] > r["declared_low"]
    ]
    verdicts = [
        [f"`{c['claim']}`", c["verdict"], c["note"].split("; at the configured")[0]]
        for c in claims
        if c.get("interval") == "region"
    ]
    return "\n".join(
        [
            f"**Consistent region** (`consistent_region.parquet`, {n} accepted input vectors): "
            "the unprinted inputs explored jointly over their physically possible ranges; a "
            "vector is in the region when no printed statement is contradicted at the 95 % "
            "level (Monte-Carlo noise included).",
            "",
            md_table(
                ["input", "possible", "left by the paper", "resolution (boundary)", "why"], rows
            ),
            "",
            "**Predictions over the region** (holds / fails everywhere in it, depends, "
            "holds or undecided, fails or undecided, undecidable):",
            "",
            md_table(["claim", "verdict", "where"], verdicts),
        ]
    )


def _g(x) -> str:
    return "n/a" if x is None else f"{x:.3g}"
