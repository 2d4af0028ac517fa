"""Comparator calibration with two grid plates (seed ``001_7e3a2951e7fed426.txt``).

Study ``gridplate_two_plates``. A simulated PSK-like comparator with a small difference of
the x and y scales and a small non-orthogonality measures two grid plates (k x k points,
slight kappa rotation each), ``L`` readings per point. Each trial reproduces the paper's
reduction: precision from repeated readings, similarity and affine fits with the grid taken
as error-free, the combined adjustment with the grid coordinates as weighted observations
(x' and y' separately), the chi-square test of the grid variance and the re-weighting of
``P_x : P_cx``. Beyond the paper: bias, spread and interval coverage of ``S``, ``S'`` and
``eps`` with the grid fixed versus weighted, over a sweep of weight ratios.

Numerics: :mod:`sim.transforms2d`, :mod:`sim.gridplate`. Coordinates in mm, errors in um.
"""
from __future__ import annotations

from functools import partial
from pathlib import Path

import numpy as np
from scipy import stats

from .. import gridplate as gp
from .. import transforms2d as t2
from ..claims import claim, mean_ci, rounding, spread, std_ci, write_claims
from ..config import COMMON, ConfigError, Field
from ..plate import grid_points
from ..plotting import plt, save
from ..report import claims_markdown, fmt, inputs_markdown, md_table
from ..runner import chunk_rng, run_chunks
from ..storage import provenance, read_provenance, read_table, write_table
from . import RunContext, Study

SEED = "001_7e3a2951e7fed426.txt"
UM = 1e-3  # mm per um
PARAMS = ("S", "S2", "eps")
PARAM_LABEL = {"S": "S", "S2": "S'", "eps": "eps"}

SCHEMA = {
    **COMMON,
    "trials": Field(4000, "int", "Monte-Carlo trials (simulated calibrations)", lo=2, hi=10_000_000),
    "chunk": Field(500, "int", "trials per chunk", lo=1, hi=100_000),
    "plate.grid": Field(5, "int", "points per side of each grid plate (k x k); not printed", lo=3,
                        hi=15),
    "plate.spacing_mm": Field(40.0, "float", "grid spacing (mm); not printed", lo=1.0, hi=100.0,
                              unit="mm"),
    "plate.count": Field(2, "int", "grid plates measured (the PSK's two carriers)", lo=1, hi=4),
    "plate.kappa_deg": Field(1.0, "float", "largest |kappa| of a plate on its carrier (uniform)",
                             lo=0.0, hi=45.0, unit="deg"),
    "readings.count": Field(4, "int", "readings L per point; not printed", lo=2, hi=50),
    "readings.sigma_um": Field(1.5, "float", "sigma of one reading per coordinate (pointing)",
                               lo=0.0, lo_open=True, hi=50.0, input=True, unit="um"),
    "comparator.coord_sigma_um": Field(1.2, "float",
                                       "sigma of a mean comparator coordinate (pointing/sqrt(L) "
                                       "plus a per-point comparator error)", lo=0.0, lo_open=True,
                                       hi=50.0, input=True, unit="um"),
    "comparator.scale_diff_ppm": Field(15.0, "float",
                                       "S' - S of the comparator (ppm); set with eps so the "
                                       "systematic rms is sqrt(1.65^2 - 1.5^2) = 0.69 um", lo=-1e4, hi=1e4,
                                       input=True, unit="ppm"),
    "comparator.nonorth_arcsec": Field(3.8, "float",
                                       "non-orthogonality eps of the comparator axes; set with "
                                       "the scale difference", lo=-3600.0, hi=3600.0, input=True,
                                       unit="arcsec"),
    "grid.sigma_true_um": Field(0.7, "float", "true sigma of the grid-plate coordinates",
                                lo=0.0, hi=50.0, input=True, unit="um"),
    "grid.sigma_stated_um": Field(0.7, "float", "stated (certificate) grid sigma",
                                  lo=0.0, lo_open=True, hi=50.0, input=True, unit="um"),
    "analysis.ratios": Field([0.25, 0.5, 1.0, 2.0, 3.0, 4.0, 6.0, 10.0, 30.0], "list[float]",
                             "weight ratios P_cx/P_x swept for coverage", lo=0.0, lo_open=True,
                             min_len=1),
    "analysis.stated_sigmas_um": Field([0.2, 0.35, 0.5, 0.7, 0.9, 1.2, 1.6], "list[float]",
                                       "stated grid sigmas for the chi-square rejection curve",
                                       lo=0.0, lo_open=True, min_len=1, unit="um"),
    "analysis.alpha": Field(0.05, "float", "level of the two-sided chi-square test", lo=0.0,
                            lo_open=True, hi=0.5),
}


def check(cfg: dict) -> None:
    sp, L, sc = cfg["readings.sigma_um"], cfg["readings.count"], cfg["comparator.coord_sigma_um"]
    if sc ** 2 < sp ** 2 / L:
        raise ConfigError("comparator.coord_sigma_um",
                          f"must be >= readings.sigma_um/sqrt(readings.count) = "
                          f"{sp / np.sqrt(L):.3f} um (the mean of L readings cannot be better)")
    if cfg["plate.grid"] ** 2 < 4:
        raise ConfigError("plate.grid", "needs at least 4 points")


def truth_rows(cfg: dict):
    """The comparator's true ``S, S', eps`` (seed 001 convention, grid -> comparator)."""
    d = cfg["comparator.scale_diff_ppm"] * 1e-6
    return 1.0 - d / 2, 1.0 + d / 2, cfg["comparator.nonorth_arcsec"] * t2.ARCSEC


