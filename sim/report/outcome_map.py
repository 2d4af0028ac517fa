"""Outcome map of swept claims: the outcome of every claim at each value of each unprinted
input swept one at a time, the set where no claim is contradicted shaded. Shared by the
grid-plate and Salsig studies (their ``sweep.parquet`` / ``consistent_set.parquet`` columns:
input, input_value, claim, outcome; input, claim, holds_low, holds_high, default)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from sim.report.plotting import plt, save

__all__ = ["fig_consistent"]

_COL = {"holds": "tab:green", "inconclusive": "gold", "fails": "tab:red"}


def fig_consistent(det: dict, cons: dict, path: Path) -> None:
    """Outcome of every swept claim against each unprinted input; consistent set shaded."""
    inputs = list(dict.fromkeys(det["input"]))
    claims = list(dict.fromkeys(det["claim"]))
    fig, axs = plt.subplots(
        len(inputs), 1, figsize=(9, 2.0 + 0.32 * len(claims) * len(inputs)), squeeze=False
    )
    short = [c.split(".", 1)[1] for c in claims]
    for ax, key in zip(axs[:, 0], inputs):
        idx = [i for i, k in enumerate(det["input"]) if k == key]
        xs = sorted({det["input_value"][i] for i in idx})
        pos = {x: n for n, x in enumerate(xs)}
        ax.scatter(
            [pos[det["input_value"][i]] for i in idx],
            [claims.index(det["claim"][i]) for i in idx],
            s=40,
            marker="s",
            c=[_COL.get(det["outcome"][i], "grey") for i in idx],
        )
        allrow = [
            j
            for j, (k, c) in enumerate(zip(cons["input"], cons["claim"]))
            if k == key and c == "ALL"
        ][0]
        lo, hi = cons["holds_low"][allrow], cons["holds_high"][allrow]
        if np.isfinite(lo):
            ax.axvspan(
                pos[lo] - 0.45,
                pos[hi] + 0.45,
                color="tab:green",
                alpha=0.12,
                label="consistent set (all claims not contradicted)",
            )
        d = cons["default"][allrow]
        if d in pos:
            ax.axvline(pos[d], color="k", ls=":", lw=1, label="value used in the run")
        ax.set_xticks(range(len(xs)), [f"{x:g}" for x in xs], fontsize=7)
        ax.set_yticks(range(len(claims)), short, fontsize=6)
        ax.set_xlim(-0.6, len(xs) - 0.4)
        ax.set_title(f"{key} (not printed)", fontsize=9)
    for o, c in _COL.items():
        axs[0, 0].scatter([], [], color=c, marker="s", label=o)
    axs[0, 0].legend(fontsize=6, loc="upper left", bbox_to_anchor=(1.0, 1.0))
    save(fig, path)
