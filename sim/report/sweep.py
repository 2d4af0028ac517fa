"""Figure and Markdown of a ``[sweep]`` run (``sweep.parquet``, see :mod:`sim.mc.sweep`):
every claim against the first swept key (``sweep.png``), and the table of cells.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from sim.mc.storage import read_provenance, read_table
from sim.report.plotting import plt, save
from sim.report.tables import fmt, md_table

__all__ = ["fig_sweep", "sweep_markdown"]


def _claim_columns(t: dict, keys: list) -> list[str]:
    skip = set(keys) | {"cell", "replicate", "label", "seed", "feasible", "reason"}
    return [c for c in t if c not in skip and not c.endswith((":lo", ":hi")) and c + ":lo" in t]


def fig_sweep(path: Path, png: Path, max_panels: int = 12) -> Path | None:
    """Each claim's value (with its 95 % interval) against the first swept key, one line per
    combination of the other keys; infeasible cells marked on the axis. Drawn from the rows
    of ``sweep.parquet`` alone."""

    t = read_table(path).to_pydict()
    keys = read_provenance(path).get("sweep_keys", [])
    claims = _claim_columns(t, keys)[:max_panels]
    if not keys or not claims:
        return None
    x = np.array(
        [float(v) if isinstance(v, (int, float)) else i for i, v in enumerate(t[keys[0]])], float
    )
    other = [tuple(t[k][i] for k in keys[1:]) for i in range(len(x))]
    feas = np.array(t["feasible"], bool)
    ncol = min(3, len(claims))
    nrow = -(-len(claims) // ncol)
    fig, axs = plt.subplots(nrow, ncol, figsize=(4.6 * ncol, 3.4 * nrow), squeeze=False)
    for ax, c in zip(axs.ravel(), claims):
        v = np.array([np.nan if a is None else a for a in t[c]], float)
        lo = np.array([np.nan if a is None else a for a in t[c + ":lo"]], float)
        hi = np.array([np.nan if a is None else a for a in t[c + ":hi"]], float)
        for grp in dict.fromkeys(other):
            sel = np.array([o == grp for o in other]) & feas
            o = np.argsort(x[sel])
            lab = ", ".join(f"{k}={g}" for k, g in zip(keys[1:], grp)) or None
            ax.errorbar(
                x[sel][o],
                v[sel][o],
                yerr=[v[sel][o] - lo[sel][o], hi[sel][o] - v[sel][o]],
                fmt="o-",
                ms=3,
                capsize=2,
                label=lab,
            )
        for xi in x[~feas]:
            ax.axvline(xi, color="tab:red", alpha=0.3, lw=3)
        ax.set_title(c, fontsize=7)
        ax.set_xlabel(keys[0] + " (red: infeasible)")
        if other[0]:
            ax.legend(fontsize=6)
    for ax in axs.ravel()[len(claims) :]:
        ax.axis("off")
    return save(fig, png)


def sweep_markdown(out: Path, name: str | None = None) -> str:
    """Markdown for a sweep directory from ``sweep.parquet`` alone: the cells with their
    feasibility and claim values, and the figure (for ``sim report``)."""

    t = read_table(Path(out) / "sweep.parquet").to_pydict()
    keys = read_provenance(Path(out) / "sweep.parquet").get("sweep_keys", [])
    claims = _claim_columns(t, keys)
    rows = [
        [
            t["label"][i],
            *[fmt(t[k][i]) for k in keys],
            t["seed"][i],
            "yes" if t["feasible"][i] else f"no: {t['reason'][i]}",
            *[fmt(t[c][i]) for c in claims],
        ]
        for i in range(len(t["cell"]))
    ]
    txt = md_table(["cell", *keys, "seed", "feasible", *[f"`{c}`" for c in claims]], rows)
    if (Path(out) / "sweep.png").is_file():
        txt += f"\n\n![sweep]({name or Path(out).name}/sweep.png)"
    return txt