def simulate(cfg: dict, rng: np.random.Generator, n: int) -> dict[str, np.ndarray]:
    """Readings and grid certificates of ``n`` calibrations.

    Returns ``readings`` (n, P, N, L, 2) mm, ``cert`` (n, P, N, 2) mm (the grid coordinates
    as given), ``true`` (n, P, 6) the true affine grid -> comparator of each plate.
    """
    G = grid_points(cfg["plate.grid"], cfg["plate.spacing_mm"])
    P, N, L = cfg["plate.count"], G.shape[0], cfg["readings.count"]
    S, S2, eps = truth_rows(cfg)
    kap = rng.uniform(-1, 1, (n, P)) * np.deg2rad(cfg["plate.kappa_deg"])
    shift = rng.uniform(-5, 5, (n, P, 2)) + np.array([120.0, 120.0])
    true = t2.affine_from_rows(S, S2, eps, kap, (shift[..., 0], shift[..., 1]))
    ideal = t2.apply_affine(true.reshape(-1, 6), G).reshape(n, P, N, 2)
    sp, sc = cfg["readings.sigma_um"] * UM, cfg["comparator.coord_sigma_um"] * UM
    s_point = np.sqrt(max(sc ** 2 - sp ** 2 / L, 0.0))
    comp_err = rng.normal(0.0, 1.0, (n, P, N, 2)) * s_point
    readings = (ideal + comp_err)[:, :, :, None, :] + rng.normal(0.0, sp, (n, P, N, L, 2))
    cert = G + rng.normal(0.0, 1.0, (n, P, N, 2)) * cfg["grid.sigma_true_um"] * UM
    return {"readings": readings, "cert": cert, "true": true}


def _rows_to_affine(rx: gp.CombinedResult, ry: gp.CombinedResult, scale_x, scale_y):
    """Stack the x' and y' adjustments into 6 affine parameters and a block covariance."""
    p = np.concatenate([rx.params, ry.params], -1)
    T = p.shape[0]
    cov = np.zeros((T, 6, 6))
    cov[:, :3, :3] = rx.cofactor * scale_x[:, None, None]
    cov[:, 3:, 3:] = ry.cofactor * scale_y[:, None, None]
    return p, cov


def _decomp_errors(p, cov, S, S2, eps):
    d = t2.decompose_rows(p, cov)
    err = np.stack([d["S"] - S, d["S2"] - S2, t2._wrap(d["eps"] - eps)], -1)
    sd = np.sqrt(np.einsum("tii->ti", d["cov"]))
    return d, err, sd


def reduce_chunk(cfg: dict, sim: dict) -> dict[str, np.ndarray]:
    """The paper's reduction (and the coverage sweep) for the simulated calibrations."""
    readings, cert = sim["readings"], sim["cert"]
    n, P, N, L, _ = readings.shape
    S, S2, eps = truth_rows(cfg)
    sx = cfg["comparator.coord_sigma_um"] * UM          # a-priori comparator sigma
    sg = cfg["grid.sigma_stated_um"] * UM
    alpha = cfg["analysis.alpha"]
    z = stats.norm.ppf(0.975)
    _, sigma_obs = gp.repeat_precision(readings)
    mean = readings.mean(axis=3).reshape(n * P, N, 2)
    g = cert.reshape(n * P, N, 2)
    out: dict[str, np.ndarray] = {"sigma_obs_um": sigma_obs / UM}
    # error-free grid: similarity and affine
    fs = t2.fit_similarity(g, mean)
    fa = t2.fit_affine(g, mean)
    out["sim_sigma_um"] = np.sqrt((fs.s0 ** 2).reshape(n, P).mean(1)) / UM
    out["aff_sigma_um"] = np.sqrt((fa.s0 ** 2).reshape(n, P).mean(1)) / UM
    # grid fixed, covariance a priori (comparator sigma only) and a posteriori
    cov_pri = fa.cofactor * sx ** 2
    for tag, cov in (("fixed_pri", cov_pri), ("fixed_post", fa.cov)):
        d, err, sd = _decomp_errors(fa.params, cov, S, S2, eps)
        for i, k in enumerate(PARAMS):
            out[f"{k}_err_{tag}"] = err[:, i].reshape(n, P)
            out[f"{k}_cov_{tag}"] = (np.abs(err[:, i]) <= z * sd[:, i]).reshape(n, P)
            out[f"{k}_sd_{tag}"] = sd[:, i].reshape(n, P)
    # combined adjustment over the weight-ratio sweep (x' and y' stacked on the trial axis)
    comp2 = np.concatenate([mean[..., 0], mean[..., 1]], 0)
    g2 = np.concatenate([g, g], 0)
    m = n * P
    for j, r in enumerate(cfg["analysis.ratios"]):
        res = gp.combined_adjustment(comp2, g2, 1.0, r)
        rx = gp.CombinedResult(res.params[:m], res.grid[:m], res.cofactor[:m], res.s0[:m],
                               res.v_comp[:m], res.v_grid[:m], res.dof, res.iterations)
        ry = gp.CombinedResult(res.params[m:], res.grid[m:], res.cofactor[m:], res.s0[m:],
                               res.v_comp[m:], res.v_grid[m:], res.dof, res.iterations)
        implied = np.sqrt((res.s0 ** 2 / r).reshape(2, n, P).mean(axis=(0, 2)))
        out[f"implied_grid_um_r{j}"] = implied / UM
        for tag, sxx, syy in (("pri", np.full(m, sx ** 2), np.full(m, sx ** 2)),
                              ("post", rx.s0 ** 2, ry.s0 ** 2)):
            p6, cov = _rows_to_affine(rx, ry, sxx, syy)
            _, err, sd = _decomp_errors(p6, cov, S, S2, eps)
            for i, k in enumerate(PARAMS):
                out[f"{k}_cov_w{tag}_r{j}"] = (np.abs(err[:, i]) <= z * sd[:, i]).reshape(n, P)
                if tag == "pri":
                    out[f"{k}_err_w_r{j}"] = err[:, i].reshape(n, P)
                    out[f"{k}_sd_w_r{j}"] = sd[:, i].reshape(n, P)
    # chi-square test with a-priori weights P_x = 1/sx^2, P_cx = 1/stated^2
    for j, st in enumerate(cfg["analysis.stated_sigmas_um"]):
        res = gp.combined_adjustment(comp2, g2, 1.0, sx ** 2 / (st * UM) ** 2)
        _, _, rej = gp.chi2_test(res.s0, res.dof, sx, alpha)
        out[f"reject_s{j}"] = rej.reshape(2, n, P).transpose(1, 2, 0).reshape(n, 2 * P)
    # the paper's re-weighting with the stated grid sigma
    rw = gp.reweight(comp2, g2, sg)
    out["ratio_rw"] = rw["ratio"].reshape(2, n, P).transpose(1, 2, 0).reshape(n, 2 * P)
    out["passes_rw"] = rw["passes"].reshape(2, n, P).transpose(1, 2, 0).reshape(n, 2 * P)
    out["comp_sigma_um"] = np.sqrt((rw["s0"] ** 2).reshape(2, n, P).mean(axis=(0, 2))) / UM
    ok = np.isfinite(rw["ratio"]).reshape(2, n, P)
    ratio_pool = np.where(ok.all(axis=(0, 2)),
                          np.nanmean(rw["ratio"].reshape(2, n, P), axis=(0, 2)), np.nan)
    out["ratio_rw_mean"] = ratio_pool
    # combined at the converged ratio: intervals a posteriori
    return out


