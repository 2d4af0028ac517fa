"""The two-plate variance ratio's posterior by quadrature (no sampler).

Model: :func:`sim.instruments.ranges.bayes.twoplate_log_posterior` (seed
``001_7e3a2951e7fed426.txt``). Each row ``r`` of comparator coordinates has residuals
``comp - A gx - B gy - C ~ N(0, sigma_c^2 + (A^2 + B^2) sigma_g^2)``. With flat priors on
``(A, B, C)`` the three are integrated out exactly (a Gaussian integral; ``A^2 + B^2`` is held
at its least-squares value ``k_r``, which moves by about 1e-5 of itself over their posterior)::

    p(sigma_c, sigma_g | data) ∝ prod_r v_r^(-(N-3)/2) exp(-RSS_r / (2 v_r)) x prior,
    v_r = sigma_c^2 + k_r sigma_g^2

The change of variables ``(log sigma_c, log sigma_g) -> (log S, log rho)`` with
``S = sigma_c^2 + sigma_g^2`` and ``rho = sigma_c^2 / sigma_g^2`` has the constant Jacobian
1/4, so with log-uniform priors the posterior of ``log rho`` is the data's (narrow) posterior
of ``log S`` times a flat density over the part of the prior's box that line crosses: the
95 % interval of the ratio is then about 0.95 x 2 log10(S / sigma_min^2) decades wide, set
by the prior's bounds, not by the data. The posterior is summed on a grid in
``(log S, log rho)``; the quadrature error is the change from a grid of half the resolution.
"""

from __future__ import annotations

import numpy as np

__all__ = ["log10_ratio_quantiles"]

LN10 = np.log(10.0)


def _rows(comp: np.ndarray, grid: np.ndarray) -> tuple[np.ndarray, np.ndarray, int]:
    """Per row: the least-squares residual sum of squares (mm^2) and ``k = A^2 + B^2``."""
    R, N = comp.shape
    rss, k = np.empty(R), np.empty(R)
    for r in range(R):
        X = np.column_stack([grid[r, :, 0], grid[r, :, 1], np.ones(N)])
        beta, *_ = np.linalg.lstsq(X, comp[r], rcond=None)
        e = comp[r] - X @ beta
        rss[r], k[r] = e @ e, beta[0] ** 2 + beta[1] ** 2
    return rss, k, N


def _cdf(comp, grid, log_sg_prior, log_bounds, n_t: int, n_v: int):
    """The grid of ``log rho`` (natural log) and its marginal posterior CDF."""
    rss, k, N = _rows(comp, grid)
    lo, hi = log_bounds
    s_hat = rss.sum() / (len(rss) * (N - 3)) * 1e6  # um^2
    sd_t = np.sqrt(2.0 / (len(rss) * (N - 3)))
    t = np.log(s_hat) + np.linspace(-12 * sd_t, 12 * sd_t, n_t)  # log S
    v = np.linspace(2 * (lo - hi), 2 * (hi - lo), n_v)  # log rho
    T, V = t[:, None], v[None, :]
    ls2c = T + V - np.logaddexp(0.0, V)  # log sigma_c^2 (um^2)
    ls2g = T - np.logaddexp(0.0, V)
    lc, lg = ls2c / 2, ls2g / 2
    logp = np.zeros(np.broadcast_shapes(T.shape, V.shape))
    for r in range(len(rss)):
        var = (np.exp(ls2c) + k[r] * np.exp(ls2g)) * 1e-6  # mm^2
        logp += -0.5 * rss[r] / var - 0.5 * (N - 3) * np.log(var)
    if log_sg_prior is not None:
        logp -= 0.5 * ((lg - log_sg_prior[0]) / log_sg_prior[1]) ** 2
    inside = (lc > lo) & (lc < hi) & (lg > lo) & (lg < hi)
    logp = np.where(inside, logp, -np.inf)
    dens = np.exp(logp - logp.max()).sum(0)  # marginal of log rho (constant Jacobian)
    cdf = np.concatenate([[0.0], np.cumsum((dens[1:] + dens[:-1]) / 2)])
    return v, cdf / cdf[-1]


def _quantiles(comp, grid, log_sg_prior, log_bounds, ps, n_t, n_v) -> np.ndarray:
    v, cdf = _cdf(comp, grid, log_sg_prior, log_bounds, n_t, n_v)
    keep = np.concatenate([[True], np.diff(cdf) > 0])
    return np.interp(ps, cdf[keep], v[keep]) / LN10


def log10_ratio_quantiles(
    comp: np.ndarray,
    grid: np.ndarray,
    log_sg_prior: tuple | None = None,
    log_bounds: tuple[float, float] = (np.log(1e-3), np.log(1e3)),
    ps: tuple[float, ...] = (0.025, 0.5, 0.975),
    n_t: int = 241,
    n_v: int = 12001,
) -> tuple[np.ndarray, np.ndarray]:
    """The posterior quantiles ``ps`` of ``log10(sigma_c^2 / sigma_g^2)`` (arguments as
    :func:`sim.instruments.ranges.bayes.twoplate_log_posterior`), and each one's quadrature
    error (its change from a grid of half the resolution in both directions)."""
    comp, grid = np.asarray(comp, float), np.asarray(grid, float)
    fine = _quantiles(comp, grid, log_sg_prior, log_bounds, ps, n_t, n_v)
    coarse = _quantiles(comp, grid, log_sg_prior, log_bounds, ps, n_t // 2 + 1, n_v // 2 + 1)
    return fine, np.abs(fine - coarse)
