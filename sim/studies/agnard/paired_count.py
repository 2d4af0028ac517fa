"""A count with many zeros over the scanner's unprinted inputs, by common random numbers
(seed ``003_5ce730a990a7ebc5.txt``, issue 21): the pass points data snooping removes from one
block under digital pugging.

The claim. "Using digital pugging, not a single pass point had to be removed" (section 5):
the paper's one block lost none. The claim book scores it by its one-plate rule on the count
of one block, printed ``0`` (zone -0.5-0.5): it *fails* where a block losing none is rare,
``p = 2 P(X = 0) < 0.05`` (``P(X < 0.5) = P(X = 0)``, ``P(X > -0.5) = 1``), *holds* where
nearly every block loses none (the 97.5 % point of the count is 0), and is undecided
between. So what decides it is the count's distribution function at 0, and near the
97.5 % point, not its mean: the paired log shift of :mod:`.paired` cannot carry a count
(the logarithm of the 34 % of blocks that lose none is not finite), and an additive shift
of the counts (``X + d``, ``d`` the mean paired difference) would move every zero off zero
at ``d >= 0.5`` even if most blocks still lose none.

The estimator: a control variate on the indicators. The configured scanner's ``base``
blocks (the main ``M`` = 500) give ``F_B(t) = P(X <= t)`` at every count ``t``. Each explored
vector and the configured scanner again run the same ``k`` blocks (the same seeds:
:func:`sim.studies.agnard.chunks.table1_chunk`), counts ``c`` and ``v``; per block the
indicators ``I_c = 1[c <= t]``, ``I_v = 1[v <= t]`` (a block that loses none, at ``t = 0``).
The vector's share is the regression (control-variate) estimator

    ``F_v(t) = mean(I_v) + beta (F_B(t) - mean(I_c))``,  ``beta = cov(I_v, I_c) / var(I_c)``,
    ``Var = var(I_v) (1 - rho^2) / k + beta^2 F_B (1 - F_B) / M``

(``rho`` the indicators' correlation on the pairs; the two terms are independent, the base
and the paired blocks having different seeds). ``beta = 1`` is the paired difference of the
indicators (an additive shift of the distribution function on the same blocks, variance
``var(I_v - I_c) / k``), ``beta = 0`` the vector's own ``k`` blocks alone; the regression
is never worse than either (to first order), and it matters here: near the configured
scanner most pairs agree and the difference is precise, but at a vector that removes more
points its zeros vanish, every pair whose configured block lost none is discordant, and the
difference's variance grows to ``F_B / k`` while the vector's own share of zeros is known
to about ``1 / k``. A 2 x 2 table of indicators with an empty cell would claim no error at
all, so the moments that give ``beta``, ``rho`` and the variance are taken with half a block
added to each cell (Agresti & Min 2005, Biometrics 61, 515-523; the base's two cells too),
which keeps the error positive (about ``sqrt(F (1 - F) / k)`` with ``F`` at least
``0.5 / (k + 2)``); the point estimate uses the raw moments (so the configured scanner
paired with itself gets exactly the main blocks' ``F_B``). At every count larger than all
the blocks show, ``F = 1`` without error. Its interval is ``+- z`` standard errors with ``z``
:func:`.paired.z_box` (Student, 97.5 % two-sided at ``k - 1`` degrees of freedom, as the log
shift: the decision reads ``F`` at two counts, the printed one and the 97.5 % point, so both
at once cover at least 95 %). What 48 pairs cannot do: show ``P(X = 0) < 0.025`` (the fail),
which needs a vector's blocks to lose none in fewer than one in forty; with the floor above,
a vector none of whose 48 blocks loses none still has an interval reaching about
``2.31 sqrt(f (1 - f) / 48)`` with ``f = 1 / 50``, 4.7 %, so the row can fail at a vector
only with more blocks (several hundred where a block loses none in one of fifty).

The evidence at a vector (:func:`count_evidence`, for :func:`sim.claims.inference.status`):
``p`` from the book's one-plate rule on the distribution function (edges counted half, as
:func:`sim.claims.intervals.plate_p`) at the end of the interval that makes it largest;
``low`` the 2.5 % point at the upper end of ``F``, ``high`` the 97.5 % point at its lower end,
``value`` the median at the estimate (each the smallest count where ``F`` reaches the level: a
count's quantile, where :func:`sim.claims.intervals.spread` interpolates between counts). So a
vector *fails* only if a block losing none is rare over the whole interval, *holds* only if
nearly every block loses none over it. The mean count shift (the paired difference of counts
per block, with its paired standard error) is reported beside it (:func:`mean_shift`).
Arrays in, arrays out: the vectors' counts have a leading vector axis ``(N, k)``.
"""