def _chunk(cfg: dict, rng: np.random.Generator, n: int) -> dict[str, np.ndarray]:
    return reduce_chunk(cfg, simulate(cfg, rng, n))


def chunk_fn(cfg: dict):
    """The chunk function ``fn(rng, n)`` for :func:`sim.runner.run_chunks` (picklable)."""
    return partial(_chunk, cfg)


def analytic_reject(cfg: dict, stated_um: float, dof: int) -> float:
    """Rejection rate of the two-sided test when the grid sigma is stated wrongly.

    ``dof s0^2 / sigma_x'^2 ~ c chi2(dof)`` with ``c = (sx^2 + k sg_true^2) / (sx^2 + k
    sg_stated^2)``, ``k = A^2 + B^2 ~ 1`` (the comparator scale).
    """
    sx, st = cfg["comparator.coord_sigma_um"], cfg["grid.sigma_true_um"]
    c = (sx ** 2 + st ** 2) / (sx ** 2 + stated_um ** 2)
    a = cfg["analysis.alpha"]
    lo, hi = stats.chi2.ppf(a / 2, dof), stats.chi2.ppf(1 - a / 2, dof)
    return float(stats.chi2.cdf(lo / c, dof) + stats.chi2.sf(hi / c, dof))


# ----------------------------------------------------------------------------- figures


def fig_residuals(cfg: dict, sim: dict, path: Path) -> dict:
    """Residual vectors of one calibration (plate 1): affine with the grid fixed, and the
    combined adjustment's comparator and grid residuals at the converged weight ratio."""
    mean = sim["readings"].mean(axis=3)[0, 0]
    g = sim["cert"][0, 0]
    fa = t2.fit_affine(g, mean)
    comp2 = np.stack([mean[:, 0], mean[:, 1]])
    rw = gp.reweight(comp2, np.stack([g, g]), cfg["grid.sigma_stated_um"] * UM)
    res = rw["result"]
    vc = np.stack([res.v_comp[0], res.v_comp[1]], -1)
    vg = np.stack([res.v_grid[0], res.v_grid[1]], 0)  # grid residuals from x' and y' runs
    fig, axs = plt.subplots(1, 2, figsize=(10, 4.8))
    qs = 2 * UM / (cfg["plate.spacing_mm"] / 4)  # 2 um drawn as a quarter spacing
    for ax in axs:
        ax.set_aspect("equal")
        ax.set_xlabel("grid x (mm)")
        ax.set_ylabel("grid y (mm)")
    q = axs[0].quiver(g[:, 0], g[:, 1], fa.residuals[0, :, 0], fa.residuals[0, :, 1],
                      angles="xy", scale_units="xy", scale=qs, color="k")
    axs[0].set_title(f"affine, grid fixed: s0 = {fa.s0[0] / UM:.2f} um", pad=16)
    q2 = axs[1].quiver(g[:, 0], g[:, 1], vc[:, 0], vc[:, 1], angles="xy", scale_units="xy",
                  scale=qs, color="tab:blue", label="comparator v")
    axs[1].quiver(g[:, 0], g[:, 1], vg[0, :, 0], vg[1, :, 1], angles="xy", scale_units="xy",
                  scale=qs, color="tab:red", label="grid v (x from x' run, y from y' run)")
    axs[1].set_title(f"combined, P_x:P_cx = 1:{np.nanmean(rw['ratio']):.2f}", pad=16)
    axs[1].legend(loc="lower left", fontsize=7)
    for ax, qq in zip(axs, (q, q2)):
        ax.quiverkey(qq, 0.85, 1.02, 2 * UM, "2 um", labelpos="E", coordinates="axes")
    save(fig, path)
    return {"x_mm": g[:, 0], "y_mm": g[:, 1], "aff_vx_um": fa.residuals[0, :, 0] / UM,
            "aff_vy_um": fa.residuals[0, :, 1] / UM, "comb_vx_um": vc[:, 0] / UM,
            "comb_vy_um": vc[:, 1] / UM, "grid_vx_um": vg[0, :, 0] / UM,
            "grid_vy_um": vg[1, :, 1] / UM}


