"""Figures of the Brown studies (Brown 1968, seed ``004``; PNG, deterministic): plate
coordinates in mm, standard deviations in µm or in units of the range σ (σᵣ). Every figure
uses a constrained layout so that labels of neighbouring panels never overlap, and puts its
legends where they hide no data."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from sim.claims.intervals import std_rel_se
from sim.instruments.ranges import brown as B
from sim.instruments.ranges import multilateration as ml
from sim.mc.storage import read_provenance, read_table
from sim.report.drawing import one_at_a_time
from sim.report.plotting import figures_off, hist_bins, place_legend, plt, save
from sim.report.region import reader_label
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
    """1σ ellipses (unit range σ) of the three models, side by side."""
    fig, axs = _fig(1, 3, 15, 5.4)
    scale = 12.0  # mm of plot per unit ratio
    for i, (ax, m) in enumerate(zip(axs[0], MODEL_NAMES)):
        Qpp = ml.covariance(pts[None], theta[None], m)[0][0]
        _plate_axes(ax, cfg, theta, f"{m}: 1σ ellipses (×{scale:.0f} mm per σᵣ)", ylabel=i == 0)
        ax.plot(pts[:, 0], pts[:, 1], ".", color="0.4", ms=3)
        for j in range(len(pts)):
            _ellipse(ax, pts[j, 0], pts[j, 1], Qpp[j], scale, color="tab:blue", lw=1)
        s = np.sqrt(np.stack([Qpp[:, 0, 0], Qpp[:, 1, 1]], 1))
        ax.text(
            0.02,
            0.02,
            f"σ/σᵣ {s.min():.3f}–{s.max():.3f}",
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
        fig.colorbar(sc, ax=ax, label="dilution (%)", shrink=0.8)
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
    ax.axhspan(5, 15, color="tab:orange", alpha=0.15, label="paper, 25 points: 5–15 %")
    ax.set_title("dilution against the number of points")
    place_legend(ax, fontsize=8)
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
    ax.set_xlabel("analytic σ (µm)")
    ax.set_ylabel("Monte-Carlo σ / analytic σ (ratio)")
    ax.set_title("Monte Carlo against the analytic covariance")
    place_legend(ax, fontsize=8)
    save(fig, path)


def fig_table1(cfg, pts, theta, an_pivot, t1, path):
    """Table 1 of Brown 1968 against simulated plates: the rms closure σ0, the share of the
    run's 2n σ (x and y of its n points: 50 on the paper's 5 x 5 plate) printing 1.1-1.3 µm,
    and the analytic σ over the plate (pivot model)."""
    fig, axs = _fig(1, 3, 15, 4.8)
    a0, a1, a2 = axs[0]
    _plate_axes(a2, cfg, theta, "analytic σ, pivot model")
    sc = a2.scatter(pts[:, 0], pts[:, 1], c=pooled(an_pivot), cmap="magma_r", s=70)
    fig.colorbar(sc, ax=a2, label="σ (µm)", shrink=0.8)
    a0.hist(t1["sigma0_um"], bins=hist_bins(t1["sigma0_um"]), color="tab:blue", alpha=0.8)
    a0.axvline(1.6, color="tab:red", ls="--", label="paper: 1.6 µm")
    a0.axvspan(1.5, 2.0, color="tab:orange", alpha=0.12, label="paper: typically 1.5–2.0 µm")
    a0.set_xlabel("rms closure σ0 of one plate (µm)")
    a0.set_ylabel("simulated plates")
    a0.set_title("closure of one plate")
    place_legend(a0, fontsize=8)
    share = np.asarray(t1["share_1p1_1p3"], float) * 100
    a1.hist(share, bins=hist_bins(np.round(share, 6), 25), color="tab:green", alpha=0.8)
    a1.axvline(80, color="tab:red", ls="--", label="paper: 80 %")
    a1.set_xlabel(f"share of the {2 * len(pts)} σ printing 1.1–1.3 µm (%)")
    a1.set_ylabel("simulated plates")
    a1.set_title("printed σ in 1.1–1.3 µm")
    place_legend(a1, fontsize=8)
    save(fig, path)


_EXAMPLE = {"station_offset_mm": "comparator.station_offset_mm", "beta_mm": "comparator.beta_mm"}


def _scale_limit(ax, xname, yname, reg):
    """The scale's limit on the station offset (every range reads on 261 + 1 mm)."""
    if xname != "station_offset_mm":
        return
    if yname == "half_extent_mm":
        e = np.linspace(float(np.min(reg[yname])), B.FORMAT_MM / 2, 100)
        ax.plot(B.max_offset_mm(e), e, "k--", lw=1.2, label="scale limit")
    elif yname == "beta_mm":
        b = np.linspace(0, B.SCALE_WIDTH_MM / 2, 50)
        ax.plot(B.max_offset_mm(90.0, b), b, "k--", lw=1.2, label="scale limit")
    else:
        ax.axvline(float(B.max_offset_mm(90.0)), color="k", ls="--", lw=1.2, label="scale limit")


