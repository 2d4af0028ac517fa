"""Claims tables: a paper's statement beside what the simulation produced.

Every study writes ``claims.parquet`` with one row per number:

==========  ==============================================================
claim       ``<study>.<claim>[.<quantity>_<unit>]``, e.g. ``brown.known_center.ratio``
source      seed file and passage the statement comes from
paper       the paper's statement, verbatim or nearly (text, never a result)
value       what the simulation produced (a Monte-Carlo estimate)
ci_low/high 95 % interval (see ``interval``)
interval    ``ci``: confidence interval of the Monte-Carlo estimate;
            ``spread``: 2.5-97.5 % range of the quantity over trials (for a
            statement about one plate, e.g. one observed rms closure);
            ``exact``: a deterministic computation (interval = value)
ref_low/hi  the interval the paper's number stands for (its rounding); NaN if none
holds       the verdict: the 95 % interval overlaps [ref_low, ref_high];
            null when the paper gives no number to test
kind        ``predicted`` (the simulation predicts it) or ``input`` (a simulation
            input was set to match it, so agreement is by construction)
note        how the value was obtained; why it does or does not hold
==========  ==============================================================
"""
from __future__ import annotations

import math
from typing import Any, Callable, Iterable, Mapping

import numpy as np
from scipy import stats

from .storage import write_table

__all__ = ["claim", "write_claims", "mean_ci", "std_ci", "bootstrap_ci", "spread", "sd_interval",
           "CLAIM_COLUMNS"]

CLAIM_COLUMNS = ["claim", "source", "paper", "value", "ci_low", "ci_high", "interval", "ref_low",
                 "ref_high", "holds", "kind", "note"]


def claim(name: str, source: str, paper: str, value: float, ci: tuple[float, float],
          kind: str, note: str = "", ref: tuple[float, float] | float | None = None,
          interval: str = "ci") -> dict[str, Any]:
    """One claims row. ``ref`` is the paper's number as an interval (or a point)."""
    if kind not in ("predicted", "input"):
        raise ValueError(f"kind must be 'predicted' or 'input', not {kind!r}")
    if interval not in ("ci", "spread", "exact"):
        raise ValueError(f"interval must be ci, spread or exact, not {interval!r}")
    lo, hi = (float(ci[0]), float(ci[1]))
    if ref is None:
        rlo = rhi = math.nan
        holds = None
    else:
        rlo, rhi = (float(ref), float(ref)) if np.isscalar(ref) else (float(ref[0]), float(ref[1]))
        holds = bool(np.isfinite(lo) and np.isfinite(hi) and lo <= rhi and hi >= rlo)
    return {"claim": name, "source": source, "paper": paper, "value": float(value), "ci_low": lo,
            "ci_high": hi, "interval": interval, "ref_low": rlo, "ref_high": rhi, "holds": holds,
            "kind": kind, "note": note}


def rounding(x: float, decimals: int) -> tuple[float, float]:
    """The interval a number printed with ``decimals`` decimals stands for."""
    h = 0.5 * 10.0 ** (-decimals)
    return (x - h, x + h)


def write_claims(path, rows: Iterable[Mapping[str, Any]], prov: Mapping[str, Any]):
    rows = list(rows)
    cols = {c: [r[c] for r in rows] for c in CLAIM_COLUMNS}
    return write_table(path, cols, prov)


def mean_ci(x: np.ndarray, level: float = 0.95) -> tuple[float, tuple[float, float]]:
    """Mean of ``x`` (1-D) and its normal-theory confidence interval."""
    x = np.asarray(x, float)
    m = x.mean()
    h = stats.norm.ppf(0.5 + level / 2) * x.std(ddof=1) / math.sqrt(x.size)
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
    lo = s * np.sqrt((n - 1) / stats.chi2.ppf(1 - a, n - 1))
    hi = s * np.sqrt((n - 1) / stats.chi2.ppf(a, n - 1))
    return s, lo, hi


def sd_interval(s: float, n: int, level: float = 0.95) -> tuple[float, float]:
    """Chi-square confidence interval of a standard deviation ``s`` from ``n`` Gaussian draws."""
    a = (1 - level) / 2
    return (float(s * np.sqrt((n - 1) / stats.chi2.ppf(1 - a, n - 1))),
            float(s * np.sqrt((n - 1) / stats.chi2.ppf(a, n - 1))))


def std_rel_se(n: int) -> float:
    """Relative standard error of a sample standard deviation of ``n`` Gaussian draws."""
    return 1.0 / math.sqrt(2.0 * (n - 1))


def bootstrap_ci(stat: Callable[[np.ndarray], float], data: np.ndarray, rng: np.random.Generator,
                 n_boot: int = 400, level: float = 0.95) -> tuple[float, tuple[float, float]]:
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
