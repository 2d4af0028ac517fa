"""Figures of ``gridplate_two_plates``: residuals of one calibration, parameter spread,
interval coverage against the weight ratio, chi-square rejection, implied grid sigma, and the
claims against every unprinted input (the consistent region, sim.report.region)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from sim.instruments import gridplate as gp
from sim.instruments import transforms2d as t2
from sim.report.plotting import plt, save
from sim.studies.gridplate.model import PARAM_LABEL, PARAMS, truth_rows
from sim.studies.gridplate.schema import UM


def fig_residuals(cfg: dict, sim: dict, path: Path) -> dict:
    """Residual vectors of one calibration (plate 1): affine with the grid fixed, and the
    combined adjustment's comparator and grid residuals at the re-weighted ratio."""
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
    fig, axs = plt.subplots(1, 2, figsize=(10, 4.8))
    qs = 2 * UM / (cfg["plate.spacing_mm"] / 4)  # 2 um drawn as a quarter spacing
    for ax in axs:
        ax.set_aspect("equal")
        ax.set_xlabel("grid x (mm)")
        ax.set_ylabel("grid y (mm)")
    q = axs[0].quiver(
        g[:, 0],
        g[:, 1],
        fa.residuals[0, :, 0],
        fa.residuals[0, :, 1],
        angles="xy",
        scale_units="xy",
        scale=qs,
        color="k",
    )
    axs[0].set_title(f"affine, grid fixed: s0 = {fa.s0[0] / UM:.2f} um", pad=16)
    q2 = axs[1].quiver(
        g[:, 0],
        g[:, 1],
        vc[:, 0],
        vc[:, 1],
        angles="xy",
        scale_units="xy",
        scale=qs,
        color="tab:blue",
        label="comparator v",
    )
    axs[1].quiver(
        g[:, 0],
        g[:, 1],
        vg[0, :, 0],
        vg[1, :, 1],
        angles="xy",
        scale_units="xy",
        scale=qs,
        color="tab:red",
        label="grid v (x from x' run, y from y' run)",
    )
    axs[1].set_title(f"combined, P_x:P_cx = 1:{np.nanmean(rw['ratio']):.2f}", pad=16)
    axs[1].legend(loc="lower left", fontsize=7)
    for ax, qq in zip(axs, (q, q2)):
        ax.quiverkey(qq, 0.85, 1.02, 2 * UM, "2 um", labelpos="E", coordinates="axes")
    save(fig, path)
    return {
        "x_mm": g[:, 0],
        "y_mm": g[:, 1],
        "aff_vx_um": fa.residuals[0, :, 0] / UM,
        "aff_vy_um": fa.residuals[0, :, 1] / UM,
        "comb_vx_um": vc[:, 0] / UM,
        "comb_vy_um": vc[:, 1] / UM,
        "grid_vx_um": vg[0, :, 0] / UM,
        "grid_vy_um": vg[1, :, 1] / UM,
    }


def fig_params(cfg: dict, res: dict, path: Path) -> None:
    S, S2, eps = truth_rows(cfg)
    truth = {"S": S, "S2": S2, "eps": eps}
    conv = {"S": 1e6, "S2": 1e6, "eps": 1 / t2.ARCSEC}
    unit = {"S": "(S - 1) ppm", "S2": "(S' - 1) ppm", "eps": "eps (arcsec)"}
    off = {"S": 1.0, "S2": 1.0, "eps": 0.0}
    fig, axs = plt.subplots(1, 3, figsize=(12, 3.6))
    for ax, k in zip(axs, PARAMS):
        a = (res[f"{k}_err_fixed_pri"].ravel() + truth[k] - off[k]) * conv[k]
        ax.hist(a, bins=60, histtype="step", color="k", label="estimates (fixed = weighted)")
        ax.axvline((truth[k] - off[k]) * conv[k], color="tab:green", lw=2, label="truth")
        ax.set_xlabel(unit[k])
        ax.set_ylabel("plates")
    axs[0].legend(fontsize=7)
    save(fig, path)


def fig_coverage(cov: dict, ratio_true: float, path: Path) -> None:
    fig, axs = plt.subplots(1, 3, figsize=(12, 3.8), sharey=True)
    r = np.asarray(cov["ratio"])
    for ax, k in zip(axs, PARAMS):
        for tag, c, lab in (
            ("pri", "tab:blue", "a-priori sigma"),
            ("post", "tab:orange", "a-posteriori s0"),
        ):
            ax.plot(r, cov[f"{k}_{tag}"], "o-", color=c, label=f"weighted, {lab}")
            ax.axhline(cov[f"{k}_fixed_{tag}"][0], color=c, ls=":", label=f"grid fixed, {lab}")
        ax.axhline(0.95, color="k", lw=0.8)
        if np.isfinite(ratio_true):
            ax.axvline(ratio_true, color="tab:green", lw=1, label="true P_cx:P_x")
        ax.set_xscale("log")
        ax.set_xlabel("weight ratio P_cx / P_x")
        ax.set_title(f"coverage, 95 % interval of {PARAM_LABEL[k]}", fontsize=9)
    axs[0].set_ylabel("fraction of plates")
    axs[0].legend(fontsize=7)
    save(fig, path)


def fig_chi2(tab: dict, true_um: float, path: Path) -> None:
    fig, ax = plt.subplots(figsize=(5.5, 3.6))
    ax.plot(tab["stated_um"], tab["analytic"], "-", color="k", label="analytic")
    ax.errorbar(
        tab["stated_um"],
        tab["reject"],
        yerr=[np.subtract(tab["reject"], tab["lo"]), np.subtract(tab["hi"], tab["reject"])],
        fmt="o",
        color="tab:red",
        label="Monte Carlo (95 % CI)",
    )
    ax.axvline(true_um, color="tab:green", label="true grid sigma")
    ax.set_xlabel("stated grid sigma (um)")
    ax.set_ylabel("rejection rate of the chi-square test")
    ax.legend(fontsize=7)
    save(fig, path)


def fig_implied(tab: dict, stated_um: float, paper: list[tuple[float, float]], path: Path) -> None:
    fig, ax = plt.subplots(figsize=(5.5, 3.6))
    r = np.asarray(tab["ratio"])
    ax.fill_between(
        r, tab["lo"], tab["hi"], color="tab:blue", alpha=0.25, label="95 % range over calibrations"
    )
    ax.plot(r, tab["median"], "o-", color="tab:blue", label="median")
    ax.axhline(stated_um, color="tab:green", label="stated grid sigma")
    ax.plot([p[0] for p in paper], [p[1] for p in paper], "k*", ms=10, label="paper")
    ax.set_xscale("log")
    ax.set_xlabel("weight ratio P_cx / P_x")
    ax.set_ylabel("grid sigma implied, s0/sqrt(P_cx) (um)")
    ax.legend(fontsize=7)
    save(fig, path)