def fig_params(cfg: dict, res: dict, j3: int, path: Path) -> None:
    S, S2, eps = truth_rows(cfg)
    truth = {"S": S, "S2": S2, "eps": eps}
    conv = {"S": 1e6, "S2": 1e6, "eps": 1 / t2.ARCSEC}
    unit = {"S": "(S - 1) ppm", "S2": "(S' - 1) ppm", "eps": "eps (arcsec)"}
    off = {"S": 1.0, "S2": 1.0, "eps": 0.0}
    fig, axs = plt.subplots(1, 3, figsize=(12, 3.6))
    for ax, k in zip(axs, PARAMS):
        a = (res[f"{k}_err_fixed_pri"].ravel() + truth[k] - off[k]) * conv[k]
        b = (res[f"{k}_err_w_r{j3}"].ravel() + truth[k] - off[k]) * conv[k]
        ax.hist(a, bins=60, histtype="step", color="k", label="grid fixed (affine)")
        ax.hist(b, bins=60, histtype="step", color="tab:red", ls="--",
                label=f"grid weighted 1:{cfg['analysis.ratios'][j3]:g}")
        ax.axvline((truth[k] - off[k]) * conv[k], color="tab:green", lw=2, label="truth")
        ax.set_xlabel(unit[k])
        ax.set_ylabel("plates")
    axs[0].legend(fontsize=7)
    save(fig, path)


def fig_coverage(cov: dict, ratio_true: float, path: Path) -> None:
    fig, axs = plt.subplots(1, 3, figsize=(12, 3.6), sharey=True)
    r = np.asarray(cov["ratio"])
    for ax, k in zip(axs, PARAMS):
        for tag, c, lab in (("pri", "tab:blue", "a-priori sigma"), ("post", "tab:orange",
                                                                     "a-posteriori s0")):
            ax.plot(r, cov[f"{k}_{tag}"], "o-", color=c, label=f"weighted, {lab}")
            ax.axhline(cov[f"{k}_fixed_{tag}"][0], color=c, ls=":",
                       label=f"grid fixed, {lab}")
        ax.axhline(0.95, color="k", lw=0.8)
        ax.axvline(ratio_true, color="tab:green", lw=1, label="true P_cx:P_x")
        ax.set_xscale("log")
        ax.set_xlabel("weight ratio P_cx / P_x")
        ax.set_title(f"coverage of the 95 % interval of {PARAM_LABEL[k]}")
    axs[0].set_ylabel("fraction of plates")
    axs[0].legend(fontsize=7)
    save(fig, path)


def fig_chi2(tab: dict, true_um: float, path: Path) -> None:
    fig, ax = plt.subplots(figsize=(5.5, 3.6))
    ax.plot(tab["stated_um"], tab["analytic"], "-", color="k", label="analytic")
    ax.errorbar(tab["stated_um"], tab["reject"], yerr=[np.subtract(tab["reject"], tab["lo"]),
                np.subtract(tab["hi"], tab["reject"])], fmt="o", color="tab:red",
                label="Monte Carlo (95 % CI)")
    ax.axvline(true_um, color="tab:green", label="true grid sigma")
    ax.set_xlabel("stated grid sigma (um)")
    ax.set_ylabel("rejection rate of the chi-square test")
    ax.legend(fontsize=7)
    save(fig, path)


def fig_implied(tab: dict, stated_um: float, path: Path) -> None:
    fig, ax = plt.subplots(figsize=(5.5, 3.6))
    r = np.asarray(tab["ratio"])
    ax.fill_between(r, tab["lo"], tab["hi"], color="tab:blue", alpha=0.25,
                    label="95 % range over calibrations")
    ax.plot(r, tab["median"], "o-", color="tab:blue", label="median")
    ax.axhline(stated_um, color="tab:green", label="stated grid sigma")
    ax.plot([2, 3], [0.8, 0.7], "k*", ms=10, label="paper (1:2, 1:3)")
    ax.set_xscale("log")
    ax.set_xlabel("weight ratio P_cx / P_x")
    ax.set_ylabel("grid sigma implied, s0/sqrt(P_cx) (um)")
    ax.legend(fontsize=7)
    save(fig, path)


# ----------------------------------------------------------------------------- run


def _pooled(x):
    return np.asarray(x, float).ravel()


