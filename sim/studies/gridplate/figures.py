"""Figures of ``gridplate_two_plates``: residuals of one calibration, parameter spread,
interval coverage against the weight ratio, chi-square rejection, implied grid sigma, and the
claims against every unprinted input (the consistent region, sim.report.region)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from sim.instruments import gridplate as gp
from sim.instruments import transforms2d as t2
from sim.report.plotting import figures_off, hist_bins, place_legend, plain_log, plt, save
from sim.studies.gridplate.model import PARAMS, truth_rows
from sim.studies.gridplate.schema import UM

#: the parameters as the figures name them
_LABEL = {"S": "S", "S2": "S'", "eps": "ε"}


def _residual_fits(cfg: dict, sim: dict) -> tuple:
    """Plate 1's grid ``g`` (mm), the affine fit with the grid fixed, the combined
    adjustment's comparator and grid residuals (m) and its re-weighting result."""
    mean = sim["readings"].mean(axis=3)[0, 0]
    g = sim["cert"][0, 0]
    fa = t2.fit_affine(g, mean)
    comp2 = np.stack([mean[:, 0], mean[:, 1]])
    rw = gp.reweight(
        comp2,
        np.stack([g, g]),
        cfg["grid.sigma_stated_um"] * UM,
        ratio0=float(cfg["analysis.ratio_start"]),
    )
    res = rw["result"]
    vc = np.stack([res.v_comp[0], res.v_comp[1]], -1)
    vg = np.stack([res.v_grid[0], res.v_grid[1]], 0)
    return g, fa, vc, vg, rw


def _arrows(ax, g, v, qs, **kw):
    return ax.quiver(
        g[:, 0], g[:, 1], v[:, 0], v[:, 1], angles="xy", scale_units="xy", scale=qs, **kw
    )


def fig_residuals(cfg: dict, sim: dict, path: Path) -> dict:
    """Residual vectors of one calibration (plate 1): affine with the grid fixed, and the
    combined adjustment's comparator and grid residuals at the re-weighted ratio. Returns
    the drawn vectors (mm, µm) as table columns (also in a run without figures, which draws
    nothing)."""
    g, fa, vc, vg, rw = _residual_fits(cfg, sim)
    cols = {
        "x_mm": g[:, 0],
        "y_mm": g[:, 1],
        "aff_vx_um": fa.residuals[0, :, 0] / UM,
        "aff_vy_um": fa.residuals[0, :, 1] / UM,
        "comb_vx_um": vc[:, 0] / UM,
        "comb_vy_um": vc[:, 1] / UM,
        "grid_vx_um": vg[0, :, 0] / UM,
        "grid_vy_um": vg[1, :, 1] / UM,
    }
    if figures_off():
        return cols
    fig, axs = plt.subplots(1, 2, figsize=(10, 5.4), layout="constrained")
    qs = 2 * UM / (cfg["plate.spacing_mm"] / 4)  # 2 µm drawn as a quarter spacing
    for ax in axs:
        ax.set_aspect("equal")
        ax.set_xlabel("grid x (mm)")
        ax.set_ylabel("grid y (mm)")
    q = _arrows(axs[0], g, fa.residuals[0], qs, color="k")
    axs[0].set_title(f"affine, grid fixed: s0 = {fa.s0[0] / UM:.2f} µm", pad=16)
    gv = np.column_stack([vg[0, :, 0], vg[1, :, 1]])
    q2 = _arrows(axs[1], g, vc, qs, color="tab:blue", label="comparator v")
    _arrows(axs[1], g, gv, qs, color="tab:red", label="grid v (x from x' run, y from y' run)")
    axs[1].set_title(f"combined, P_x:P_cx = 1:{np.nanmean(rw['ratio']):.2f}", pad=16)
    axs[1].legend(loc="upper center", bbox_to_anchor=(0.5, -0.14), fontsize=7, ncol=2)
    for ax, qq in zip(axs, (q, q2)):
        ax.quiverkey(qq, 0.85, 1.02, 2 * UM, "2 µm", labelpos="E", coordinates="axes")
    save(fig, path)
    return cols


