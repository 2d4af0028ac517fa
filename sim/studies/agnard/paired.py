"""Tables 2-3's 21-control rows over the scanner's unprinted inputs, by common random numbers
(seed ``003_5ce730a990a7ebc5.txt``, issue 21).

The problem. Table 1 is set aside as not comparable, so no printed statement constrains the
scanner's five unprinted inputs (``scanner.toml``) and the 21-control rows, which hang on the
scanner through what the grid correction leaves, must be decided over the whole declared
box. Each row is a one-block statistic (an rms over one block's points) decided by the
book's one-plate rule: the 2.5-97.5 % spread of the blocks against the printed zone, and the
probability ``p`` of a block at least as extreme as the printed number. Its tails need
hundreds of blocks; a few dozen blocks per input vector give decisions that move with the
draw.

The estimator (a control variate by common random numbers). The configured scanner is run
on the main ``trials`` blocks (``base``, 500 at full size). Every explored vector *and the
configured scanner again* are run on the SAME ``k = table1.trials`` blocks (the same seeds:
scanner shape, fiducials, pointing, model frames, control; the grid's node noise on a stream
of its own, :class:`sim.studies.agnard.simulate.Simulated`), so a vector's statistic and the
configured one differ block by block only by what the inputs change. In logarithms (an rms
is positive and its spread grows with its level) the pair of samples ``u = log c``,
``w = log v`` (configured, vector) gives

* the shift ``delta = mean(w - u)``, standard error ``sd(w - u) / sqrt(k)``: paired, its
  variance is ``(s_w^2 + s_u^2 - 2 rho s_w s_u) / k`` against ``(s_w^2 + s_u^2) / k`` from
  independent blocks (:func:`variance_ratio`; with ``rho`` 0.41-0.99 at full size, 1.7-110
  times less);
* the spread's scale ``beta = s_w / s_u``, standard error of ``log beta``
  ``sqrt((1 - rho^2) / (k - 1))`` (Pitman-Morgan: the variance of the log ratio of two
  correlated normal sample variances is ``4 (1 - rho^2) / (k - 1)``).

The vector's blocks are then the configured ``base`` blocks shifted in logarithms,
``log x = log base + delta`` (:func:`mapped`): the configured distribution moved, its relative
width kept. That is the map's assumption, and it is tested at every vector on its own pairs:
where ``|log beta| > z`` standard errors (the pairs show the relative spread changed), or
where the pairs are too few for the test to see a 30 % change (:data:`MIN_TEST_PAIRS`), the
map stretches as well, ``log x = m + delta + beta (log base - m)`` (``m`` the mean of
``u``) with ``log beta`` over its interval. At the configured scanner itself ``delta = 0``
and ``beta = 1`` with no error, so the row's evidence there is exactly the book's over
``base``. Checked at full size against 500 blocks simulated directly at each of the 16
explored vectors (docs/papers/agnard-nolette-gagnon.md): 121 of 128 row x vector decisions
agree, none is opposite, and the 7 others are undecided here where the direct blocks decide.

The decision, honestly propagated. ``delta`` ranges over ``+- z`` standard errors (and
``log beta`` too where it is stretched; ``z`` :func:`z_box`, Student's two-sided 97.5 % point
with ``k - 1`` degrees of freedom, 2.31 at 48 pairs: both at once cover at least 95 %,
Bonferroni) on a lattice of ``GRID`` points per parameter that
includes the interval's ends; the row's evidence at the vector is the widest spread and the
largest ``p`` over the lattice (:func:`paired_evidence`). So by the book's rule a vector
*fails* only if ``p < 0.05`` at every lattice point, *holds* only if every lattice point's
spread lies inside the zone, and is *undecided* where the shift's own uncertainty straddles
the decision. The configured blocks' own Monte-Carlo noise enters as the book's rule lets it
enter at the configured inputs (their sample spread and ``p``), no more.

Why this and not more blocks per vector: about 150 blocks per vector would cost about 25 s of
CPU more than ``make rerun`` allows; 48 paired blocks cost about 3.5 s more than the former 10
unpaired ones, and decide no vector that 500 direct blocks leave undecided (the check above;
48 unpaired blocks decided 6 such).
Arrays in, arrays out: the vectors' samples have a leading vector axis ``(N, k)``.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from scipy import special

from sim.claims.book_region import sample_evidence

__all__ = [
    "LEVEL",
    "GRID",
    "MIN_TEST_PAIRS",
    "z_box",
    "Shift",
    "paired_shift",
    "mapped",
    "paired_evidence",
    "variance_ratio",
]

#: two-sided level of each parameter's interval: two parameters, each at 97.5 %, so the box
#: covers both at >= 95 % (Bonferroni)
LEVEL = 1 - 0.05 / 2


@lru_cache(maxsize=None)
def z_box(k: int) -> float:
    """Half-width of each parameter's interval in standard errors from ``k`` pairs: Student's
    two-sided :data:`LEVEL` point with ``k - 1`` degrees of freedom (2.31 at k = 48; the
    normal 2.24 as k grows; 4.18 at k = 4)."""
    return float(special.stdtrit(k - 1, 0.5 + LEVEL / 2))  # scipy.stats.t.ppf, lighter import


#: lattice points per parameter over its interval (odd: the estimate itself is one of them)
GRID = 5
#: fewer pairs than this cannot test the shift-only map, and the map always stretches: the
#: test sees a change of the spread by 30 % (|log beta| 0.26) at the pairs' typical
#: correlation 0.8 only when z sqrt((1 - 0.8^2) / (k - 1)) < 0.26 with z about 2.3, i.e. k >= 30
MIN_TEST_PAIRS = 30


@dataclass(frozen=True)
class Shift:
    """Per vector (leading axis N): the log shift and its paired standard error, the log of
    the spread's scale and its standard error, the pairs' correlation; ``m`` the mean log of
    the configured paired blocks (the map's centre), ``z`` the intervals' half-width in
    standard errors (:func:`z_box` of the number of pairs)."""

    delta: np.ndarray
    delta_se: np.ndarray
    log_beta: np.ndarray
    log_beta_se: np.ndarray
    rho: np.ndarray
    m: float
    z: float
    k: int

    @property
    def stretched(self) -> np.ndarray:
        """Per vector: the pairs contradict the shift-only map (``|log beta| > z se``, beyond
        the rounding of two equal spreads), or are too few to test it (:data:`MIN_TEST_PAIRS`)."""
        if self.k < MIN_TEST_PAIRS:
            return np.ones(self.log_beta.shape, bool)
        return np.abs(self.log_beta) > self.z * self.log_beta_se + 1e-9

    def map_of(self, stretch: bool = False) -> "Shift":
        """The map used: ``log beta`` (and its error) zero where not :attr:`stretched`
        (everywhere kept with ``stretch``)."""
        keep = np.ones(self.log_beta.shape, bool) if stretch else self.stretched
        return Shift(
            self.delta,
            self.delta_se,
            np.where(keep, self.log_beta, 0.0),
            np.where(keep, self.log_beta_se, 0.0),
            self.rho,
            self.m,
            self.z,
            self.k,
        )


def _log(x) -> np.ndarray:
    x = np.asarray(x, float)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(x > 0, np.log(np.where(x > 0, x, 1.0)), np.nan)


def paired_shift(c: np.ndarray, v: np.ndarray) -> Shift:
    """The shift of each vector's blocks ``v`` (N, k) from the configured ``c`` (k,) on the
    same k blocks, in logarithms (the module doc). Non-positive or NaN values give NaN."""
    u, w = _log(c), _log(np.atleast_2d(v))
    k = u.size
    if k < 2 or w.shape[1] != k:
        raise ValueError(f"need the same k >= 2 blocks for c and v, not {k} and {w.shape[1]}")
    d = w - u
    su, sw = u.std(ddof=1), w.std(axis=1, ddof=1)
    uc, wc = u - u.mean(), w - w.mean(axis=1, keepdims=True)
    with np.errstate(divide="ignore", invalid="ignore"):
        rho = np.clip((wc * uc).sum(1) / (k - 1) / (su * sw), -1.0, 1.0)
        log_beta = np.log(sw / su)
        # 1 - rho^2 as the share of w's variance that u leaves unexplained (the regression's
        # residuals): no cancellation near |rho| = 1, where 1 - rho^2 is rounding alone
        res = wc - ((wc * uc).sum(1) / (uc * uc).sum())[:, None] * uc
        unexplained = np.clip((res * res).sum(1) / (wc * wc).sum(1), 0.0, 1.0)
    rho = np.where(np.isfinite(rho), rho, 1.0 if su == 0 else 0.0)
    unexplained = np.where(np.isfinite(unexplained), unexplained, 1.0 - rho**2)
    return Shift(
        d.mean(1),
        d.std(axis=1, ddof=1) / np.sqrt(k),
        log_beta,
        np.sqrt(unexplained / (k - 1)),
        rho,
        float(u.mean()),
        z_box(k),
        k,
    )


def mapped(base: np.ndarray, sh: Shift, grid: int = GRID) -> np.ndarray:
    """The ``base`` blocks (M,) mapped to each vector at each point of the ``grid x grid``
    lattice over ``delta +- z se`` and ``log beta +- z se`` (``z = sh.z``; a zero ``se``
    repeats the estimate): shape (N, grid^2, M)."""
    t = np.linspace(-sh.z, sh.z, grid)
    dd = sh.delta[:, None] + sh.delta_se[:, None] * t  # (N, g)
    bb = np.exp(sh.log_beta[:, None] + sh.log_beta_se[:, None] * t)  # (N, g)
    lb = _log(base) - sh.m
    x = sh.m + dd[:, :, None, None] + bb[:, None, :, None] * lb  # (N, g, g, M)
    return np.exp(x.reshape(len(dd), grid * grid, lb.size))


def paired_evidence(
    base: np.ndarray,
    c: np.ndarray,
    v: np.ndarray,
    ref: float | None = None,
    h: float = 0.0,
    stretch: bool = False,
) -> dict[str, np.ndarray]:
    """The evidence of a row at N vectors (for :func:`sim.claims.inference.status`): the
    median of the mapped blocks at the estimate, the lowest 2.5 % and highest 97.5 % point
    and (one-plate, with ``ref`` and its rounding half-unit ``h``) the largest ``p`` over the
    lattice (:func:`sim.claims.book_region.sample_evidence` at every lattice point). A vector
    whose blocks are not all finite and positive gets NaN (undecided). ``stretch``: the
    spread's scale over its interval at every vector, tested or not (:mod:`.joint`)."""
    sh = paired_shift(c, v).map_of(stretch)
    x = mapped(np.asarray(base, float), sh)
    n, g, m = x.shape
    ok = np.isfinite(x).all(axis=(1, 2))
    ev = sample_evidence(np.where(ok[:, None, None], x, 1.0).reshape(n * g, m), ref, h)
    ev = {q: a.reshape(n, g) for q, a in ev.items()}
    mid = g // 2
    out = {"value": ev["value"][:, mid], "low": ev["low"].min(1), "high": ev["high"].max(1)}
    if "p" in ev:
        out["p"] = ev["p"].max(1)
    out = {q: np.where(ok, a, np.nan) for q, a in out.items()}
    return {**out, "plates": np.full(n, m)}  # the configured blocks behind every vector


def variance_ratio(s_u: float, s_w: float, rho: float) -> float:
    """Var(paired shift) / Var(shift from independent blocks) for samples of sds ``s_u``,
    ``s_w`` and correlation ``rho``: ``1 - 2 rho s_u s_w / (s_u^2 + s_w^2)`` (``1 - rho``
    when the sds are equal)."""
    return 1.0 - 2.0 * rho * s_u * s_w / (s_u**2 + s_w**2)
