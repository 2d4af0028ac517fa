"""Confidence intervals of sample statistics over Monte-Carlo trials.

Normal-theory interval of a mean, chi-square interval of a standard deviation (exact for
Gaussian samples: ``(N - 1) s^2 / sigma^2 ~ chi2(N - 1)``), its relative standard error,
a percentile bootstrap over the trial axis and the central range of a spread. The claims of
every study (:mod:`sim.claims.book`) are decided on these intervals.
"""

from __future__ import annotations

import math
from typing import Callable

import numpy as np

from sim.lsq import distributions as D

__all__ = ["mean_ci", "std_ci", "sd_interval", "std_rel_se", "bootstrap_ci", "spread"]


def mean_ci(x: np.ndarray, level: float = 0.95) -> tuple[float, tuple[float, float]]:
    """Mean of ``x`` (1-D) and its normal-theory confidence interval."""
    x = np.asarray(x, float)
    m = x.mean()
    h = D.norm_ppf(0.5 + level / 2) * x.std(ddof=1) / math.sqrt(x.size)
    return float(m), (float(m - h), float(m + h))


def std_ci(x: np.ndarray, level: float = 0.95, axis: int = 0):
    """Sample standard deviation along ``axis`` with its chi-square confidence interval.

    Exact for Gaussian samples: (N-1) s^2 / sigma^2 ~ chi2(N-1).
    Returns ``(s, lo, hi)`` with the shape of ``x`` less ``axis``.
    """
    x = np.asarray(x, float)
    n = x.shape[axis]
    s = x.std(axis=axis, ddof=1)
    a = (1 - level) / 2
    lo = s * np.sqrt((n - 1) / D.chi2_ppf(1 - a, n - 1))
    hi = s * np.sqrt((n - 1) / D.chi2_ppf(a, n - 1))
    return s, lo, hi


def sd_interval(s: float, n: int, level: float = 0.95) -> tuple[float, float]:
    """Chi-square confidence interval of a standard deviation ``s`` from ``n`` Gaussian draws."""
    a = (1 - level) / 2
    return (
        float(s * np.sqrt((n - 1) / D.chi2_ppf(1 - a, n - 1))),
        float(s * np.sqrt((n - 1) / D.chi2_ppf(a, n - 1))),
    )


def std_rel_se(n: int) -> float:
    """Relative standard error of a sample standard deviation of ``n`` Gaussian draws."""
    return 1.0 / math.sqrt(2.0 * (n - 1))


def bootstrap_ci(
    stat: Callable[[np.ndarray], float],
    data: np.ndarray,
    rng: np.random.Generator,
    n_boot: int = 400,
    level: float = 0.95,
) -> tuple[float, tuple[float, float]]:
    """Percentile bootstrap over the leading (trial) axis of ``data``.

    ``stat`` maps an array with the trial axis first to a scalar. Returns the statistic on
    the full sample and its ``level`` percentile interval.
    """
    data = np.asarray(data)
    n = data.shape[0]
    est = float(stat(data))
    reps = np.empty(n_boot)
    for b in range(n_boot):  # n_boot resamples, not a per-trial loop
        reps[b] = stat(data[rng.integers(0, n, n)])
    a = (1 - level) / 2 * 100
    lo, hi = np.percentile(reps, [a, 100 - a])
    return est, (float(lo), float(hi))


def spread(x: np.ndarray, level: float = 0.95) -> tuple[float, tuple[float, float]]:
    """Median of ``x`` and its central ``level`` range over trials."""
    x = np.asarray(x, float)
    a = (1 - level) / 2 * 100
    lo, med, hi = np.percentile(x, [a, 50, 100 - a])
    return float(med), (float(lo), float(hi))