from __future__ import annotations

import numpy as np

from sim.studies.agnard.paired import z_box

__all__ = ["cdf_shift", "count_evidence", "mean_shift", "count_quantile"]


def _counts(x, name: str) -> np.ndarray:
    a = np.asarray(x, float)
    if not (np.isfinite(a).all() and (a >= 0).all() and (a == np.round(a)).all()):
        raise ValueError(f"{name}: counts must be finite non-negative integers")
    return a


def cdf_shift(base, c, v, tmax: int | None = None) -> dict[str, np.ndarray]:
    """The distribution function of each vector's count at ``t = 0..tmax`` (the module doc).

    base : (M,) counts of the configured scanner's main blocks; c : (k,) the configured
    scanner's counts on the paired blocks; v : (N, k) each vector's counts on the same blocks.
    Returns ``F`` (N, T) the estimate, ``se`` its standard error (the smoothed moments),
    ``var`` the plug-in variance of the raw moments, ``beta`` the control variate's
    coefficients (the raw moments', those of the estimate), ``se_paired_difference`` and ``se_unpaired`` (the errors of the paired
    difference, ``beta = 1``, and of two independent samples) and ``t`` (T,) the counts
    (``tmax`` defaults to the largest seen)."""
    b, c = _counts(base, "base"), _counts(c, "c")
    v = np.atleast_2d(_counts(v, "v"))
    k, m = c.size, b.size
    if k < 2 or v.shape[1] != k or m < 1:
        raise ValueError(f"need the same k >= 2 blocks for c and v, not {k} and {v.shape[1]}")
    top = int(max(b.max(), c.max(), v.max()))
    t = np.arange((top if tmax is None else int(tmax)) + 1)
    fb = (b[None, :] <= t[:, None]).mean(1)  # (T,)
    ic = c[None, :] <= t[:, None]  # (T, k)
    iv = v[:, None, :] <= t[None, :, None]  # (N, T, k)
    n11, n10, n01 = (ic & iv).sum(-1), (ic & ~iv).sum(-1), (~ic & iv).sum(-1)
    fc, fv = ic.mean(-1), iv.mean(-1)
    raw = _moments(n11, n10, n01, k, 0.0)
    sm = _moments(n11, n10, n01, k, 0.5)  # Agresti-Min: half a block in each cell
    ft = (fb * m + 0.5) / (m + 1.0)
    var_b, var_bt = fb * (1 - fb) / m, ft * (1 - ft) / m
    var_am = sm["resid"] / k + sm["beta"] ** 2 * var_bt
    beyond = t >= top  # every block shows a count <= t: F = 1 exactly
    return {
        "t": t,
        "F": np.clip(fv + raw["beta"] * (fb - fc), 0.0, 1.0),
        "se": np.where(beyond, 0.0, np.sqrt(var_am)),
        "var": raw["resid"] / k + raw["beta"] ** 2 * var_b,
        "beta": raw["beta"],
        "se_paired_difference": np.sqrt(var_b + ((n10 + n01) / k - ((n01 - n10) / k) ** 2) / k),
        "se_unpaired": np.sqrt(var_b + (fc * (1 - fc) + fv * (1 - fv)) / k),
    }


