"""Bayesian cross-checks with ``emcee`` (seed ``004``; the two-plate case after seed ``001``).

1. The posterior of Brown's 7 globals for one simulated plate of the paper's design (points
   marginalised analytically, :func:`sim.instruments.ranges.bayes.brown_log_posterior`) against the least-squares
   covariance.
2. The comparator / grid variance ratio of one simulated two-plate calibration
   (``gridplate_two_plates``'s default configuration) against the chi-square re-weighting.
   Its quantiles are computed by quadrature (:mod:`sim.instruments.ranges.twoplate_quad`):
   with log-uniform priors the ratio's posterior is flat between the prior's bounds, about
   12 decades wide, and a chain's autocorrelation time there is about 1000 steps (50 of them
   would take 50,000 steps). The chains stay beside it as the cross-check (their width and length).

Each posterior is ``bayes.chains`` independent ensembles, one chunk each (chunk size 1), so
they run in parallel on the run's executor and are stored for resumption. An MCMC estimate is
not reproducible to the last bit across machines (the BLAS's last bits change the chain's
path), so every number here carries its Monte-Carlo standard error from the integrated
autocorrelation time (``emcee``'s ``get_autocorr_time``): ``N_eff = kept steps x walkers /
tau`` summed over chains; ``se(sd) = sd / sqrt(2 N_eff)``; ``se(q_p) = sqrt(p (1-p) / N_eff) /
f(q_p)`` for a quantile.
"""

from __future__ import annotations

from functools import partial

import numpy as np

from sim.instruments import gridplate as gp
from sim.instruments import transforms2d as t2
from sim.instruments.ranges import multilateration as ml
from sim.instruments.ranges.twoplate_quad import log10_ratio_quantiles
from sim.mc.runner import chunk_rng, run_chunks
from sim.mc.workunits import chain_units
from sim.studies.design.chunks import brown_chain_chunk, brown_lsq, twoplate_chain_chunk

__all__ = ["bayes_analysis", "twoplate_analysis", "quantile_se", "PART_BROWN", "PART_TWOPLATE"]

PART_BROWN = 61
PART_TWOPLATE = (71, 72)


def _n_eff(sim: dict, k: int | None = None) -> np.ndarray:
    """Effective sample size per parameter, summed over the chains."""
    C, S, W = sim["samples"].shape[:3]
    return (S * W / sim["tau"]).sum(0) if k is None else (S * W / sim["tau"][:, k]).sum()


def quantile_se(x: np.ndarray, p: float, n_eff: float, dp: float = 0.01) -> float:
    """Monte-Carlo standard error of the ``p`` quantile of correlated samples ``x``."""
    lo, hi = np.quantile(x, [max(p - dp, 0.0), min(p + dp, 1.0)])
    dens = (min(p + dp, 1.0) - max(p - dp, 0.0)) / max(hi - lo, 1e-300)
    return float(np.sqrt(p * (1 - p) / n_eff) / dens)


def bayes_analysis(cfg: dict, pts: np.ndarray, sr_um: float, ctx) -> tuple[dict, dict, np.ndarray]:
    """Returns the per-parameter table, the values the claims need, and the pooled samples."""
    h = cfg["plate.format_mm"] / 2 + cfg["paper.offset_mm"]
    th = ml.design_theta(h, cfg["comparator.alpha_mm"], cfg["paper.beta_mm"])
    sig = sr_um * 1e-3
    r, theta_ls, Q = brown_lsq(pts, th, sig, chunk_rng(cfg["seed"], 60, 0))
    fn = partial(brown_chain_chunk, r, sig, theta_ls, Q, cfg["bayes.walkers"], cfg["bayes.steps"])
    units = chain_units(cfg["bayes.walkers"], cfg["bayes.steps"], "brown")
    sim = run_chunks(
        fn,
        cfg["bayes.chains"],
        cfg["seed"],
        1,
        part=PART_BROWN,
        label="emcee (Brown)",
        ctx=ctx,
        units=units,
    )
    X = sim["samples"].reshape(-1, sim["samples"].shape[-1])
    neff = _n_eff(sim)
    ps = X.std(0, ddof=1)
    lsd = np.sqrt(np.diag(Q))
    pc = np.corrcoef(X.T)
    lc = Q / np.outer(lsd, lsd)
    ratio = ps / lsd
    ratio_se = ratio / np.sqrt(2 * neff)
    diff = np.abs(pc - lc)
    i, j = np.unravel_index(np.argmax(diff), diff.shape)
    corr_se = float((1 - pc[i, j] ** 2) / np.sqrt(min(neff[i], neff[j])))
    chain_ratio = (
        np.stack([c.reshape(-1, c.shape[-1]).std(0, ddof=1) for c in sim["samples"]]) / lsd
    )
    names = list(ml.PARAM_NAMES)
    cols = {
        "param": names,
        "ls_estimate": theta_ls,
        "ls_sigma_mm": lsd,
        "post_mean": X.mean(0),
        "post_mean_se": ps / np.sqrt(neff),
        "post_sigma_mm": ps,
        "ratio": ratio,
        "ratio_se": ratio_se,
        "ratio_chain_spread": chain_ratio.std(0, ddof=1),
        "tau_steps": sim["tau"].mean(0),
        "n_eff": neff,
        "acceptance": np.full(len(names), float(sim["acceptance"].mean())),
        "max_abs_corr_diff": np.full(len(names), float(diff.max())),
    }
    vals = {
        "ratio": dict(zip(names, zip(ratio, ratio_se, sim["tau"].mean(0), neff))),
        # the shortest chain's kept steps in autocorrelation times of its slowest parameter
        "chain_tau": float((sim["samples"].shape[1] / sim["tau"].max(1)).min()),
        "kept": int(sim["samples"].shape[1]),
        "max_corr_diff": (float(diff.max()), corr_se, names[i], names[j]),
        "chains": cfg["bayes.chains"],
        "steps": cfg["bayes.steps"],
        "walkers": cfg["bayes.walkers"],
        "Q": Q,
        "theta_ls": theta_ls,
    }
    return cols, vals, X