def run(cfg: dict, out: Path, ctx: RunContext) -> None:
    res = run_chunks(chunk_fn(cfg), cfg["trials"], cfg["seed"], cfg["chunk"], part=0,
                     label="gridplate", quiet=ctx.quiet, ctx=ctx)
    prov = provenance(cfg)
    T = res["sim_sigma_um"].shape[0]
    N = cfg["plate.grid"] ** 2
    dof = N - 3
    ratios = list(cfg["analysis.ratios"])
    sx, sgt = cfg["comparator.coord_sigma_um"], cfg["grid.sigma_true_um"]
    ratio_true = sx ** 2 / sgt ** 2 if sgt > 0 else np.inf
    # per-trial table (one row per trial; per-plate values of plate 1 and 2 side by side)
    cols = {"trial": np.arange(T)}
    for k, v in res.items():
        v = np.asarray(v)
        if v.ndim == 1:
            cols[k] = v
        else:
            for p in range(v.shape[1]):
                cols[f"{k}_{p + 1}"] = v[:, p]
    write_table(out / "trials.parquet", cols, prov)

    # coverage table
    cov = {"ratio": np.asarray(ratios)}
    for k in PARAMS:
        for tag in ("pri", "post"):
            cov[f"{k}_{tag}"] = np.array([res[f"{k}_cov_w{tag}_r{j}"].mean()
                                          for j in range(len(ratios))])
            cov[f"{k}_fixed_{tag}"] = np.full(len(ratios), res[f"{k}_cov_fixed_{tag}"].mean())
    write_table(out / "coverage.parquet", cov, prov)
    # implied grid sigma vs ratio
    imp = {"ratio": np.asarray(ratios), "median": [], "lo": [], "hi": []}
    for j in range(len(ratios)):
        m, (lo, hi) = spread(res[f"implied_grid_um_r{j}"])
        imp["median"].append(m)
        imp["lo"].append(lo)
        imp["hi"].append(hi)
    write_table(out / "implied_grid.parquet", imp, prov)
    # chi-square rejection
    ch = {"stated_um": np.asarray(cfg["analysis.stated_sigmas_um"]), "reject": [], "lo": [],
          "hi": [], "analytic": [], "tests": []}
    for j, st in enumerate(cfg["analysis.stated_sigmas_um"]):
        x = res[f"reject_s{j}"].ravel()
        k = int(x.sum())
        lo, hi = stats.binomtest(k, x.size).proportion_ci(0.95, method="wilson")
        ch["reject"].append(x.mean())
        ch["lo"].append(lo)
        ch["hi"].append(hi)
        ch["analytic"].append(analytic_reject(cfg, st, dof))
        ch["tests"].append(x.size)
    write_table(out / "chi2_power.parquet", ch, prov)
    # bias / spread table
    conv = {"S": 1e6, "S2": 1e6, "eps": 1 / t2.ARCSEC}
    j_true = int(np.argmin(np.abs(np.log(np.asarray(ratios) / ratio_true))))
    beyond = {"param": [], "method": [], "bias": [], "bias_lo": [], "bias_hi": [], "sd": [],
              "sd_lo": [], "sd_hi": [], "stated_sd_rms": [], "unit": []}
    for k in PARAMS:
        for meth, key, sdkey in (("grid fixed (affine)", f"{k}_err_fixed_pri", f"{k}_sd_fixed_post"),
                                 (f"grid weighted 1:{ratios[j_true]:g}", f"{k}_err_w_r{j_true}",
                                  f"{k}_sd_w_r{j_true}")):
            e = _pooled(res[key]) * conv[k]
            b, (blo, bhi) = mean_ci(e)
            s, slo, shi = std_ci(e)
            beyond["param"].append(PARAM_LABEL[k])
            beyond["method"].append(meth)
            beyond["bias"].append(b)
            beyond["bias_lo"].append(blo)
            beyond["bias_hi"].append(bhi)
            beyond["sd"].append(float(s))
            beyond["sd_lo"].append(float(slo))
            beyond["sd_hi"].append(float(shi))
            sd_st = (np.sqrt(np.mean(_pooled(res[sdkey]) ** 2)) * conv[k]) if sdkey else np.nan
            beyond["stated_sd_rms"].append(sd_st)
            beyond["unit"].append("arcsec" if k == "eps" else "ppm")
    write_table(out / "beyond.parquet", beyond, prov)

    # one calibration for the residual figure (its own stream)
    ex = simulate(cfg, chunk_rng(cfg["seed"], 1, 0), 1)
    write_table(out / "example_plate.parquet", fig_residuals(cfg, ex, out / "residuals.png"), prov)
    fig_params(cfg, res, j_true, out / "parameters.png")
    fig_coverage(cov, ratio_true, out / "coverage.png")
    fig_chi2(ch, sgt, out / "chi2_power.png")
    fig_implied(imp, cfg["grid.sigma_stated_um"], out / "implied_grid.png")

    write_claims(out / "claims.parquet", claims(cfg, res, ratios, ch, beyond, cov, j_true), prov)


