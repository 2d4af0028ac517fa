"""Quantiles and tails of the normal, chi-square, Student t, F and binomial distributions.

The same special functions ``scipy.stats`` evaluates for these distributions
(``scipy.special``: ``ndtri``, ``gammaincinv``, ``chdtr``, ``stdtrit``, ``fdtri``, ``bdtr``),
called directly: importing ``scipy.stats`` costs more than a second per process, and every
``sim run`` (and every worker it starts) paid it for a handful of quantiles. Values equal
``scipy.stats`` to rounding (``tests/test_distributions.py``). Arguments broadcast as numpy
arrays; probabilities outside [0, 1] give NaN.
"""

from __future__ import annotations

import numpy as np
from scipy import special

__all__ = [
    "norm_ppf",
    "norm_cdf",
    "norm_pdf",
    "chi2_ppf",
    "chi2_cdf",
    "chi2_sf",
    "t_ppf",
    "f_ppf",
    "binom_ppf",
    "wilson_ci",
]


def _p(q):
    q = np.asarray(q, float)
    return np.where((q >= 0) & (q <= 1), q, np.nan)


def norm_ppf(q):
    """Standard normal quantile."""
    return special.ndtri(_p(q))


def norm_cdf(x):
    """Standard normal distribution function."""
    return special.ndtr(x)


def norm_pdf(x):
    """Standard normal density."""
    x = np.asarray(x, float)
    return np.exp(-x * x / 2) / np.sqrt(2 * np.pi)


def chi2_ppf(q, df):
    """Chi-square quantile with ``df`` degrees of freedom."""
    return 2 * special.gammaincinv(np.asarray(df, float) / 2, _p(q))


def chi2_cdf(x, df):
    """Chi-square distribution function."""
    return special.chdtr(df, np.maximum(x, 0))


def chi2_sf(x, df):
    """Chi-square upper tail ``1 - cdf``."""
    return special.chdtrc(df, np.maximum(x, 0))


def t_ppf(q, df):
    """Student t quantile."""
    return special.stdtrit(df, _p(q))


def f_ppf(q, dfn, dfd):
    """F quantile with ``dfn`` and ``dfd`` degrees of freedom."""
    return special.fdtri(dfn, dfd, _p(q))


def binom_ppf(q: float, n: int, p: float) -> int:
    """Binomial quantile: the smallest ``k`` with ``P(X <= k) >= q`` (scalar arguments)."""
    k = np.arange(int(n) + 1)
    cdf = special.bdtr(k, int(n), p)
    hit = np.flatnonzero(cdf >= q * (1 - 1e-12))  # a cdf within rounding of q reaches it
    return int(hit[0]) if hit.size else int(n)


def wilson_ci(k: int, n: int, level: float = 0.95) -> tuple[float, float]:
    """Wilson score interval of a proportion ``k / n`` (no continuity correction), as
    ``scipy.stats.binomtest(k, n).proportion_ci(level, "wilson")``."""
    z = float(special.ndtri(0.5 + level / 2))
    p = k / n
    denom = 2 * (n + z * z)
    centre = (2 * n * p + z * z) / denom
    half = z * np.sqrt(4 * n * p * (1 - p) + z * z) / denom
    # at k = 0 and k = n the bound is exactly 0 and 1 (rounding gave 1 - 1e-16 at k = n = 40,
    # an interval that missed its own value)
    lo = 0.0 if k == 0 else max(centre - half, 0.0)
    return float(lo), float(1.0 if k == n else min(centre + half, 1.0))