#: the two-plate calibration of ``gridplate_two_plates``'s defaults (seed 001's setup)
TWO_PLATES = dict(
    grid=5,
    spacing_mm=40.0,
    plates=2,
    readings=4,
    scale_diff_ppm=15.0,
    nonorth_arcsec=3.8,
    kappa_deg=1.0,
    reading_sigma_um=1.5,
    coord_sigma_um=1.2,
    grid_sigma_um=0.7,
)
#: the certificate's stated sigma (um)
TWO_PLATES_STATED_UM = 0.7


def _twoplate_data(cfg: dict):
    """One simulated two-plate calibration (:data:`TWO_PLATES`)."""
    sim = gp.simulate_calibrations(chunk_rng(cfg["seed"], 70, 0), 1, **TWO_PLATES)
    mean = sim["readings"].mean(axis=3)[0]  # (plates, N, 2)
    cert = sim["cert"][0]
    comp = np.concatenate([mean[..., 0], mean[..., 1]], 0)  # rows x' (plates), y' (plates)
    g = np.concatenate([cert, cert], 0)
    sg = TWO_PLATES_STATED_UM
    rw = gp.reweight(comp, g, sg * 1e-3)
    fa = t2.fit_affine(cert, mean)
    return TWO_PLATES, comp, g, sg, rw, fa


def _twoplate_row(sim: dict, name: str, rw: dict, gcfg: dict, exact) -> tuple[dict, np.ndarray]:
    """One prior's row of ``bayes_twoplate.parquet``: the ratio's quantiles by quadrature
    (``exact``: :func:`~sim.instruments.ranges.twoplate_quad.log10_ratio_quantiles`), and the
    chains' own width, length and diagnostics beside them; and the chains' ratio samples."""
    Y = sim["samples"].reshape(-1, 2)
    lc, lg = Y[:, 0], Y[:, 1]
    lrho = 2 * (lc - lg) / np.log(10)  # log10 of the ratio
    neff = float(_n_eff(sim).min())
    q, err = exact
    cq = np.quantile(lrho, [0.025, 0.975])
    row = {"prior": name}
    for c, v in zip(("rho_q025", "rho_median", "rho_q975"), 10**q):
        row[c] = float(v)
    row["log10_width"] = float(q[2] - q[0])
    row["quad_err"] = float(err.max())
    row["chain_log10_width"] = float(cq[1] - cq[0])
    row["chain_log10_width_se"] = float(
        np.hypot(quantile_se(lrho, 0.025, neff), quantile_se(lrho, 0.975, neff))
    )
    # the shortest chain's kept steps in autocorrelation times of its slowest parameter
    row["chain_tau"] = float((sim["samples"].shape[1] / sim["tau"].max(1)).min())
    row["sigma_c_median_um"] = float(np.median(np.exp(lc)))
    row["sigma_g_median_um"] = float(np.median(np.exp(lg)))
    row["tau_max"] = float(sim["tau"].max())
    row["n_eff"] = neff
    row["rw_ratio_mean"] = float(np.nanmean(rw["ratio"]))
    row["true_ratio"] = (gcfg["coord_sigma_um"] / gcfg["grid_sigma_um"]) ** 2
    return row, 10**lrho


def twoplate_analysis(cfg: dict, ctx):
    """Posterior of sigma_c^2 / sigma_g^2 with flat and certificate priors. Returns
    ``(columns, values, samples, why)`` (``why`` is empty: kept for the callers)."""
    gcfg, comp, g, sg, rw, fa = _twoplate_data(cfg)
    R = comp.shape[0]
    abc = np.concatenate([fa.params[:, :3], fa.params[:, 3:]], 0)
    x0 = np.concatenate([abc.ravel(), [np.log(gcfg["coord_sigma_um"]), np.log(sg)]])
    sd = np.concatenate([np.tile([2e-5, 2e-5, 5e-4], R), [0.1, 0.3]])
    W = max(cfg["bayes.walkers"], 2 * len(x0) + 2)
    cols = {
        k: []
        for k in (
            "prior",
            "rho_q025",
            "rho_median",
            "rho_q975",
            "log10_width",
            "quad_err",
            "chain_log10_width",
            "chain_log10_width_se",
            "chain_tau",
            "sigma_c_median_um",
            "sigma_g_median_um",
            "tau_max",
            "n_eff",
            "rw_ratio_mean",
            "true_ratio",
        )
    }
    samples = {}
    for part, (name, prior) in zip(
        PART_TWOPLATE,
        (("flat", None), ("certificate", (np.log(sg), cfg["bayes.grid_prior_log_sd"]))),
    ):
        fn = partial(twoplate_chain_chunk, comp, g, prior, x0, sd, W, 2 * cfg["bayes.steps"])
        sim = run_chunks(
            fn,
            cfg["bayes.chains"],
            cfg["seed"],
            1,
            part=part,
            label=f"emcee (two plates, {name})",
            ctx=ctx,
            units=chain_units(cfg["bayes.walkers"], cfg["bayes.steps"], "twoplate"),
        )
        exact = log10_ratio_quantiles(comp, g, prior)
        row, samples[name] = _twoplate_row(sim, name, rw, gcfg, exact)
        for c, v in row.items():
            cols[c].append(v)
    vals = {"sg": sg, "rw_rows": [float(v) for v in rw["ratio"]]}
    return cols, vals, samples, ""