def claims(cfg, res, ratios, ch, beyond, cov, j_true) -> list[dict]:
    src = f"{SEED}, Analysis of the results"
    rows = []
    T = res["sim_sigma_um"].shape[0]
    L = cfg["readings.count"]
    v, sp = spread(res["sigma_obs_um"])
    rows.append(claim(
        "twoplate.observation_sigma.sigma_um", src,
        "The standard error of precision of one observation is obtained as 1.5 um.", v, sp,
        "input", f"sigma = sqrt(sum sigma_i^2 / 4N) from {L} readings of "
        f"{cfg['plate.grid'] ** 2} points on {cfg['plate.count']} plates, per calibration; the "
        f"reading sigma is an input ({cfg['readings.sigma_um']:g} um), so this checks the "
        "estimator: unbiased for the variance, 4N(L-1) degrees of freedom (the paper's '4N' is "
        "the divisor). Median and 95 % range over calibrations.",
        ref=rounding(1.5, 1), interval="spread"))
    for r, paper_v in ((2.0, 0.8), (3.0, 0.7)):
        if r not in ratios:
            continue
        j = ratios.index(r)
        v, sp = spread(res[f"implied_grid_um_r{j}"])
        rows.append(claim(
            f"twoplate.weight_ratio.grid_sigma_1to{r:g}_um", src,
            f"On weighting Px:Pcx = 1:{r:g}, sigma_x becomes {paper_v} um", v, sp, "predicted",
            f"grid sigma implied by the weights, s0/sqrt(P_cx), of the combined adjustment with "
            f"P_x:P_cx = 1:{r:g} (x' and y', both plates pooled). Follows from the inputs "
            f"sigma_x' = {cfg['comparator.coord_sigma_um']:g} and grid "
            f"{cfg['grid.sigma_true_um']:g} um: s0^2/P_cx = (sx^2 + sg^2)/(1 + P_cx). The "
            "paper's pair (0.8 at 1:2, 0.7 at 1:3) is consistent with one misclosure variance "
            "(1.92 vs 1.96 um^2).", ref=rounding(paper_v, 1), interval="spread"))
    rr = res["ratio_rw_mean"]
    fin = np.isfinite(rr)
    v, sp = spread(rr[fin])
    rows.append(claim(
        "twoplate.weight_ratio.converged_ratio", src,
        "Px:Pcx = 1:3 satisfies the chi-square test for the given grid sigma 0.7 um", v, sp,
        "predicted", "P_cx/P_x after the paper's re-weighting (P_cx <- s0^2/sigma_g^2, iterated to "
        "its fixed point; P_x = 1), mean of the four adjustments (x', y' on two plates) of one "
        f"calibration; {int((~fin).sum())} of {T} calibrations had no positive fixed point. "
        f"The true ratio is sx^2/sg^2 = {cfg['comparator.coord_sigma_um'] ** 2 / max(cfg['grid.sigma_true_um'], 1e-9) ** 2:.2f}. "
        "The ref interval 2.5-3.5 is the paper's integer 3.",
        ref=(2.5, 3.5), interval="spread"))
    pr = res["passes_rw"].ravel()
    m, ci = mean_ci(pr.astype(float))
    rows.append(claim(
        "twoplate.weight_ratio.pass_rate_after_reweighting", src,
        "(the re-weighted adjustment satisfies the chi-square test)", m, ci, "predicted",
        "fraction of adjustments whose chi-square test of the implied grid variance passes after "
        "re-weighting: the re-weighting forces s0^2/P_cx to the stated value, so the test passes "
        "by construction and cannot check the stated grid sigma. Only the sum sx'^2 + sg^2 is "
        "estimable from one plate (one misclosure per point and coordinate)."))
    v, sp = spread(res["sim_sigma_um"])
    rows.append(claim(
        "twoplate.similarity_vs_affine.similarity_sigma_um", src,
        "rigid-body transformation with a scale factor: standard error 1.65 um", v, sp,
        "predicted", "sqrt(sum(vx^2+vy^2)/(2N-4)) of a 4-parameter fit to the mean readings, "
        "grid fixed, pooled over the two plates: the affine sigma plus, in quadrature, the "
        "systematic part. The comparator's scale difference "
        f"({cfg['comparator.scale_diff_ppm']:g} ppm) and non-orthogonality "
        f"({cfg['comparator.nonorth_arcsec']:g}\") are not printed; they were set so the "
        "systematic part is the paper's implied 0.69 um, so this value is low by as much as "
        "the affine sigma is.", ref=rounding(1.65, 2), interval="spread"))
    v, sp = spread(res["aff_sigma_um"])
    rows.append(claim(
        "twoplate.similarity_vs_affine.affine_sigma_um", src,
        "with scale and non-orthogonality corrected, grid error-free: 1.5 um", v, sp, "predicted",
        "sqrt(sum(vx^2+vy^2)/(2N-6)) of the affine fit, grid fixed; expectation "
        "sqrt(sx'^2 + sg^2) = "
        f"{np.hypot(cfg['comparator.coord_sigma_um'], cfg['grid.sigma_true_um']):.2f} um from the "
        "paper's own 1.2 and 0.7 um; the paper's 1.5 implies sx' = 1.33 um instead.",
        ref=rounding(1.5, 1), interval="spread"))
    lin_sys = res["sim_sigma_um"] - res["aff_sigma_um"]
    v, sp = spread(lin_sys)
    rows.append(claim(
        "twoplate.similarity_vs_affine.scale_share_linear_um", src,
        "0.15 um error is due to a systematic error in scale and non-orthogonality", v, sp,
        "predicted", "difference of the standard errors (the paper's linear subtraction) similarity "
        "minus affine; follows from the chosen amplitudes. Independent errors add in quadrature: "
        "see scale_share_quadrature_um.", ref=rounding(0.15, 2), interval="spread"))
    lin_grid = res["aff_sigma_um"] - res["comp_sigma_um"]
    v, sp = spread(lin_grid)
    rows.append(claim(
        "twoplate.similarity_vs_affine.grid_share_linear_um", src,
        "the residual of 0.3 um is due to errors in grid coordinates", v, sp, "predicted",
        "affine sigma (grid fixed) minus the comparator sigma from the re-weighted combined "
        "adjustment, the paper's linear subtraction. With the paper's own 1.2 and 0.7 um the "
        "affine sigma is sqrt(1.2^2 + 0.7^2) = 1.39 um, so this difference is about 0.19 um; "
        "the paper's 0.3 = 1.5 - 1.2 inherits its affine 1.5 um, which is not consistent with "
        "1.2 and 0.7 under independent errors. (In quadrature the grid share is the stated grid "
        "sigma by construction of the re-weighting, so it is not reported as a result.)",
        ref=rounding(0.3, 1), interval="spread"))
    q_sys = np.sqrt(np.maximum(res["sim_sigma_um"] ** 2 - res["aff_sigma_um"] ** 2, 0))
    v, sp = spread(q_sys)
    rows.append(claim(
        "twoplate.similarity_vs_affine.scale_share_quadrature_um", src,
        "(implied: the paper's 1.65 and 1.5 um give sqrt(1.65^2 - 1.5^2) = 0.69 um)", v, sp,
        "input", "sqrt(sigma_sim^2 - sigma_aff^2): the rms the scale difference and "
        "non-orthogonality add to each coordinate. The two amplitudes (not printed) were set "
        "to give this value; the ref is derived from the paper's two printed sigmas, not "
        "printed itself.", ref=(0.685, 0.695), interval="spread"))
    v, sp = spread(res["comp_sigma_um"])
    rows.append(claim(
        "twoplate.comparator_sigma.sigma_um", src,
        "the standard error in both x and y comparator coordinates is obtained as 1.2 um", v, sp,
        "input", "s0 (P_x = 1) of the re-weighted combined adjustment, x' and y' on both plates "
        f"pooled ({4 * (cfg['plate.grid'] ** 2 - 3)} degrees of freedom); the truth is an input "
        f"({cfg['comparator.coord_sigma_um']:g} um), so this shows the estimator's spread for one "
        "calibration. With L readings of 1.5 um the mean alone would be "
        f"{cfg['readings.sigma_um'] / np.sqrt(cfg['readings.count']):.2f} um; the rest is a "
        "per-point comparator error.", ref=rounding(1.2, 1), interval="spread"))
    # beyond the paper
    for i in range(len(beyond["param"])):
        k, meth, u = beyond["param"][i], beyond["method"][i], beyond["unit"][i]
        tag = "fixed" if meth.startswith("grid fixed") else "weighted"
        kk = {"S": "S", "S'": "S2", "eps": "eps"}[k]
        rows.append(claim(
            f"twoplate.beyond.{tag}.bias_{kk}_{u}", "beyond the paper",
            "(no statement)", beyond["bias"][i], (beyond["bias_lo"][i], beyond["bias_hi"][i]),
            "predicted", f"mean error of {k} ({meth}) over {2 * T} plates; the combined "
            "adjustment gives the same estimates as the affine fit to ~1e-10 (equal weights on "
            "all points), so bias and spread are the same."))
        rows.append(claim(
            f"twoplate.beyond.{tag}.sd_{kk}_{u}", "beyond the paper",
            "(no statement)", beyond["sd"][i], (beyond["sd_lo"][i], beyond["sd_hi"][i]),
            "predicted", f"standard deviation of {k} ({meth}) over plates (chi-square CI)."))
    for k in PARAMS:
        for tag, lab in (("fixed_pri", "grid fixed, a-priori comparator sigma"),
                         ("fixed_post", "grid fixed, a-posteriori s0"),
                         (f"wpri_r{j_true}", f"weighted 1:{ratios[j_true]:g}, a-priori sigma"),
                         (f"wpost_r{j_true}", f"weighted 1:{ratios[j_true]:g}, a-posteriori s0")):
            x = res[f"{k}_cov_{tag}"].ravel().astype(float)
            m, ci = mean_ci(x)
            short = tag.replace(f"_r{j_true}", "")
            rows.append(claim(
                f"twoplate.beyond.coverage_{k}_{short}", "beyond the paper",
                "(stated 95 % interval)", m, ci, "predicted",
                f"fraction of plates whose interval {PARAM_LABEL[k]} +- 1.96 sd contains the "
                f"truth; {lab}. " + ("Ignoring the grid errors with an a-priori sigma makes the "
                                     "interval too narrow." if tag == "fixed_pri" else "")))
    return rows


