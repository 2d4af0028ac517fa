"""Formal against empirical: coverage of confidence ellipses, chi-square test, sigma0 bias.

Seeds: ``004_f5bd9e86c308241f.txt`` (Brown's ``pivot`` model, whose "rigorous error
propagation" gives the point covariances) and the affine comparator calibration of
``001_7e3a2951e7fed426.txt`` / ``002_fb81c7b0481438c4.txt`` (a linear model, for which the
formal statements are exact and the Monte Carlo must reproduce them).

For a point error ``e`` (2-vector) with formal covariance ``sigma^2 Q``:

* known sigma: ``e^T Q^-1 e / sigma^2 ~ chi2(2)``: the 95 % ellipse covers the truth when the
  statistic is below ``chi2.ppf(0.95, 2)``;
* estimated sigma0 (``dof`` degrees of freedom): ``e^T Q^-1 e / (2 s0^2) ~ F(2, dof)``.

Global test of the adjustment: reject when ``dof s0^2 / sigma^2 > chi2.ppf(1 - alpha, dof)``;
for a correct linear model the rejection (false-alarm) rate is ``alpha``. ``E[s0^2] = sigma^2``
for a linear model; ``s0`` itself is biased low by the factor ``c4(dof + 1)``.
"""

from __future__ import annotations

import numpy as np
from scipy import special

from sim.lsq import distributions as D
from sim.lsq.linear import lstsq

__all__ = [
    "mahalanobis2",
    "ellipse_inside",
    "chi2_reject",
    "c4",
    "affine_trials",
    "binomial_se",
    "result_inside",
]


def mahalanobis2(e: np.ndarray, Q: np.ndarray) -> np.ndarray:
    """``e^T Q^-1 e`` for ``e`` ``(..., 2)`` and ``Q`` ``(..., 2, 2)`` (closed-form 2x2 inverse)."""
    a, b, c = Q[..., 0, 0], Q[..., 0, 1], Q[..., 1, 1]
    det = a * c - b * b
    x, y = e[..., 0], e[..., 1]
    return (c * x * x - 2 * b * x * y + a * y * y) / det


def ellipse_inside(
    e: np.ndarray,
    Q: np.ndarray,
    sigma: float | np.ndarray | None = None,
    s0: np.ndarray | None = None,
    dof: int | None = None,
    level: float = 0.95,
) -> np.ndarray:
    """Whether each error ``e`` ``(T, n, 2)`` lies inside its ``level`` ellipse.

    Give ``sigma`` (known, same units as ``e``) or ``s0`` ``(T,)`` with ``dof``.
    """
    m2 = mahalanobis2(e, Q)
    if s0 is not None:
        return m2 / (2 * s0[:, None] ** 2) <= D.f_ppf(level, 2, dof)
    return m2 / np.asarray(sigma) ** 2 <= D.chi2_ppf(level, 2)


def result_inside(
    result, truth: np.ndarray, sigma: float | None = None, level: float = 0.95
) -> np.ndarray:
    """Ellipse coverage of an engine result (:class:`sim.lsq.Result`): whether each adjusted
    point's error ``result.points - truth`` ``(T, n, 2)`` lies inside its ``level`` ellipse
    from the result's point cofactors; known ``sigma`` (the units of the points) or, if None,
    the result's ``sigma0`` and ``dof``."""
    e = result.points - truth
    Q = result.point_cofactors()
    if sigma is None:
        return ellipse_inside(e, Q, s0=result.sigma0, dof=result.dof, level=level)
    return ellipse_inside(e, Q, sigma=sigma, level=level)


def chi2_reject(s0: np.ndarray, sigma: float, dof: int, alpha: float = 0.05) -> np.ndarray:
    """Global chi-square test of the a-posteriori variance: True where rejected."""
    return dof * (s0 / sigma) ** 2 > D.chi2_ppf(1 - alpha, dof)


def c4(n: int) -> float:
    """``E[s] / sigma`` for a sample variance on ``n - 1`` degrees of freedom."""
    return float(
        np.sqrt(2.0 / (n - 1)) * np.exp(special.gammaln(n / 2) - special.gammaln((n - 1) / 2))
    )


def binomial_se(p: float, n: int) -> float:
    return float(np.sqrt(max(p * (1 - p), 1e-12) / n))


def affine_trials(
    rng: np.random.Generator, T: int, grid: np.ndarray, sigma_um: float, affine: np.ndarray
) -> dict[str, np.ndarray]:
    """Affine calibration of a comparator on a grid plate, ``T`` trials (linear model).

    grid : (n, 2) mm, the reference coordinates (exact); the comparator reads
    ``M grid + t + noise`` (noise N(0, sigma_um^2) per coordinate); the 6 affine parameters
    are fitted by least squares. Returns per trial the errors of the fitted positions
    ``(T, n, 2)`` um, their cofactors (leverages) ``(n,)``, s0 (um) and dof.
    """
    n = len(grid)
    G = np.column_stack([grid, np.ones(n)])  # (n, 3) design of each row
    M = np.asarray(affine, float).reshape(2, 3)
    truth = G @ M.T  # (n, 2) mm
    noise = rng.normal(0.0, sigma_um, size=(T, n, 2))  # um
    obs = truth[None] + noise * 1e-3
    f = lstsq(G, obs)  # shared design: factorised once
    p = f.x  # (T, 3, 2)
    fit = np.einsum("nk,tkc->tnc", G, p)
    dof = 2 * n - 6
    s0 = f.s0 * 1e3
    lev = np.einsum("nk,kl,nl->n", G, f.cofactor()[0], G)  # diag of the hat matrix
    return {
        "err_um": (fit - truth[None]) * 1e3,
        "leverage": lev,
        "s0_um": s0,
        "dof": dof,
        "param_err": p - M.T[None],
    }
