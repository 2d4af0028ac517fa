"""Confidence intervals of sample statistics over Monte-Carlo trials, and the one-plate spread.

Every interval a claim is decided on comes from one function here (or from the delete-one-chunk
jackknife, :func:`sim.mc.runner.jackknife`); ``METHODS`` names each in words and is written
into the provenance of every ``claims.parquet`` (:func:`sim.claims.book.write_claims`).

* :func:`mean_ci` -- Student-t interval of a mean, ``m +- t(1 - a/2, N - 1) s / sqrt(N)``
  (exact for Gaussian samples, the normal interval's large-N limit otherwise).
* :func:`std_ci` / :func:`sd_interval` -- chi-square interval of a standard deviation, exact for
  Gaussian samples: ``(N - 1) s^2 / sigma^2 ~ chi2(N - 1)``; :func:`std_rel_se` its relative
  standard error ``1 / sqrt(2 (N - 1))``.
* :func:`binomial_ci` / :func:`share_ci` -- Wilson score interval of a proportion from its
  counts (Wilson 1927), always inside [0, 1]; proportions never get a normal or jackknife
  interval.
* :func:`bootstrap_ci` -- percentile bootstrap over the trial axis (Efron 1979).
* :func:`spread` / :func:`plate_p` -- the *one-plate* distribution: a paper's number is one
  plate's statistic, the simulation gives its distribution over plates; the median, the
  central ``level`` range (2.5-97.5 % at 95 %) and ``p``, the probability of a plate at least
  as extreme as the paper's value (two-sided).

``level`` is the two-sided confidence level, 0.95 throughout the suite (``LEVEL``).
"""

from __future__ import annotations

import math
from typing import Callable

import numpy as np

from sim.lsq import distributions as D
from sim.mc.runner import MIN_CHUNKS

__all__ = [
    "LEVEL",
    "METHODS",
    "MIN_CHUNKS",
    "mean_ci",
    "std_ci",
    "sd_interval",
    "std_rel_se",
    "binomial_ci",
    "share_ci",
    "bootstrap_ci",
    "spread",
    "plate_p",
]

#: the two-sided confidence level of every interval in the suite
LEVEL = 0.95

#: each interval method in words: written into every claims.parquet's provenance
METHODS = {
    "mean": "Student-t interval of a mean over trials, m +- t(0.975, N-1) s/sqrt(N)",
    "sd": "chi-square interval of a standard deviation, (N-1) s^2/sigma^2 ~ chi2(N-1)",
    "share": "Wilson score interval of a proportion from its counts, inside [0, 1]",
    "bootstrap": "percentile bootstrap over trials, 2.5-97.5 % of the resampled statistic",
    "jackknife": (
        f"delete-one-chunk jackknife over per-chunk sums, Student-t with C-1 degrees of "
        f"freedom; computed only from C >= {MIN_CHUNKS} chunks (fewer are refused)"
    ),
    "spread": (
        "one plate: median and 2.5-97.5 % range of the statistic over simulated plates; "
        "p = min(1, 2 min(P(X < ref + h), P(X > ref - h))) over the plates, h half a unit "
        "of the paper's last printed decimal (plates on an edge count half; h = 0: "
        "2 min(q, 1-q), q the share below the paper's value)"
    ),
    "exact": (
        "a deterministic computation: the interval is the value itself, or, recomputed from "
        "the paper's printed numbers, its range over their rounding"
    ),
}


def _half(level: float) -> float:
    """The lower tail ``(1 - level) / 2`` of a two-sided ``level`` interval."""
    if not 0 < level < 1:
        raise ValueError(f"level must lie in (0, 1), not {level!r}")
    return (1 - level) / 2


def mean_ci(x: np.ndarray, level: float = LEVEL) -> tuple[float, tuple[float, float]]:
    """Mean of ``x`` (1-D, N >= 2) and its Student-t confidence interval."""
    x = np.asarray(x)
    if x.size < 2:
        raise ValueError("a mean's interval needs at least 2 values")
    m = x.mean()
    h = D.t_ppf(1 - _half(level), x.size - 1) * x.std(ddof=1) / math.sqrt(x.size)
    return float(m), (float(m - h), float(m + h))


def std_ci(x: np.ndarray, level: float = LEVEL, axis: int = 0):
    """Sample standard deviation along ``axis`` with its chi-square confidence interval.

    Exact for Gaussian samples: (N-1) s^2 / sigma^2 ~ chi2(N-1).
    Returns ``(s, lo, hi)`` with the shape of ``x`` less ``axis``.
    """
    x = np.asarray(x)
    n = x.shape[axis]
    s = x.std(axis=axis, ddof=1)
    lo, hi = _sd_factors(n, level)
    return s, s * lo, s * hi


def _sd_factors(n: int, level: float) -> tuple[float, float]:
    if n < 2:
        raise ValueError("a standard deviation's interval needs at least 2 values")
    a = _half(level)
    return (
        float(np.sqrt((n - 1) / D.chi2_ppf(1 - a, n - 1))),
        float(np.sqrt((n - 1) / D.chi2_ppf(a, n - 1))),
    )


