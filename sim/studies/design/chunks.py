"""Chunk functions of study ``brown_design`` (seed ``004``, Brown 1968).

Every function here is module-level and takes plain arguments first, so
``functools.partial(fn, *args)`` pickles: the runner sends it to process-pool or Dask workers
and stores each chunk for resumption. The last two arguments are always ``(rng, n)``: the
chunk's generator (:func:`sim.mc.runner.chunk_rng`) and its number of trials. Units: ranges and coordinates in mm
inside the solvers, errors in um in the outputs.
"""

from __future__ import annotations

import numpy as np

from sim.instruments.ranges import bayes, budget
from sim.instruments.ranges import coverage as cv
from sim.instruments.ranges import multilateration as ml
from sim.instruments.ranges import positions as po
from sim.lsq import datum as dm
from sim.lsq import distributions as D

__all__ = [
    "design_chunk",
    "budget_chunk",
    "coverage_chunk",
    "affine_chunk",
    "brown_chain_chunk",
    "twoplate_chain_chunk",
]


def _start(th: np.ndarray) -> np.ndarray:
    t0 = np.array(th, float)
    t0[-2:] = 0.0
    return t0


def design_chunk(pts, th, sigma_um, rng, n):
    """The paper's design in the P-position solver: coordinate errors (um) in the inner datum
    over the points, and the solver status per trial."""
    P = np.broadcast_to(pts, (n,) + pts.shape)
    TH = np.broadcast_to(th, (n, len(th)))
    noise = rng.normal(0.0, sigma_um, (n, len(pts), (len(th) - 2) // 2)) * 1e-3
    res = po.adjust(po.ranges(P, TH) + noise, "pivot", _start(th), "inner")
    e = ((res.points - P) * 1e3).reshape(n, -1) @ dm.inner(pts).T
    return {"err_um": e, "status": res.status}


def budget_chunk(bcfg, pts, th, sources, setting_sigma, settings, rng, n):
    """Ranges with the chosen error sources (:mod:`sim.instruments.ranges.budget`), pivot adjustment, mean square
    coordinate error after a rigid fit over all points (um^2), sigma0 (um).

    bcfg : plain dict with the ``budget.*`` amplitudes and ``comparator.sigma_um``.
    """
    S = dm.s_matrix(dm.null_basis(pts))
    P = np.broadcast_to(pts, (n,) + pts.shape)
    TH = np.broadcast_to(th, (n, len(th)))
    r = po.ranges(P, TH)
    psi = po.arm_angles(P, TH)
    e = np.zeros_like(r)
    if setting_sigma > 0:
        e += rng.normal(0.0, setting_sigma, r.shape + (settings,)).mean(-1)
    for s in sources:
        e += (
            rng.normal(0.0, bcfg["comparator.sigma_um"], r.shape)
            if s == "comparator"
            else budget.source_error(s, r, psi, rng, bcfg)
        )
    res = po.adjust(r + e * 1e-3, "pivot", _start(th), "inner")
    err = ((res.points - P) * 1e3).reshape(n, -1) @ S.T
    ok = res.status == 0
    return {"ms_um2": np.where(ok, (err**2).mean(1), np.nan), "s0_um": res.sigma0 * 1e3, "ok": ok}


def coverage_chunk(pts, th, sigma_um, alpha_test, rng, T):
    """Pivot model in Brown's datum (Brown's 7 globals, :mod:`sim.instruments.ranges.multilateration`: its
    compiled kernel, the same adjustment as :mod:`sim.instruments.ranges.positions` in the ``brown`` datum):
    per-point 95 % ellipse coverage (known sigma; s0 with F), the global chi-square test,
    sigma0 (um) and the b = beta^2 / beta intervals."""
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):  # flagged trials
        n = len(pts)
        dof = 4 * n - (2 * n + 7)
        zq = D.norm_ppf(0.975)
        thp = po.from_brown_theta(th)
        Pt = np.broadcast_to(pts, (T,) + pts.shape)
        TH = np.broadcast_to(thp, (T, 10))
        r = po.ranges(Pt, TH) + rng.normal(0.0, sigma_um * 1e-3, (T, n, 4))
        t0 = np.array(th, float)
        t0[5:] = 0.0
        res = ml.adjust(r, "pivot", t0, max_iter=60)
        Qpp, Qgg = ml.covariance(res.points, res.theta, "pivot")[:2]
        e = (res.points - Pt) * 1e3
        s0 = res.sigma0 * 1e3
        ink = cv.ellipse_inside(e, Qpp, sigma=sigma_um).mean(1)
        inf_ = cv.ellipse_inside(e, Qpp, s0=s0, dof=dof).mean(1) if dof > 0 else np.full(T, np.nan)
        sb = sigma_um * 1e-3 * np.sqrt(Qgg[:, -1, -1])
        b_in = np.abs(res.theta[:, -1] - th[6]) <= zq * sb
        bhat = np.sqrt(np.maximum(res.theta[:, -1], 0.0))
        sbeta = sb / (2 * np.maximum(bhat, 1e-300))
        beta_in = np.abs(bhat - np.sqrt(th[6])) <= zq * sbeta
        rej = cv.chi2_reject(s0, sigma_um, dof, alpha_test) if dof > 0 else np.zeros(T, bool)
    return {
        "ok": res.status == 0,
        "status": res.status,
        "cov_known": ink,
        "cov_f": inf_,
        "reject": rej,
        "s0_um": s0,
        "b_in": b_in,
        "beta_in": beta_in,
    }


def affine_chunk(grid, sigma_um, aff, alpha_test, rng, n):
    """Affine calibration (linear model, seed 001): the same statistics as
    :func:`coverage_chunk` (no b / beta)."""
    r = cv.affine_trials(rng, n, grid, sigma_um, aff)
    Q = np.broadcast_to(r["leverage"][:, None, None] * np.eye(2), (len(grid), 2, 2))
    return {
        "cov_known": cv.ellipse_inside(r["err_um"], Q, sigma=sigma_um).mean(1),
        "cov_f": cv.ellipse_inside(r["err_um"], Q, s0=r["s0_um"], dof=r["dof"]).mean(1),
        "reject": cv.chi2_reject(r["s0_um"], sigma_um, r["dof"], alpha_test),
        "s0_um": r["s0_um"],
        "ok": np.ones(n, bool),
        "status": np.zeros(n, np.int8),
        "b_in": np.full(n, np.nan),
        "beta_in": np.full(n, np.nan),
    }


def _emcee_seed(rng) -> np.random.SeedSequence:
    return np.random.SeedSequence(int(rng.integers(0, 2**63 - 1)))


def brown_chain_chunk(r_obs, sig_mm, theta_ls, Q, walkers, steps, rng, n):
    """One independent emcee ensemble (one chunk of ``n = 1``) for Brown's 7 globals of one
    plate, started from the least-squares estimate and covariance. Returns the kept samples
    ``(1, S, W, 7)`` (step, walker, parameter), the integrated autocorrelation times
    (``emcee``'s ``get_autocorr_time``) and the acceptance."""
    if n != 1:
        raise ValueError("an emcee chunk is one chain: chunk size 1")
    p0 = rng.multivariate_normal(theta_ls, Q, size=walkers)
    ch = bayes.run_emcee(bayes.brown_log_posterior(r_obs, sig_mm), p0, steps, _emcee_seed(rng))
    S = ch.samples.shape[0] // walkers
    return {
        "samples": ch.samples.reshape(1, S, walkers, -1),
        "tau": ch.tau[None],
        "acceptance": np.array([ch.acceptance]),
    }


def twoplate_chain_chunk(comp, grid, prior, x0, sd, walkers, steps, rng, n):
    """One emcee ensemble of the two-plate variance components (seed 001); keeps only
    ``log sigma_c`` and ``log sigma_g`` ``(1, S, W, 2)``."""
    if n != 1:
        raise ValueError("an emcee chunk is one chain: chunk size 1")
    p0 = x0 + rng.normal(size=(walkers, len(x0))) * sd
    lp = bayes.twoplate_log_posterior(comp, grid, prior)
    ch = bayes.run_emcee(lp, p0, steps, _emcee_seed(rng))
    S = ch.samples.shape[0] // walkers
    return {
        "samples": ch.samples[:, -2:].reshape(1, S, walkers, 2),
        "tau": ch.tau[None, -2:],
        "acceptance": np.array([ch.acceptance]),
    }


def brown_lsq(pts, th, sig_mm, rng):
    """One simulated plate of the paper's design (Brown's 4-station model): observed ranges,
    least-squares globals and their covariance (mm^2)."""
    r = ml.ranges(pts[None], th[None])[0] + rng.normal(0.0, sig_mm, (len(pts), 4))
    t0 = np.array(th, float)
    t0[5:] = 0.0
    ls = ml.adjust(r[None], "pivot", t0)
    Q = ml.covariance(ls.points, ls.theta, "pivot")[1][0] * sig_mm**2
    return r, ls.theta[0], Q
