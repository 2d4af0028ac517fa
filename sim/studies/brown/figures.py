"""Figures of the Brown studies (PNG, deterministic)."""
from __future__ import annotations

import numpy as np

from ... import multilateration as ml
from ...claims import std_rel_se
from ...plotting import plt, save
from .schema import MODEL_NAMES
from .core import pooled_sigma

# ----------------------------------------------------------------------------- figures


def _plate_axes(ax, cfg, theta, title):
    half = cfg["plate.format_mm"] / 2
    ax.add_patch(plt.Rectangle((-half, -half), 2 * half, 2 * half, fill=False, lw=1, color="k"))
    S = ml.stations(theta)
    ax.plot(S[:, 0], S[:, 1], "^", color="tab:red", ms=7, label="stations")
    ax.set_aspect("equal")
    ax.set_title(title)
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")


def _ellipse(ax, x, y, cov, scale, **kw):
    w, v = np.linalg.eigh(cov)
    t = np.linspace(0, 2 * np.pi, 60)
    e = (v @ (np.sqrt(np.maximum(w, 0))[:, None] * np.vstack([np.cos(t), np.sin(t)]))) * scale
    ax.plot(x + e[0], y + e[1], **kw)


def fig_sigma_maps(cfg, pts, theta, sr, path):
    fig, axs = plt.subplots(1, 3, figsize=(13, 4.6))
    scale = 12.0 / sr  # mm of plot per um
    for ax, m in zip(axs, MODEL_NAMES):
        Qpp = ml.covariance(pts[None], theta[None], m)[0][0] * sr ** 2
        _plate_axes(ax, cfg, theta, f"{m}: 1-sigma ellipses (x{scale:.0f} mm/um)")
        ax.plot(pts[:, 0], pts[:, 1], ".", color="0.4", ms=3)
        for j in range(len(pts)):
            _ellipse(ax, pts[j, 0], pts[j, 1], Qpp[j], scale, color="tab:blue", lw=1)
        s = np.sqrt(np.stack([Qpp[:, 0, 0], Qpp[:, 1, 1]], 1)) / sr
        ax.text(0.02, 0.02, f"sigma/sigma_r {s.min():.3f}-{s.max():.3f}", transform=ax.transAxes,
                fontsize=8, bbox=dict(fc="w", alpha=0.8))
    save(fig, path)


def fig_dilution_points(cfg, pts, theta, an, path):
    fig, axs = plt.subplots(1, 2, figsize=(11, 4.8))
    k = pooled_sigma(an["known"])
    for ax, m in zip(axs, ("stations", "pivot")):
        d = (pooled_sigma(an[m]) / k - 1) * 100
        _plate_axes(ax, cfg, theta, f"dilution of {m} over known (%)")
        sc = ax.scatter(pts[:, 0], pts[:, 1], c=d, cmap="viridis", s=60)
        for j in range(len(pts)):
            if len(pts) <= 49:
                ax.annotate(f"{d[j]:.1f}", pts[j], textcoords="offset points", xytext=(0, 6),
                            ha="center", fontsize=7)
        fig.colorbar(sc, ax=ax, label="%")
    save(fig, path)


def fig_dilution_vs_points(tab, path):
    fig, ax = plt.subplots(figsize=(6, 4))
    n = np.asarray(tab["n_points"])
    for col, lab in (("dil_max_pct", "max over points"), ("dil_mean_pct", "mean"),
                     ("dil_min_pct", "min over points")):
        ax.plot(n, tab[col], "o-", label=lab)
    ax.set_xscale("log")
    ax.set_xlabel("number of points (k x k grid, same extent)")
    ax.set_ylabel("dilution of 'stations' over 'known' (%)")
    ax.axhspan(5, 15, color="tab:orange", alpha=0.15, label="paper, 25 points: 5-15 %")
    ax.legend()
    save(fig, path)


def fig_sigma_vs_offset(tab, path):
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.plot(tab["offset_mm"], tab["known_min_ratio"], "o-", label="smallest sigma / sigma_r")
    ax.plot(tab["offset_mm"], tab["known_max_ratio"], "s-", label="largest sigma / sigma_r")
    for v, lab in ((0.71, "paper 0.71"), (0.85, "paper 0.85")):
        ax.axhline(v, ls="--", color="0.5")
        ax.text(tab["offset_mm"][-1], v, lab, va="bottom", ha="right", fontsize=8)
    ax.set_xlabel("station offset outside the midsides (mm)")
    ax.set_ylabel("sigma of a coordinate / sigma of a range")
    ax.set_title("known stations: range of accuracy over the points")
    ax.legend()
    save(fig, path)


def fig_edge_contour(extents, offsets, grid, found, path):
    fig, ax = plt.subplots(figsize=(6, 4.2))
    cs = ax.contourf(offsets, extents, grid, levels=np.arange(0.70, 1.01, 0.02), cmap="viridis")
    ax.contour(offsets, extents, grid, levels=[0.85], colors="w", linewidths=2)
    fig.colorbar(cs, ax=ax, label="largest sigma / sigma_r (known stations)")
    ok = np.isfinite(found)
    ax.plot(found[ok], np.asarray(extents)[ok], "wo")
    ax.set_xlabel("station offset outside the midsides (mm)")
    ax.set_ylabel("half extent of the points (mm)")
    ax.set_title("where the largest ratio is 0.85 (white)")
    save(fig, path)


def fig_mc_vs_analytic(cols, n_trials, path):
    fig, ax = plt.subplots(figsize=(5.5, 5))
    model = np.asarray(cols["model"])
    for m, mk in zip(MODEL_NAMES, "os^"):
        sel = model == m
        a = np.concatenate([np.asarray(cols["sigma_x_um"])[sel], np.asarray(cols["sigma_y_um"])[sel]])
        s = np.concatenate([np.asarray(cols["mc_sigma_x_um"])[sel],
                            np.asarray(cols["mc_sigma_y_um"])[sel]])
        ax.plot(a, s / a, mk, ms=4, label=m, alpha=0.7)
        band = 1.96 * std_rel_se(n_trials)
    ax.axhspan(1 - band, 1 + band, color="0.8", alpha=0.5, label="95 % sampling band")
    ax.axhline(1, color="k", lw=0.8)
    ax.set_xlabel("analytic sigma (um)")
    ax.set_ylabel("Monte-Carlo sigma / analytic sigma")
    ax.legend()
    save(fig, path)

