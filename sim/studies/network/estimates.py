"""Monte-Carlo estimates of a network study from the runner's per-chunk sums: the point sigmas
with jackknife intervals over chunks, their ratio to the analytic sigmas (the root of the
mean variance ratio: unbiased at any number of trials), the coverage of the analytic 95 %
ellipses and the false-alarm rate of the global test (Wilson intervals from the counts).
Coordinates and sigmas in mm. Every estimate is ``(value, lo, hi)``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sim.claims.intervals import binomial_ci
from sim.mc.config import StudyError
from sim.mc.runner import jackknife

__all__ = ["McEstimates", "mc_estimates", "sample_sd", "sigma_ratio", "TOO_FEW"]

#: why the Monte-Carlo estimates of a run cannot be formed (the jackknife over chunks)
TOO_FEW = "too few trials (the jackknife over chunks needs two outside each chunk) converged"


def sample_sd(n, e, ee):
    """The sample standard deviation (n - 1) from the count ``n``, the sum ``e`` and the sum of
    squares ``ee`` of the errors (clipped at zero against rounding)."""
    return np.sqrt(np.maximum(ee / n - (e / n) ** 2, 0) * n / (n - 1))


def sigma_ratio(s_mc: np.ndarray, an_sig: np.ndarray) -> float:
    """Monte-Carlo over analytic sigma of the coordinates as one number: the root of the mean
    ratio of the variances, ``sqrt(mean(s_mc^2 / an_sig^2))``.

    Why the variances: the sample variance ``s^2`` (n - 1) is unbiased, so the mean of the
    variance ratios is 1 in expectation when the analytic sigmas are right, whatever the
    number of trials; its root is biased only by the spread of that mean (by about minus an
    eighth of its variance: 1e-6 at 40 trials of 5,000 independent coordinates).
    The sample standard deviation is biased low, by the factor ``c4(n)`` for normal errors
    (0.9936 at n = 40), which a mean of ``s / sigma`` over many coordinates keeps while its
    interval shrinks: at 40 trials network_gridplate_2500's interval left out 1. Dividing
    by ``c4`` would hold for normal errors only; the variances are unbiased for any."""
    return float(np.sqrt(np.mean((s_mc / an_sig) ** 2)))


@dataclass(frozen=True)
class McEstimates:
    """What the Monte Carlo gave over the estimated points ``pts`` (x and y interleaved).

    n_ok : converged trials per chunk; an_sig : the analytic sigmas (mm); s_mc, s_lo, s_hi : the
    Monte-Carlo sigmas and their 95 % interval (mm); ratio : MC / analytic sigma (the root of
    the mean variance ratio, :func:`sigma_ratio`); cover : per point, the share inside its
    95 % ellipse; cover_mean : its mean over points; alarm : the rejection rate of the global
    test. The last four as ``(value, lo, hi)`` arrays."""

    n_ok: np.ndarray
    an_sig: np.ndarray
    s_mc: np.ndarray
    s_lo: np.ndarray
    s_hi: np.ndarray
    ratio: tuple
    cover: tuple
    cover_mean: tuple
    alarm: tuple


def _sums(sim: dict) -> np.ndarray:
    """Per chunk: converged count, error sums, squared-error sums, inside counts, rejections."""
    n_ok = sim["sum.n"][:, 0]
    return np.concatenate(
        [
            sim["sum.n"],
            sim["sum.e"].reshape(len(n_ok), -1),
            np.einsum("ckii->cki", sim["sum.ee"]).reshape(len(n_ok), -1),
            sim["sum.inside"],
            sim["sum.reject"],
        ],
        axis=1,
    )


def mc_estimates(an, pts: list[int], sim: dict) -> McEstimates:
    """The estimates of the chunks ``sim`` for the points ``pts`` of the analysis ``an``;
    :class:`StudyError` when leaving out any one chunk (the jackknife) leaves fewer than two
    converged trials: a sample sigma of one trial divided by zero (2 of 40 trials, in two
    chunks: three numpy warnings, then a claim "not finite" named as the cause)."""
    n_ok = sim["sum.n"][:, 0]
    if n_ok.size < 2 or np.min(n_ok.sum() - n_ok) < 2:
        raise StudyError(
            f"solver.max_iter: {TOO_FEW}; the network does not converge from its true coordinates"
        )
    sums = _sums(sim)
    k = len(pts)

    def sig(t):
        return sample_sd(t[0], t[1 : 1 + 2 * k], t[1 + 2 * k : 1 + 4 * k])

    an_sig = np.sqrt(np.stack([an.cov[pts, 0, 0], an.cov[pts, 1, 1]], 1)).reshape(-1)
    s_mc, s_lo, s_hi = jackknife(sig, sums)
    ratio = jackknife(lambda t: np.atleast_1d(sigma_ratio(sig(t), an_sig)), sums)
    tot = sums.sum(axis=0)  # proportions: Wilson intervals from the counts, inside [0, 1]
    cover = binomial_ci(tot[1 + 4 * k : 1 + 5 * k], tot[0])
    cover_mean = _share_interval(
        jackknife(lambda t: np.atleast_1d(np.mean(t[1 + 4 * k : 1 + 5 * k] / t[0])), sums),
        binomial_ci(tot[1 + 4 * k : 1 + 5 * k].sum(), tot[0] * k),
    )
    alarm = binomial_ci(tot[-1:], tot[0])
    return McEstimates(n_ok, an_sig, s_mc, s_lo, s_hi, ratio, cover, cover_mean, alarm)


def _share_interval(jack: tuple, wilson: tuple) -> tuple:
    """The mean coverage over points is a proportion: its jackknife interval over chunks (which
    sees the points of one trial move together) widened to the Wilson interval of the pooled
    counts and kept inside [0, 1]. The jackknife alone left [0, 1] (0.975 in [0.92, 1.03]) and,
    when every chunk covered every point (20 chunks of one trial of one point), was [1, 1]:
    a self-check "fails" from 20 trials."""
    (est, lo, hi), (_, wlo, whi) = jack, wilson
    return est, np.clip(np.minimum(lo, wlo), 0.0, 1.0), np.clip(np.maximum(hi, whi), 0.0, 1.0)
