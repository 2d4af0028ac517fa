"""Figure of a consistent region (issue 21 item 5): pairwise projections of the explored
input vectors, the consistent ones (no printed statement contradicted) in green, the
excluded ones in grey, the box of physically possible ranges as the frame, an optional
hardware boundary (a curve) and the configured nominal inputs as a labelled example."""

from __future__ import annotations

import re
from itertools import combinations
from pathlib import Path
from typing import Callable, Mapping

import numpy as np

from sim.claims.inference import Region
from sim.report.drawing import one_at_a_time
from sim.report.papers import paper_name
from sim.report.plotting import figures_off, plt, save

__all__ = ["fig_region", "reader_label", "LABELS"]


#: axis labels of the region inputs the studies declare (``region.toml``), with units
LABELS = {
    "five_inset_1": "inset of the five control points (share of the block length)",
    "grid_points_1": "grid points per side",
    "spacing_mm": "grid spacing (mm)",
    "scale_diff_at_100mm_um": "scale difference S' - S over 100 mm (µm)",
    "grid_sigma_true_um": "true σ of the grid coordinates (µm)",
    "relief_mm": "relief of the control heights, rms (model mm)",
    "sigma_z_um": "σ_z of a control point (model µm)",
    "sigma_xy_um": "σ_xy of a control point (model µm)",
    "control_1": "control points per model",
    "pointing_sigma_um": "pointing σ of one reading (µm)",
    "field_scale_1": "factor on the field amplitudes",
    "mono_sigma_um": "monocomparator σ (µm)",
}
_PLAIN = ((re.compile(r"(?<![\w.])um(?![\w.])"), "µm"), (re.compile(r"\bsigma\b"), "σ"))
_PLAIN += ((re.compile(r"\+-"), "±"),)


def reader_label(name: str, labels: Mapping[str, str] | None = None) -> str:
    """The axis label of input ``name``: the study's own label or :data:`LABELS`, with units
    and symbols as a reader writes them (µm, σ, ±); else the name with the unit its suffix
    names (``x_mm`` -> ``x (mm)``)."""
    text = (labels or {}).get(name) or LABELS.get(name)
    if text is None:
        base, _, unit = name.rpartition("_")
        unit = {"um": "µm", "mm": "mm", "m": "m", "deg": "deg"}.get(unit)
        text = f"{base} ({unit})" if base and unit else name
    for pat, rep in _PLAIN:
        text = pat.sub(rep, text)
    return text


def _title(title: str) -> str:
    """A title that names its paper by authors and year (``seed 003:`` -> ``Agnard, Nolette
    & Gagnon (early 1990s):``)."""
    m = re.match(r"seed (\d{3})\b", title)
    return paper_name(m.group(1)) + title[m.end() :] if m else title


@one_at_a_time  # (drawn from two API runs' threads at once)
def fig_region(
    region: Region,
    path: Path,
    *,
    title: str = "",
    nominal: Mapping[str, float] | None = None,
    boundary: Mapping[tuple[str, str], Callable[[np.ndarray], np.ndarray]] | None = None,
    labels: Mapping[str, str] | None = None,
) -> None:
    """Pairwise projections of ``region`` (inputs with ``low < high``); one input alone is
    drawn as the share of explored values consistent along its range. The legend is the
    figure's, below the panels (never over the points).

    boundary : ``{(x input, y input): f}``, a hardware limit ``y = f(x)`` drawn as a line.
    nominal : the configured values, drawn as a star (an example, not a verdict).
    Nothing is built in a run without figures (:func:`~sim.report.plotting.figures_off`).
    """
    if figures_off():
        return
    free = [i for i in region.inputs if i.high > i.low]
    pairs = list(combinations(free, 2))
    n = max(len(pairs), 1)
    cols = min(3, n)
    rows = int(np.ceil(n / cols))
    fig, axs = plt.subplots(
        rows, cols, figsize=(4.4 * cols, 3.6 * rows + 0.8), squeeze=False, layout="constrained"
    )
    acc = region.accepted
    if not pairs:
        _one_input(axs[0, 0], region, free[0], labels, nominal)
    for ax, (a, b) in zip(axs.ravel(), pairs):
        xa, xb = region.x[a.name], region.x[b.name]
        ax.scatter(xa[~acc], xb[~acc], s=6, color="0.6", label="contradicted")
        ax.scatter(xa[acc], xb[acc], s=8, color="tab:green", label="consistent")
        ax.set_xlim(a.low, a.high)
        ax.set_ylim(b.low, b.high)
        ax.set_xlabel(reader_label(a.name, labels))
        ax.set_ylabel(reader_label(b.name, labels))
        f = (boundary or {}).get((a.name, b.name))
        if f is not None:
            t = np.linspace(a.low, a.high, 200)
            ax.plot(t, f(t), "k--", lw=1, label="hardware limit")
        if nominal and a.name in nominal and b.name in nominal:
            ax.plot(nominal[a.name], nominal[b.name], "k*", ms=10, label="nominal (example)")
    for ax in axs.ravel()[n:]:
        ax.set_visible(False)
    handles = {}
    for ax in axs.ravel()[:n]:
        for h, lab in zip(*ax.get_legend_handles_labels()):
            handles.setdefault(lab, h)
    fig.legend(handles.values(), handles.keys(), loc="outside lower center", ncol=len(handles))
    fig.suptitle(_title(title) or "consistent region of the unprinted inputs", fontsize=10)
    save(fig, path)


def _one_input(ax, region: Region, inp, labels, nominal) -> None:
    """One free input: the explored values, consistent (green) or contradicted (grey),
    against the input, spread vertically by their order (a strip)."""
    x = region.x[inp.name]
    acc = region.accepted
    y = np.linspace(0.0, 1.0, x.size) if x.size > 1 else np.full(x.size, 0.5)
    ax.scatter(x[~acc], y[~acc], s=8, color="0.6", label="contradicted")
    ax.scatter(x[acc], y[acc], s=10, color="tab:green", label="consistent")
    if nominal and inp.name in nominal:
        ax.axvline(nominal[inp.name], color="k", ls="--", lw=1, label="nominal (example)")
    ax.set_xlim(inp.low, inp.high)
    ax.set_ylim(-0.05, 1.05)
    ax.set_yticks([])
    ax.set_xlabel(reader_label(inp.name, labels))
    ax.set_title(f"{int(acc.sum())} of {x.size} explored values consistent", fontsize=9)