# ----------------------------------------------------------------------------- report


def _claims_by_name(out: Path) -> dict:
    t = read_table(out / "claims.parquet").to_pylist()
    return {r["claim"]: r for r in t}


def report(out: Path) -> str:
    prov = read_provenance(out / "claims.parquet")
    cfg = prov["config"]
    name = out.name
    c = _claims_by_name(out)

    def v(k, f="value"):
        r = c.get(k)
        return fmt(r[f]) if r is not None else "n/a"

    cov = read_table(out / "coverage.parquet").to_pydict()
    ch = read_table(out / "chi2_power.parquet").to_pydict()
    be = read_table(out / "beyond.parquet").to_pydict()
    imp = read_table(out / "implied_grid.parquet").to_pydict()
    k = cfg["plate.grid"]
    txt = [
        f"Simulated calibrations of a comparator with {cfg['plate.count']} grid plates of "
        f"{k} x {k} points at {cfg['plate.spacing_mm']:g} mm (the paper prints neither), each "
        f"on its carrier with |kappa| <= {cfg['plate.kappa_deg']:g} deg, {cfg['readings.count']} "
        f"readings per point of {cfg['readings.sigma_um']:g} um, a mean comparator coordinate "
        f"of {cfg['comparator.coord_sigma_um']:g} um, grid coordinates of "
        f"{cfg['grid.sigma_true_um']:g} um (stated {cfg['grid.sigma_stated_um']:g} um), "
        f"{cfg['trials']} calibrations (seed {cfg['seed']}). The paper's numbers describe one "
        "calibration, so most values are medians with the 95 % range over simulated "
        "calibrations.",
        "",
        "**Model choices.** Grid -> comparator affine `x' = A1 x + B1 y + c1`, "
        "`y' = A2 x + B2 y + c2` (the paper's equation 2). Decomposition in the paper's "
        "convention (rows): `S = 1/sqrt(A1^2+B1^2)`, `S' = 1/sqrt(A2^2+B2^2)`, "
        "`phi = atan(B1/A1)`, `phi' = atan(B2/A2)`, `phi' - phi = pi/2 - eps`. The combined "
        "adjustment carries `(A, B, C)` and the adjusted grid coordinates of every point as "
        "unknowns, one comparator coordinate at a time (2N + 3 unknowns, N - 3 redundancy), "
        "Gauss-Newton with the point blocks eliminated. The rows of x' and y' are adjusted "
        "apart, as in the paper; their covariance is taken block diagonal (the shared grid "
        "errors correlate them by A1 A2 + B1 B2 ~ 0).",
        "",
        "**Variance-component estimator.** The paper re-weights `P_x : P_cx` until the "
        "chi-square test of the implied grid variance `s0^2 / P_cx` against the stated one "
        "passes. With `P_x = 1` held fixed this is a one-component estimate: the grid component "
        "is held at its stated value and the comparator component is `s0^2`. Each point gives "
        "one condition per coordinate whose misclosure has variance `sx'^2 + (A^2+B^2) sg^2`, so "
        "only that sum is estimable from the residuals; the fixed point of the re-weighting is "
        "the subtraction estimate `sx'^2 = s_w^2 - sg^2` (a full Helmert two-group estimate is "
        "not unique here). The code jumps to that fixed point (the paper's plain iteration "
        "converges to it with factor 1/(1 + P_cx) per round). Consequence: after re-weighting "
        "the chi-square test passes by construction; it cannot confirm the stated grid sigma. "
        "Tested with fixed a-priori weights instead, it detects a wrong stated grid sigma only "
        "when the total variance changes enough (figure below).",
        "",
        "**Findings.** (1) The paper's pair 1:2 -> 0.8 um and 1:3 -> 0.7 um follows from its "
        f"own 1.2 um and 0.7 um (simulated medians {v('twoplate.weight_ratio.grid_sigma_1to2_um')} "
        f"and {v('twoplate.weight_ratio.grid_sigma_1to3_um')} um); the re-weighting converges to "
        f"P_cx:P_x = {v('twoplate.weight_ratio.converged_ratio')} (median). (2) After "
        "re-weighting the chi-square test passes by construction, so it does not validate the "
        "stated grid sigma; only the sum of the comparator and grid variances is estimable. "
        "(3) The paper's affine 1.5 um is not consistent with its 1.2 and 0.7 um: these give "
        f"{v('twoplate.similarity_vs_affine.affine_sigma_um')} um (median), and so the linear "
        f"grid share is {v('twoplate.similarity_vs_affine.grid_share_linear_um')} um, not 0.3 um. "
        "(4) Weighting the grid does not change the estimates of S, S' and eps (bias and spread "
        "identical); it only changes the stated intervals: the grid taken as error-free with "
        f"the comparator's own sigma covers the truth {v('twoplate.beyond.coverage_eps_fixed_pri')}"
        " of the time for eps instead of 0.95; with the weights at the true ratio, "
        f"{v('twoplate.beyond.coverage_eps_wpri')}.",
        "",
        claims_markdown(out / "claims.parquet"),
        "",
        inputs_markdown(cfg, SCHEMA),
        "",
        "**Grid sigma implied by the weight ratio** (`s0/sqrt(P_cx)`, median and 95 % range):",
        "",
        md_table(["P_cx : P_x", "median (um)", "95 % range (um)"],
                 [[fmt(r), fmt(m), f"{fmt(lo)}-{fmt(hi)}"] for r, m, lo, hi in
                  zip(imp["ratio"], imp["median"], imp["lo"], imp["hi"])]),
        "",
        f"![implied grid sigma]({name}/implied_grid.png)",
        "",
        "**Beyond the paper: grid fixed versus weighted.** Errors of the recovered parameters "
        "(estimate minus truth) over all simulated plates; `stated sd` is the rms of the "
        "stated standard deviations (grid fixed: a-posteriori s0; weighted: a-priori weights).",
        "",
        md_table(["parameter", "method", "bias", "95 % CI", "sd", "stated sd (a-post.)", "unit"],
                 [[p, m, fmt(b), f"[{fmt(lo)}, {fmt(hi)}]", fmt(s), fmt(st), u]
                  for p, m, b, lo, hi, s, st, u in zip(be["param"], be["method"], be["bias"],
                                                       be["bias_lo"], be["bias_hi"], be["sd"],
                                                       be["stated_sd_rms"], be["unit"])]),
        "",
        "The estimates are the same whether the grid is fixed or weighted (equal weights on "
        "all points make the combined adjustment's parameters coincide with the affine fit's "
        "to second order in sigma/extent). What the weighting changes is the stated precision. "
        "Coverage of the nominal 95 % intervals:",
        "",
        md_table(["P_cx : P_x"] + [f"{PARAM_LABEL[k]} a-priori" for k in PARAMS]
                 + [f"{PARAM_LABEL[k]} a-post." for k in PARAMS],
                 [[fmt(r)] + [fmt(cov[f"{k}_pri"][i]) for k in PARAMS]
                  + [fmt(cov[f"{k}_post"][i]) for k in PARAMS] for i, r in enumerate(cov["ratio"])]
                 + [["grid fixed"] + [fmt(cov[f"{k}_fixed_pri"][0]) for k in PARAMS]
                    + [fmt(cov[f"{k}_fixed_post"][0]) for k in PARAMS]]),
        "",
        "With a-priori sigmas the coverage is right only at the true ratio `sx'^2/sg^2`; "
        "treating the grid as error-free with the comparator's own sigma makes the intervals "
        "too narrow. With the a-posteriori s0 the coverage is close to 95 % at every ratio "
        "(slightly below, since 1.96 is used with N - 3 degrees of freedom).",
        "",
        f"![coverage]({name}/coverage.png)",
        f"![parameters]({name}/parameters.png)",
        "",
        "**Chi-square test with a wrong stated grid sigma** (fixed a-priori weights "
        "`P_x = 1/sx'^2`, `P_cx = 1/sg_stated^2`, two-sided at "
        f"{cfg['analysis.alpha']:g}, one test per coordinate and plate):",
        "",
        md_table(["stated sigma (um)", "rejection rate", "95 % CI", "analytic"],
                 [[fmt(s), fmt(r), f"[{fmt(lo)}, {fmt(hi)}]", fmt(a)] for s, r, lo, hi, a in
                  zip(ch["stated_um"], ch["reject"], ch["lo"], ch["hi"], ch["analytic"])]),
        "",
        f"![chi-square]({name}/chi2_power.png)",
        "",
        "Residual vectors of one simulated calibration (plate 1):",
        "",
        f"![residuals]({name}/residuals.png)",
    ]
    return "\n".join(txt)


STUDIES = {
    "gridplate_two_plates": Study("gridplate_two_plates",
                                  "Calibration of a comparator with two grid plates", SEED,
                                  SCHEMA, run, report, check, order=20),
}