def sd_interval(s: float, n: int, level: float = LEVEL) -> tuple[float, float]:
    """Chi-square confidence interval of a standard deviation ``s`` from ``n`` Gaussian draws."""
    lo, hi = _sd_factors(n, level)
    return float(s * lo), float(s * hi)


def std_rel_se(n: int) -> float:
    """Relative standard error of a sample standard deviation of ``n`` Gaussian draws."""
    return 1.0 / math.sqrt(2.0 * (n - 1))


def binomial_ci(k, n, level: float = LEVEL):
    """Proportion ``k / n`` and its Wilson score interval (no continuity correction).

    ``k`` and ``n`` are counts (arrays broadcast); ``n >= 1``. Returns ``(p, lo, hi)``, each
    inside [0, 1]; equal to ``scipy.stats.binomtest(k, n).proportion_ci(level, "wilson")``.
    """
    k, n = np.asarray(k), np.asarray(n)
    if np.any(n < 1) or np.any(k < 0) or np.any(k > n):
        raise ValueError("a proportion needs counts 0 <= k <= n and n >= 1")
    z = float(D.norm_ppf(1 - _half(level)))
    p = k / n
    denom = 2 * (n + z * z)
    centre = (2 * n * p + z * z) / denom
    half = z * np.sqrt(4 * n * p * (1 - p) + z * z) / denom
    # rounding can carry the bounds a few ulp outside [0, 1] (k = n = 16: 1 + 2e-16), or
    # inside it (k = n = 40: 1 - 1e-16, an interval that missed its own value 1): at k = 0
    # and k = n the Wilson bound is exactly 0 and 1
    lo = np.where(k == 0, 0.0, np.maximum(centre - half, 0.0))[()]  # [()]: a scalar stays one
    return p, lo, np.where(k == n, 1.0, np.minimum(centre + half, 1.0))[()]


def share_ci(x: np.ndarray, level: float = LEVEL) -> tuple[float, tuple[float, float]]:
    """Share of true values in ``x`` (0/1 or boolean, any shape) with its Wilson interval;
    the same return shape as :func:`mean_ci`."""
    x = np.asarray(x)
    if x.size == 0 or not np.all((x == 0) | (x == 1)):
        raise ValueError("a share needs a non-empty array of 0/1 values")
    p, lo, hi = binomial_ci(int(np.count_nonzero(x)), x.size, level)
    return float(p), (float(lo), float(hi))


def bootstrap_ci(
    stat: Callable[[np.ndarray], float],
    data: np.ndarray,
    rng: np.random.Generator,
    n_boot: int = 400,
    level: float = LEVEL,
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
    a = _half(level) * 100
    lo, hi = np.percentile(reps, [a, 100 - a])
    return est, (float(lo), float(hi))


def spread(x: np.ndarray, level: float = LEVEL) -> tuple[float, tuple[float, float]]:
    """Median of ``x`` and its central ``level`` range over trials (plates): the one-plate
    distribution of a statistic. Linear interpolation between order statistics
    (``numpy.percentile``'s default)."""
    x = np.asarray(x)
    if x.size == 0:
        raise ValueError("a spread needs at least one value")
    a = _half(level) * 100
    lo, med, hi = np.percentile(x, [a, 50, 100 - a])
    return float(med), (float(lo), float(hi))


def spread_rows(x: np.ndarray, level: float = LEVEL) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`spread` of every row of ``x`` ``(N, M)`` (NaN ignored): the median and the
    central ``level`` range of each row, ``(median, low, high)``, each ``(N,)``; NaN for a row
    without a finite value (numpy's value, without its "All-NaN slice" warning on standard
    error: gridplate's region at a point where no calibration has a re-weighting)."""
    a = _half(level) * 100
    x = np.asarray(x, float)
    out = np.full((3, x.shape[0]), np.nan)
    some = ~np.isnan(x).all(axis=1)
    if some.any():
        out[:, some] = np.nanpercentile(x[some], [a, 50, 100 - a], axis=1)
    lo, med, hi = out
    return med, lo, hi


def plate_p(x: np.ndarray, ref: float, h: float = 0.0) -> float:
    """The probability of a simulated plate at least as extreme as *every* value that prints
    as the paper's ``ref``: ``p = min(1, 2 min(P(X < ref + h), P(X > ref - h)))``, ``h`` half a
    unit of the printed last decimal (0.05 for a printed "0.8": the paper's plate is rare only
    if everything in 0.75-0.85 is rare). A plate on an edge (``ref + h`` for the lower share,
    ``ref - h`` for the upper) counts half, as a plate equal to ``ref`` does at ``h = 0``,
    where this is ``2 min(q, 1 - q)`` with ``q`` the share below ``ref`` (ties half)."""
    x = np.asarray(x)
    if x.size == 0:
        raise ValueError("a one-plate p needs at least one plate")
    if not h >= 0:
        raise ValueError(f"the rounding half-unit h must be >= 0, not {h!r}")
    below = np.count_nonzero(x < ref + h) + 0.5 * np.count_nonzero(x == ref + h)
    above = np.count_nonzero(x > ref - h) + 0.5 * np.count_nonzero(x == ref - h)
    return float(min(1.0, 2 * min(below, above) / x.size))
