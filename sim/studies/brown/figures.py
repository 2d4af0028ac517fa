"""Figures of the Brown studies (PNG, deterministic). Every figure uses a constrained layout
so that labels of neighbouring panels never overlap."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from sim.claims.intervals import std_rel_se
from sim.instruments.ranges import multilateration as ml
from sim.mc.storage import read_table
from sim.report.plotting import plt, save
from sim.studies.brown.schema import MODEL_NAMES
from sim.studies.brown.values import pooled


def _fig(nrows, ncols, w, h):
    return plt.subplots(nrows, ncols, figsize=(w, h), layout="constrained", squeeze=False)


def _plate_axes(ax, cfg, theta, title, ylabel=True):
    half = cfg["plate.format_mm"] / 2
    ax.add_patch(plt.Rectangle((-half, -half), 2 * half, 2 * half, fill=False, lw=1, color="k"))
    S = ml.stations(theta)
    ax.plot(S[:, 0], S[:, 1], "^", color="tab:red", ms=7, label="stations")
    ax.set_aspect("equal")
    ax.set_title(title, fontsize=9)
    ax.set_xlabel("x (mm)")
    if ylabel:
        ax.set_ylabel("y (mm)")


def _ellipse(ax, x, y, cov, scale, **kw):
    w, v = np.linalg.eigh(cov)
    t = np.linspace(0, 2 * np.pi, 60)
    e = (v @ (np.sqrt(np.maximum(w, 0))[:, None] * np.vstack([np.cos(t), np.sin(t)]))) * scale
    ax.plot(x + e[0], y + e[1], **kw)


def fig_sigma_maps(cfg, pts, theta, path):
    """1-sigma ellipses (unit range sigma) of the three models, side by side."""
    fig, axs = _fig(1, 3, 15, 5.4)
    scale = 12.0  # mm of plot per unit ratio
    for i, (ax, m) in enumerate(zip(axs[0], MODEL_NAMES)):
        Qpp = ml.covariance(pts[None], theta[None], m)[0][0]
        _plate_axes(
            ax, cfg, theta, f"{m}: 1-sigma ellipses (x{scale:.0f} mm per sigma_r)", ylabel=i == 0
        )
        ax.plot(pts[:, 0], pts[:, 1], ".", color="0.4", ms=3)
        for j in range(len(pts)):
            _ellipse(ax, pts[j, 0], pts[j, 1], Qpp[j], scale, color="tab:blue", lw=1)
        s = np.sqrt(np.stack([Qpp[:, 0, 0], Qpp[:, 1, 1]], 1))
        ax.text(
            0.02,
            0.02,
            f"sigma/sigma_r {s.min():.3f}-{s.max():.3f}",
            transform=ax.transAxes,
            fontsize=8,
            bbox=dict(fc="w", alpha=0.8),
        )
    save(fig, path)


def fig_dilution_points(cfg, pts, theta, unit, path):
    fig, axs = _fig(1, 2, 12, 5.4)
    k = pooled(unit["known"])
    for i, (ax, m) in enumerate(zip(axs[0], ("stations", "pivot"))):
        d = (pooled(unit[m]) / k - 1) * 100
        _plate_axes(ax, cfg, theta, f"dilution of {m} over known (%)", ylabel=i == 0)
        sc = ax.scatter(pts[:, 0], pts[:, 1], c=d, cmap="viridis", s=60)
        if len(pts) <= 49:
            for j in range(len(pts)):
                ax.annotate(
                    f"{d[j]:.1f}",
                    pts[j],
                    textcoords="offset points",
                    xytext=(0, 6),
                    ha="center",
                    fontsize=7,
                )
        fig.colorbar(sc, ax=ax, label="%", shrink=0.8)
    save(fig, path)


def fig_dilution_vs_points(table: Path, path):
    tab = read_table(table).to_pydict()
    fig, axs = _fig(1, 1, 6.5, 4.2)
    ax = axs[0, 0]
    n = np.asarray(tab["n_points"])
    for col, lab in (
        ("dil_max_pct", "max over points"),
        ("dil_mean_pct", "mean"),
        ("dil_min_pct", "min over points"),
    ):
        ax.plot(n, tab[col], "o-", label=lab)
    ax.set_xscale("log")
    ax.set_xlabel("number of points (k x k grid, same extent)")
    ax.set_ylabel("dilution of 'stations' over 'known' (%)")
    ax.axhspan(5, 15, color="tab:orange", alpha=0.15, label="paper, 25 points: 5-15 %")
    ax.legend(fontsize=8)
    save(fig, path)


def fig_mc_vs_analytic(cols, n_trials, path):
    fig, axs = _fig(1, 1, 6, 5)
    ax = axs[0, 0]
    model = np.asarray(cols["model"])
    band = 1.96 * std_rel_se(n_trials)
    for m, mk in zip(MODEL_NAMES, "os^"):
        sel = model == m
        a = np.concatenate(
            [np.asarray(cols["sigma_x_um"])[sel], np.asarray(cols["sigma_y_um"])[sel]]
        )
        s = np.concatenate(
            [np.asarray(cols["mc_sigma_x_um"])[sel], np.asarray(cols["mc_sigma_y_um"])[sel]]
        )
        ax.plot(a, s / a, mk, ms=4, label=m, alpha=0.7)
    ax.axhspan(1 - band, 1 + band, color="0.8", alpha=0.5, label="95 % sampling band")
    ax.axhline(1, color="k", lw=0.8)
    ax.set_xlabel("analytic sigma (um)")
    ax.set_ylabel("Monte-Carlo sigma / analytic sigma")
    ax.legend(fontsize=8)
    save(fig, path)


def fig_table1(cfg, pts, theta, an_pivot, t1, path):
    fig, axs = _fig(1, 3, 15, 4.6)
    a0, a1, a2 = axs[0]
    a0.hist(t1["sigma0_um"], bins=50, color="tab:blue", alpha=0.8)
    a0.axvline(1.6, color="tab:red", ls="--", label="paper 1.6 um")
    a0.axvspan(1.5, 2.0, color="tab:orange", alpha=0.12, label="paper: typically 1.5-2.0 um")
    a0.set_xlabel("rms closure sigma0 (um) of one plate")
    a0.set_ylabel("simulated plates")
    a0.legend(fontsize=8)
    a1.hist(t1["share_1p1_1p3"] * 100, bins=np.linspace(0, 100, 26), color="tab:green", alpha=0.8)
    a1.axvline(80, color="tab:red", ls="--", label="paper: 80 %")
    a1.set_xlabel("share of the 50 sigmas printing 1.1-1.3 um (%)")
    a1.set_ylabel("simulated plates")
    a1.legend(fontsize=8)
    _plate_axes(a2, cfg, theta, "analytic sigma (um), pivot model")
    sc = a2.scatter(pts[:, 0], pts[:, 1], c=pooled(an_pivot), cmap="magma_r", s=70)
    fig.colorbar(sc, ax=a2, label="um", shrink=0.8)
    save(fig, path)


def _short(cid: str) -> str:
    return cid.replace("brown.", "").replace("table1_point_sigma.", "")


def fig_consistent_set(out: Path, path):
    """Each swept claim against the station offset: the paper's decision zone (orange), the
    infeasible offsets (grey: ranges longer than the scale; idealised), the consistent set of
    the nominal extent (green), one line per swept extent."""
    sw = read_table(out / "sweep.parquet").to_pydict()
    cs = read_table(out / "consistent_set.parquet").to_pylist()
    cl = {r["claim"]: r for r in read_table(out / "claims.parquet").to_pylist()}
    claims = list(dict.fromkeys(sw["claim"]))
    E = np.asarray(sw["half_extent_mm"])
    O = np.asarray(sw["offset_mm"])
    C = np.asarray(sw["claim"])
    exts = sorted(set(E))
    P = read_table(out / "points.parquet").to_pydict()
    e0 = float(max(np.abs(P["x_mm"]).max(), np.abs(P["y_mm"]).max()))
    fixed0 = next(
        r["fixed"]
        for r in cs
        if r["input"] == "comparator.station_offset_mm"
        and r["fixed"].startswith(f"half extent of the points {e0:g} mm")
    )
    row_all = next(r for r in cs if r["claim"] == "ALL" and r["fixed"] == fixed0)
    multi = len(exts) > 1
    n = len(claims) + multi
    ncols = 3
    fig, axs = _fig(math.ceil(n / ncols), ncols, 15, 3.6 * math.ceil(n / ncols))
    cmap = plt.get_cmap("viridis")
    for ax, cid in zip(axs.flat, claims):
        for i, e in enumerate(exts):
            s = (C == cid) & (E == e)
            o = O[s]
            v, lo, hi = (np.asarray(sw[k], float)[s] for k in ("value", "ci_low", "ci_high"))
            f = np.asarray(sw["feasible"], bool)[s]
            col = cmap(i / max(len(exts) - 1, 1)) if multi else "tab:blue"
            lab = f"+-{e:g} mm" if multi else "simulated"
            ax.plot(o, np.where(f, v, np.nan), "-", color=col, lw=1.6 if e == e0 else 1, label=lab)
            ax.plot(o, np.where(f, np.nan, v), ":", color=col, lw=1)
            if cl.get(cid, {}).get("form") == "range":  # the largest element too
                ax.plot(o, np.where(f, hi, np.nan), "-", color=col, lw=1.6 if e == e0 else 1)
                ax.plot(o, np.where(f, np.nan, hi), ":", color=col, lw=1)
            if e == e0 and np.any(lo != hi):
                ax.fill_between(o, lo, hi, color=col, alpha=0.15, lw=0)
        r = cl.get(cid, {})
        zl, zh = r.get("zone_low"), r.get("zone_high")
        if zl is not None and zh is not None:
            yl = ax.get_ylim()
            if zh - zl > 1e-3 * (yl[1] - yl[0]):
                ax.axhspan(
                    max(zl, yl[0] - 1e3),
                    min(zh, yl[1] + 1e3),
                    color="tab:orange",
                    alpha=0.25,
                    lw=0,
                    label="paper (decision zone)",
                )
            else:
                ax.axhline(zl, color="tab:orange", lw=2, label="paper (decision zone)")
            ax.set_ylim(yl)
        _shade(ax, row_all, cid, cs)
        ax.set_title(_short(cid), fontsize=9)
        ax.set_xlabel("station offset outside the midsides (mm)")
        ax.set_ylabel("simulated value")
        ax.ticklabel_format(axis="y", useOffset=False)
    if multi:
        ax = axs.flat[len(claims)]
        grid = np.zeros((len(exts), len(np.unique(O))))
        xo = np.unique(O)
        v = np.asarray(sw["verdict"])
        feas = np.asarray(sw["feasible"], bool)
        for i, e in enumerate(exts):
            for j, o in enumerate(xo):
                s = (E == e) & (O == o)
                grid[i, j] = (v[s] == "holds").sum() if feas[s].all() else np.nan
        im = ax.pcolormesh(
            xo, exts, grid, shading="nearest", cmap="Greens", vmin=0, vmax=len(claims)
        )
        fig.colorbar(im, ax=ax, label="claims that hold", shrink=0.8)
        ax.set_xlabel("station offset outside the midsides (mm)")
        ax.set_ylabel("half extent of the points (mm)")
        ax.set_title("claims holding (white: ranges longer than the scale)", fontsize=9)
    for ax in list(axs.flat)[n:]:
        ax.set_visible(False)
    handles = {}
    for ax in list(axs.flat)[: len(claims)]:
        for h, lab in zip(*ax.get_legend_handles_labels()):
            handles.setdefault(lab, h)
    fig.legend(
        list(handles.values()),
        list(handles),
        loc="outside lower center",
        ncols=min(len(handles), 5),
        fontsize=8,
    )
    save(fig, path)


def _shade(ax, row_all, cid, cs):
    fh, hi = row_all["feasible_high"], row_all["swept_high"]
    if fh is not None and np.isfinite(fh) and fh < hi:
        ax.axvspan(fh, hi, color="0.6", alpha=0.25, lw=0, label="idealised (off the scale)")
    own = next((r for r in cs if r["claim"] == cid and r["fixed"] == row_all["fixed"]), None)
    if own and _some(own):
        ax.axvspan(
            own["holds_low"],
            own["holds_high"],
            color="tab:blue",
            alpha=0.12,
            lw=0,
            label=f"this claim holds ({own['fixed'].replace('half extent of the points', '+-')})",
        )
    if _some(row_all):
        ax.axvspan(
            row_all["holds_low"],
            row_all["holds_high"],
            color="tab:green",
            alpha=0.15,
            lw=0,
            label="consistent set (all claims hold)",
        )
    elif _some(row_all, "ok"):
        ax.axvspan(
            row_all["ok_low"],
            row_all["ok_high"],
            color="tab:green",
            alpha=0.15,
            lw=0,
            label="no claim contradicted (holds or inconclusive)",
        )


def _some(r, which="holds") -> bool:
    return r[f"{which}_low"] is not None and np.isfinite(r[f"{which}_low"])