def fig_params(cfg: dict, res: dict, path: Path) -> None:
    S, S2, eps = truth_rows(cfg)
    truth = {"S": S, "S2": S2, "eps": eps}
    conv = {"S": 1e6, "S2": 1e6, "eps": 1 / t2.ARCSEC}
    unit = {"S": "(S - 1) ppm", "S2": "(S' - 1) ppm", "eps": "ε (arcsec)"}
    off = {"S": 1.0, "S2": 1.0, "eps": 0.0}
    fig, axs = plt.subplots(1, 3, figsize=(12, 3.9), layout="constrained")
    for ax, k in zip(axs, PARAMS):
        a = (res[f"{k}_err_fixed_pri"].ravel() + truth[k] - off[k]) * conv[k]
        ax.hist(a, bins=hist_bins(a, 60), histtype="step", color="k", label="estimates")
        ax.axvline((truth[k] - off[k]) * conv[k], color="tab:green", lw=2, label="truth")
        ax.set_xlabel(unit[k])
        ax.set_ylabel("plates")
        ax.set_title(f"estimates of {_LABEL[k]} (grid fixed = weighted)", fontsize=9)
    for ax in axs:
        place_legend(ax)
    save(fig, path)


def fig_coverage(cov: dict, ratio_true: float, path: Path) -> None:
    fig, axs = plt.subplots(1, 3, figsize=(12, 4.2), sharey=True, layout="constrained")
    r = np.asarray(cov["ratio"])
    for ax, k in zip(axs, PARAMS):
        for tag, c, lab in (
            ("pri", "tab:blue", "a-priori σ"),
            ("post", "tab:orange", "a-posteriori s0"),
        ):
            ax.plot(r, cov[f"{k}_{tag}"], "o-", color=c, label=f"weighted, {lab}")
            ax.axhline(cov[f"{k}_fixed_{tag}"][0], color=c, ls=":", label=f"grid fixed, {lab}")
        ax.axhline(0.95, color="k", lw=0.8, label="nominal 95 %")
        if np.isfinite(ratio_true):
            ax.axvline(ratio_true, color="tab:green", lw=1, label="true P_cx:P_x")
        ax.set_xscale("log")
        plain_log(ax)
        ax.set_xlabel("weight ratio P_cx / P_x")
        ax.set_title(f"coverage, 95 % interval of {_LABEL[k]}", fontsize=9)
    axs[0].set_ylabel("fraction of plates")
    handles, labels = axs[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="outside lower center", ncol=3, fontsize=7)
    save(fig, path)


def fig_chi2(tab: dict, true_um: float, path: Path) -> None:
    fig, ax = plt.subplots(figsize=(5.5, 3.8), layout="constrained")
    ax.plot(tab["stated_um"], tab["analytic"], "-", color="k", label="analytic")
    ax.errorbar(
        tab["stated_um"],
        tab["reject"],
        yerr=[np.subtract(tab["reject"], tab["lo"]), np.subtract(tab["hi"], tab["reject"])],
        fmt="o",
        color="tab:red",
        label="Monte Carlo (95 % CI)",
    )
    ax.axvline(true_um, color="tab:green", label="true grid σ")
    ax.set_xlabel("stated grid σ (µm)")
    ax.set_ylabel("rejection rate of the chi-square test")
    ax.set_title("chi-square test of the stated grid σ")
    place_legend(ax)
    save(fig, path)


def fig_implied(tab: dict, stated_um: float, paper: list[tuple[float, float]], path: Path) -> None:
    fig, ax = plt.subplots(figsize=(5.5, 3.8), layout="constrained")
    r = np.asarray(tab["ratio"])
    ax.fill_between(
        r, tab["lo"], tab["hi"], color="tab:blue", alpha=0.25, label="95 % range over calibrations"
    )
    ax.plot(r, tab["median"], "o-", color="tab:blue", label="median")
    ax.axhline(stated_um, color="tab:green", label="stated grid σ")
    ax.plot([p[0] for p in paper], [p[1] for p in paper], "k*", ms=10, label="paper")
    ax.set_xscale("log")
    plain_log(ax)
    ax.set_xlabel("weight ratio P_cx / P_x")
    ax.set_ylabel("grid σ implied, s0/√P_cx (µm)")
    ax.set_title("grid σ implied by the re-weighting")
    place_legend(ax)
    save(fig, path)