@one_at_a_time  # (drawn from two API runs' threads at once)
def fig_region(out: Path, pairs, path):
    """Pairwise projections of the consistent region (grey: inputs the hardware and the
    constraining statements allow; green: where every prediction holds together), the declared
    hardware box (dotted) and the scale's limit (dashed); the configured geometry as a labelled
    example (star). The legend is the figure's, below the panels. Nothing is built in a run
    without figures."""
    if figures_off():
        return
    reg = read_table(out / "consistent_region.parquet").to_pydict()
    ins = {r["input"]: r for r in read_table(out / "region_inputs.parquet").to_pylist()}
    cfg = read_provenance(out / "claims.parquet")["config"]
    tog = np.asarray(reg["together"], bool)
    fig, axs = _fig(1, len(pairs), 4.6 * len(pairs), 4.6)
    for ax, (xn, yn) in zip(axs.flat, pairs):
        _region_panel(ax, reg, ins, cfg, tog, xn, yn)
    handles = {}
    for ax in axs.flat:
        for h, lab in zip(*ax.get_legend_handles_labels()):
            handles.setdefault(lab, h)
    fig.legend(handles.values(), handles.keys(), loc="outside lower center", ncol=3, fontsize=8)
    fig.suptitle("Brown 1968: consistent region of the unprinted inputs", fontsize=10)
    save(fig, path)


def _region_panel(ax, reg, ins, cfg, tog, xn, yn) -> None:
    x, y = np.asarray(reg[xn]), np.asarray(reg[yn])
    ax.scatter(x[~tog], y[~tog], s=3, color="0.6", label="region (hardware, printed inputs)")
    ax.scatter(x[tog], y[tog], s=4, color="tab:green", label="every prediction holds")
    for name, setter in ((xn, ax.axvline), (yn, ax.axhline)):
        for v in (ins[name]["declared_low"], ins[name]["declared_high"]):
            setter(v, color="tab:blue", ls=":", lw=1, label="declared hardware range")
    _scale_limit(ax, xn, yn, reg)
    ex = [cfg.get(_EXAMPLE.get(n, ""), None) for n in (xn, yn)]
    if all(v is not None for v in ex):
        ax.plot(*ex, "*", color="tab:red", ms=11, label="configured example (not a verdict)")
    ax.set_xlabel(reader_label(xn, _LABELS))
    ax.set_ylabel(reader_label(yn, _LABELS))
    ax.ticklabel_format(useOffset=False)


#: axis labels of Brown's region inputs
_LABELS = {
    "station_offset_mm": "station offset (mm)",
    "beta_mm": "β (mm)",
    "half_extent_mm": "half extent of the points (mm)",
    "sigma0_um": "setting σ0 (µm)",
    "screw_pitch_mm": "screw pitch (mm)",
    "zeiss_half_extent_mm": "half extent of the Zeiss grid (mm)",
}
