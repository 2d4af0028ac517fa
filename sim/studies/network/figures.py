"""Figures of a network study: the network with its 95 % ellipses, and its reliability."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from sim.report.plotting import plt, save
from sim.studies.network.analysis import CHI2_2_95, ellipse
from sim.studies.network.definition import KINDS

__all__ = ["network_figure", "reliability_figure"]


#: extent (mm) from which a network is drawn in metres (a field network, not a plate)
FIELD_MM = 10_000.0


def natural_unit(xy_mm: np.ndarray) -> tuple[str, float]:
    """The unit a network's coordinates read naturally in and its size in mm: metres for a
    field network (extent of 10 m or more), millimetres for a plate or a comparator."""
    span = float(np.ptp(xy_mm, axis=0).max()) if len(xy_mm) else 0.0
    return ("m", 1000.0) if span >= FIELD_MM else ("mm", 1.0)


def network_figure(net, an, pts, path: Path) -> Path:
    """Points (fixed as triangles), observation lines, 95 % ellipses magnified to be seen;
    axes in metres for a field network and in mm for a plate (:func:`natural_unit`)."""
    unit, f = natural_unit(net.xy)
    xy = net.xy / f
    fig, ax = plt.subplots(figsize=(6.5, 6.0))
    seen = set()
    for r in range(net.m):
        if net.kind[r] >= 5:
            continue
        a, b = net.i[r], (net.k[r] if net.kind[r] == 2 else net.j[r])
        key = (min(a, b), max(a, b))
        if key in seen:
            continue
        seen.add(key)
        ax.plot(xy[[a, b], 0], xy[[a, b], 1], color="0.8", lw=0.5, zorder=1)
    fixed = net.role == 1
    ax.scatter(xy[~fixed, 0], xy[~fixed, 1], s=10, color="C0", zorder=3, label="estimated point")
    if fixed.any():
        ax.scatter(
            xy[fixed, 0],
            xy[fixed, 1],
            marker="^",
            s=40,
            color="C3",
            zorder=3,
            label="fixed point",
        )
    a95, b95, th = ellipse(an.cov[pts])
    k = np.sqrt(CHI2_2_95)
    span = np.ptp(net.xy, axis=0).max() or 1.0
    mag = 0.06 * span / max(float(k * a95.max()), 1e-300)  # both in mm
    t = np.linspace(0, 2 * np.pi, 61)
    for p, A, B, T in zip(pts, a95, b95, th):
        ex = k * mag * (A * np.cos(t) * np.cos(T) - B * np.sin(t) * np.sin(T))
        ey = k * mag * (A * np.cos(t) * np.sin(T) + B * np.sin(t) * np.cos(T))
        ax.plot(xy[p, 0] + ex / f, xy[p, 1] + ey / f, color="C1", lw=0.9, zorder=2)
    ax.plot([], [], color="C1", label=f"95 % ellipse x {mag:.3g}")
    ax.set_aspect("equal")
    ax.set_xlabel(f"x ({unit})")
    ax.set_ylabel(f"y ({unit})")
    ax.set_title(f"{net.name}: {net.n} points, {net.m} observations")
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)
    return save(fig, path)


def reliability_figure(net, an, path: Path) -> Path:
    """Redundancy number per observation and the bias-to-noise ratio, by kind."""
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(7.0, 5.0), sharex=True)
    idx = np.arange(net.m)
    for c in np.unique(net.kind):
        s = net.kind == c
        a1.bar(idx[s], an.redundancy[s], width=1.0, label=KINDS[c])
        bnr = np.where(np.isfinite(an.bnr[s]), an.bnr[s], np.nan)
        a2.bar(idx[s], bnr, width=1.0)
    a1.set_ylabel("redundancy number")
    a1.set_ylim(0, 1)
    a1.legend(fontsize=8, ncol=4, loc="upper right")
    a2.set_ylabel("bias-to-noise ratio")
    a2.set_xlabel("observation")
    a1.set_title(
        f"sum of redundancy numbers {an.redundancy.sum():.3f}; degrees of freedom {an.dof}"
    )
    fig.tight_layout()
    return save(fig, path)
