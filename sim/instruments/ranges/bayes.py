"""Bayesian cross-check of the least-squares calibrations with ``emcee``.

Seed: ``004_f5bd9e86c308241f.txt`` (Brown 1968). For one simulated plate the posterior of
Brown's 7 global parameters (``y1, x2, y2, y3, x4, alpha, b = beta^2``; Brown's datum) is
sampled with the affine-invariant ensemble sampler. The ``2n`` point coordinates are
**marginalised analytically**: with flat priors on the points and the globals and a known
range sigma, the points enter each range almost linearly (ranges of 100-300 mm, errors of
1 um), so for given globals the integral over each point is the Laplace (Gaussian) integral

    p(theta | r) ∝ exp(-RSS_min(theta) / (2 sigma^2)) prod_j det(N_j(theta))^(-1/2)

with ``RSS_min`` the residual sum of squares after adjusting the points with the globals held
(the ``known`` model of :mod:`sim.instruments.ranges.multilateration`) and ``N_j`` each point's 2x2 normal
matrix. The prior on ``b`` (not on ``beta``) is flat, so ``b`` may be negative.

Randomness: the sampler's legacy ``RandomState`` is seeded from an explicit
``numpy.random.SeedSequence`` (emcee 3 draws from its own ``RandomState``). The chains run on
:func:`sim.instruments.ranges.ensemble.stretch_chain`, emcee's algorithm step for step (the same chain for the
same seed) without emcee's per-walker Python bookkeeping.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from sim.instruments.ranges import multilateration as ml
from sim.instruments.ranges import positions as po
from sim.instruments.ranges.autocorr import ensemble_time
from sim.instruments.ranges.ensemble import stretch_chain

__all__ = ["Chain", "run_emcee", "brown_log_posterior", "linear_log_posterior"]


@dataclass
class Chain:
    """Flattened posterior samples ``(N, d)`` after burn-in and thinning, with diagnostics."""

    samples: np.ndarray
    tau: np.ndarray  # integrated autocorrelation time per parameter (steps; autocorr.py)
    n_eff: float  # independent samples: kept steps x walkers / max(tau)
    acceptance: float
    steps: int
    walkers: int
    burn: int


def run_emcee(
    log_prob: Callable[[np.ndarray], np.ndarray],
    p0: np.ndarray,
    steps: int,
    seed: np.random.SeedSequence,
    burn: int | None = None,
    engine: str = "vectorised",
) -> Chain:
    """Run emcee's ensemble sampler (stretch move, vectorised log-probability over walkers).

    p0 : (walkers, d) initial positions. ``burn`` defaults to a quarter of ``steps``.
    engine : ``vectorised`` (:func:`sim.instruments.ranges.ensemble.stretch_chain`, emcee's algorithm step for
    step without its per-walker Python loop: the same chain) or ``emcee``
    (``emcee.EnsembleSampler`` itself, the reference).
    """
    W, d = p0.shape
    rs = np.random.RandomState(np.random.MT19937(seed))
    if engine == "vectorised":
        chain, _, n_acc = stretch_chain(log_prob, p0, steps, rs)
        acceptance = n_acc / float(steps)
    elif engine == "emcee":
        import emcee

        sampler = emcee.EnsembleSampler(W, d, log_prob, vectorize=True)
        sampler.random_state = rs.get_state()
        sampler.run_mcmc(p0, steps, progress=False)
        chain, acceptance = sampler.get_chain(), sampler.acceptance_fraction
    else:
        raise ValueError(f"engine must be vectorised or emcee, not {engine!r}")
    burn = steps // 4 if burn is None else burn
    tau = ensemble_time(chain[burn:])
    kept = chain[burn:].reshape(-1, d)
    n_eff = (steps - burn) * W / float(np.max(tau))
    return Chain(kept, tau, n_eff, float(np.mean(acceptance)), steps, W, burn)


def linear_log_posterior(A: np.ndarray, y: np.ndarray, sigma: float):
    """Flat-prior posterior of ``y = A x + N(0, sigma^2)``; analytic: N(x_hat, sigma^2 (A^T A)^-1)."""

    def lp(x: np.ndarray) -> np.ndarray:
        r = y[None, :] - x @ A.T
        return -0.5 * np.einsum("wi,wi->w", r, r) / sigma**2

    return lp


def brown_log_posterior(r_obs: np.ndarray, sigma_mm: float, tol_mm: float = 1e-11):
    """Log posterior of the 7 globals of one plate, points marginalised (Laplace).

    r_obs : (n, 4) observed ranges, mm. Returns ``lp(theta (W, 7)) -> (W,)``.
    """
    r_obs = np.asarray(r_obs, float)

    model = po.RangeModel(None, ml.BROWN_LAYOUT, P=4)

    def lp(theta: np.ndarray) -> np.ndarray:
        W = theta.shape[0]
        R = np.broadcast_to(r_obs, (W,) + r_obs.shape)
        res = ml.adjust(R, "known", theta, tol_mm=tol_mm, max_iter=20)
        rss = np.einsum("tnk,tnk->t", res.residuals, res.residuals)
        # the point cofactors Qpp = Npp^-1 of the known model (the engine's 2x2 inverse)
        Jp = model.linearize(res.points, theta, False).Jp
        Npp = np.swapaxes(Jp, -1, -2) @ Jp
        a, b, c = Npp[..., 0, 0], Npp[..., 0, 1], Npp[..., 1, 1]
        inv = 1.0 / (a * c - b * b)
        logdetQ = np.log(np.maximum((c * inv) * (a * inv) - (-b * inv) ** 2, 1e-300)).sum(1)
        out = -0.5 * rss / sigma_mm**2 + 0.5 * logdetQ
        return np.where(res.converged & np.isfinite(out), out, -np.inf)

    return lp


def twoplate_log_posterior(
    comp: np.ndarray,
    grid: np.ndarray,
    log_sg_prior: tuple | None = None,
    log_bounds: tuple[float, float] = (np.log(1e-3), np.log(1e3)),
):
    """Variance components of the two-plate comparator calibration (seed
    ``001_7e3a2951e7fed426.txt``): posterior of each row's affine parameters ``(A, B, C)`` and
    of ``log sigma_c`` (comparator) and ``log sigma_g`` (grid coordinates), both in um.

    comp : (R, N) comparator coordinates (mm) of ``R`` rows (x' and y' of each plate);
    grid : (R, N, 2) the grid coordinates as given (mm). The true grid coordinates are
    integrated out exactly (flat prior; the model is linear in them)::

        comp_i - A gx_i - B gy_i - C  ~  N(0, sigma_c^2 + (A^2 + B^2) sigma_g^2)

    so the data constrain the sum, not the ratio, of the two variances. Priors: flat on
    ``A, B, C``; ``log sigma`` uniform within ``log_bounds``; optionally
    ``log sigma_g ~ N(mu, s^2)`` with ``log_sg_prior = (mu, s)`` (a certificate value).
    Parameter vector: ``A_1, B_1, C_1, ..., A_R, B_R, C_R, log sigma_c, log sigma_g``.
    """
    comp = np.asarray(comp, float)
    grid = np.asarray(grid, float)
    R = comp.shape[0]

    def lp(x: np.ndarray) -> np.ndarray:
        W = x.shape[0]
        abc = x[:, : 3 * R].reshape(W, R, 3)
        lc, lg = x[:, -2], x[:, -1]
        w = (
            comp[None]
            - abc[..., 0, None] * grid[None, ..., 0]
            - abc[..., 1, None] * grid[None, ..., 1]
            - abc[..., 2, None]
        )  # (W, R, N)
        var = (
            np.exp(2 * lc)[:, None]
            + (abc[..., 0] ** 2 + abc[..., 1] ** 2) * np.exp(2 * lg)[:, None]
        ) * 1e-6  # mm^2
        out = (-0.5 * (w**2).sum(-1) / var - 0.5 * comp.shape[1] * np.log(var)).sum(-1)
        if log_sg_prior is not None:
            out = out - 0.5 * ((lg - log_sg_prior[0]) / log_sg_prior[1]) ** 2
        inside = (
            (lc > log_bounds[0])
            & (lc < log_bounds[1])
            & (lg > log_bounds[0])
            & (lg < log_bounds[1])
        )
        return np.where(inside, out, -np.inf)

    return lp