def _moments(n11, n10, n01, k: int, add: float) -> dict[str, np.ndarray]:
    """From the 2 x 2 table of the pairs' indicators (``add`` blocks added to each cell):
    ``beta = cov / var(I_c)`` and ``resid = var(I_v) - cov^2 / var(I_c)`` (0 where ``I_c``
    is constant and so carries no information: ``beta = 0``)."""
    n = k + 4 * add
    pc, pv = (n11 + n10 + 2 * add) / n, (n11 + n01 + 2 * add) / n
    cov = (n11 + add) / n - pc * pv
    vc, vv = pc * (1 - pc), pv * (1 - pv)
    with np.errstate(divide="ignore", invalid="ignore"):
        beta = np.where(vc > 0, cov / vc, 0.0)
    return {"beta": beta, "resid": np.maximum(vv - beta * cov, 0.0)}


def count_quantile(F: np.ndarray, t: np.ndarray, q: float) -> np.ndarray:
    """Per row of ``F`` (N, T), the smallest count ``t`` with ``F >= q`` (the last ``t`` if
    none): a count's quantile."""
    ok = F >= q - 1e-12
    i = np.where(ok.any(axis=1), ok.argmax(axis=1), F.shape[1] - 1)
    return np.asarray(t, float)[i]


def _g(F: np.ndarray, a: float) -> np.ndarray:
    """``P(X < a) + P(X = a) / 2`` of an integer count from its distribution function ``F``
    at ``t = 0..T-1`` (rows), ``F(-1) = 0``, ``F(t >= T) = 1``."""
    n, tn = F.shape
    at = lambda j: (  # noqa: E731
        np.zeros(n) if j < 0 else np.ones(n) if j >= tn else F[:, j]
    )
    if a == np.floor(a):
        return 0.5 * (at(int(a) - 1) + at(int(a)))
    return at(int(np.floor(a)))


def count_evidence(base, c, v, ref: float | None = None, h: float = 0.0) -> dict[str, np.ndarray]:
    """The evidence of a count's row at N vectors (the module doc): ``value`` the median at
    the estimate, ``low`` / ``high`` the 2.5 / 97.5 % points at the ends of the interval that
    widen them, and (one-plate, printed ``ref`` with rounding half-unit ``h``) the largest
    ``p = min(1, 2 min(P(X < ref + h), P(X > ref - h)))`` over the interval."""
    s = cdf_shift(base, c, v)
    k = np.asarray(c).size
    z = z_box(k)
    lo = np.clip(s["F"] - z * s["se"], 0.0, 1.0)
    hi = np.clip(s["F"] + z * s["se"], 0.0, 1.0)
    out = {
        "value": count_quantile(s["F"], s["t"], 0.5),
        "low": count_quantile(hi, s["t"], 0.025),
        "high": count_quantile(lo, s["t"], 0.975),
        "share_zero": s["F"][:, 0],
        "share_zero_low": lo[:, 0],
        "share_zero_high": hi[:, 0],
        "plates": np.full(lo.shape[0], np.asarray(base).size),  # the configured blocks
    }
    if ref is not None:
        below = _g(hi, ref + h)  # the rarer side's share at its largest
        above = 1.0 - _g(lo, ref - h)
        out["p"] = np.minimum(1.0, 2 * np.minimum(below, above))
    return out


def mean_shift(c, v) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The mean paired difference of counts per block ``mean(v - c)`` (N,), its paired
    standard error ``sd(v - c) / sqrt(k)`` and the unpaired one
    ``sqrt((var c + var v) / k)``: how many more blocks' points a vector removes, on average."""
    c = _counts(c, "c")
    v = np.atleast_2d(_counts(v, "v"))
    k = c.size
    d = v - c
    paired = d.std(axis=1, ddof=1) / np.sqrt(k)
    unpaired = np.sqrt((c.var(ddof=1) + v.var(axis=1, ddof=1)) / k)
    return d.mean(axis=1), paired, unpaired
