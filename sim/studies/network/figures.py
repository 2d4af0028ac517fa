"""Figures of a network study: the network with its 95 % ellipses, and its reliability."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from sim.report.mpl import collections as mcoll
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


#: above this many observations the figures draw collections (one artist for all lines,
#: ellipses and bars): the same picture, in seconds for networks of thousands of points
LARGE = 2000


def _lines_large(ax, net, xy: np.ndarray) -> None:
    """The observation lines of a large network as one collection (each pair once), at the
    drawn coordinates ``xy`` (n, 2)."""
    use = net.kind < 5
    a = net.i[use]
    b = np.where(net.kind[use] == 2, net.k[use], net.j[use])
    pairs = np.unique(np.sort(np.stack([a, b], 1), axis=1), axis=0)
    ax.add_collection(mcoll.LineCollection(xy[pairs], colors="0.8", linewidths=0.5, zorder=1))


def _lines(ax, net, xy: np.ndarray) -> None:
    """The observation lines (each pair once; one collection for a large network)."""
    if net.m > LARGE:
        _lines_large(ax, net, xy)
        return
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


#: most points a side of the network figure draws an ellipse at: a denser network (a
#: 142 x 142 grid drew its 20,164 ellipses 1 pt across, under its markers: a blue square)
#: shows those of one point in each of SIDE x SIDE cells of its extent, and smaller markers
SIDE = 50


def _thinned(xy: np.ndarray, pts: np.ndarray) -> np.ndarray:
    """``pts``, or of more than :data:`SIDE` ** 2 of them the first in each of SIDE x SIDE
    cells of their extent."""
    pts = np.asarray(pts)
    if len(pts) <= SIDE**2:
        return pts
    p = xy[pts]
    lo, span = p.min(0), np.ptp(p, axis=0)
    cell = np.floor(SIDE * (p - lo) / np.where(span > 0, span, 1.0)).clip(0, SIDE - 1)
    _, first = np.unique(cell[:, 0] * SIDE + cell[:, 1], return_index=True)
    return pts[np.sort(first)]


def _ellipses(ax, net, an, pts, xy: np.ndarray, f: float) -> tuple[float, int]:
    """The 95 % ellipses of ``pts`` (of a dense network, of one point a cell: :func:`_thinned`),
    magnified to be seen (to 6 % of the extent, or 40 % of the spacing for a large network);
    returns the magnification and the number of ellipses drawn."""
    large = net.m > LARGE
    some = _thinned(xy, pts) if large else pts
    side = SIDE if len(some) < len(pts) else np.sqrt(net.n)
    pts = some
    a95, b95, th = ellipse(an.cov[pts])
    k = np.sqrt(CHI2_2_95)
    span = np.ptp(net.xy, axis=0).max() or 1.0
    room = 0.4 * span / side if large else 0.06 * span  # a large net: the spacing
    mag = room / max(float(k * a95.max()), 1e-300)  # both in mm
    t = np.linspace(0, 2 * np.pi, 61)
    A, B, T = a95[:, None], b95[:, None], th[:, None]
    ex = k * mag * (A * np.cos(t) * np.cos(T) - B * np.sin(t) * np.sin(T))
    ey = k * mag * (A * np.cos(t) * np.sin(T) + B * np.sin(t) * np.cos(T))
    seg = np.stack([xy[pts, 0, None] + ex / f, xy[pts, 1, None] + ey / f], -1)
    if large:
        ax.add_collection(mcoll.LineCollection(seg, colors="C1", linewidths=0.9, zorder=2))
    else:
        for s_ in seg:
            ax.plot(s_[:, 0], s_[:, 1], color="C1", lw=0.9, zorder=2)
    return mag, len(pts)


def _times(mag: float) -> str:
    """A magnification as a reader writes it: ``×9360``, ``×2.5`` (never e-notation)."""
    return f"×{mag:.0f}" if mag >= 100 else f"×{mag:.3g}"


def literal(text: str) -> str:
    """A user's text for matplotlib, drawn as written (doors24c): text between two ``$`` is
    mathtext there, so a network named ``net $\\alpha$`` was titled "net α", and one named
    ``$\\foo{$`` failed the run at its figure, after every trial. Each ``$`` is escaped."""
    return text.replace("$", r"\$")


def network_figure(net, an, pts, path: Path) -> Path:
    """Points (fixed as triangles), observation lines, 95 % ellipses magnified to be seen;
    axes in metres for a field network and in mm for a plate (:func:`natural_unit`)."""
    unit, f = natural_unit(net.xy)
    xy = net.xy_mm / f
    fig, ax = plt.subplots(figsize=(6.5, 6.0), layout="constrained")
    large = net.m > LARGE
    _lines(ax, net, xy)
    fixed = net.role == 1
    dot = 2 * min(1.0, SIDE**2 / net.n) if large else 10  # markers apart on a dense network
    ax.scatter(*xy[~fixed].T, s=dot, color="C0", zorder=3, label="estimated point")
    if fixed.any():
        ax.scatter(*xy[fixed].T, marker="^", s=40, color="C3", zorder=3, label="fixed point")
    mag, drawn = _ellipses(ax, net, an, pts, xy, f)
    some = f" of {drawn:,} of the {len(pts):,} points" if drawn < len(pts) else ""
    ax.plot([], [], color="C1", label=f"95 % ellipses{some}, drawn {_times(mag)}")
    ax.plot([], [], color="0.8", lw=0.5, label="observation")
    ax.set_aspect("equal")
    ax.set_xlabel(f"x ({unit})")
    ax.set_ylabel(f"y ({unit})")
    ax.set_title(f"{literal(net.name)}: {net.n} points, {net.m} observations")
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.1), ncol=2, fontsize=8)
    return save(fig, path)


def reliability_figure(net, an, path: Path) -> Path:
    """Redundancy number per observation and the bias-to-noise ratio, by kind."""
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(7.0, 5.6), sharex=True, layout="constrained")
    idx = np.arange(net.m)
    for n_c, c in enumerate(np.unique(net.kind)):
        s = net.kind == c
        bnr = np.where(np.isfinite(an.bnr[s]), an.bnr[s], np.nan)
        if net.m > LARGE:  # bars as one filled step outline per kind
            r_all = np.where(s, an.redundancy, 0.0)
            b_all = np.zeros(net.m)
            b_all[s] = np.nan_to_num(bnr)
            kw = dict(where=s, step="mid", color=f"C{n_c}", lw=0)
            a1.fill_between(idx, 0, r_all, label=KINDS[c], **kw)
            a2.fill_between(idx, 0, b_all, **kw)
            continue
        a1.bar(idx[s], an.redundancy[s], width=1.0, label=KINDS[c], color=f"C{n_c}")
        a2.bar(idx[s], bnr, width=1.0, color=f"C{n_c}")
    a1.set_ylabel("redundancy number")
    a1.set_ylim(0, 1)
    a2.set_ylabel("bias-to-noise ratio")
    a2.set_xlabel("observation (index)")
    a1.set_title(f"redundancy numbers: sum {an.redundancy.sum():.3f}, degrees of freedom {an.dof}")
    a2.set_title("bias-to-noise ratio (internal reliability)")
    fig.legend(*a1.get_legend_handles_labels(), loc="outside lower center", ncol=4, fontsize=8)
    return save(fig, path)
