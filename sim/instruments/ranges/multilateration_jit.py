"""Compiled Gauss-Newton kernel for Brown's multilateration (optional, via numba).

The same model, parameterisation and reduction as the NumPy engine in
:mod:`sim.instruments.ranges.multilateration` (seed ``004_f5bd9e86c308241f.txt``): ranges
``r = sqrt(d^2 - b) - alpha`` with ``b = beta^2``, Brown's datum, the 2x2 point blocks
eliminated per point (reduced normal equations, Brown's EMBET), a scaled Cholesky solve of
the p x p reduced normals (p <= 7), convergence when the largest correction -- or the
remaining error estimated from the observed contraction, rho / (1 - rho) x correction with
rho the ratio of the last two corrections -- is below the tolerance. No Python runs per
trial: the kernel (source :mod:`sim.instruments.ranges.multilateration_kernel`) is compiled
by :func:`sim.lsq.compile.compiled` and adjusts ``LANES`` trials at a time in lock-step with
the trial axis innermost, so the compiler turns each sweep over the trials into SIMD
instructions. Each trial's arithmetic is the scalar algorithm's, operation for operation, so
the results are bit-identical whatever the lane width; a test checks this.

Status codes as in :class:`sim.lsq.Result`: 0 converged, 1 iteration limit, 2 singular
normals (a point block by the engine's rule :func:`sim.lsq.normals.block2_rcond`), 3
non-finite corrections; and
:data:`~sim.instruments.ranges.multilateration_kernel.UNDECIDED` (4) where the kernel could
not prove the reduced normals regular by the engine's rule (the caller re-runs those trials
on the NumPy engine).
"""

from __future__ import annotations

import numpy as np

from sim.instruments.ranges.multilateration_kernel import _kernel, _lane_stations, _start
from sim.lsq import compile
from sim.lsq.normals import RCOND, block2_rcond

__all__ = ["available", "LANES", "gauss_newton", "use_lanes"]

LANES = 64  # trials per SIMD block; 8 or 16 leave the sweeps scalar (see make bench)
_LANE_BYTES = 216  # bytes of lane arrays per point and lane (R, X, Y, K, Ninv, up, D)
_MAX_LANE_MEMORY = 256 * 2**20


def available() -> bool:
    """Whether the compiled kernel runs (:func:`sim.lsq.compile.available`)."""
    return compile.available()


def gauss_newton(
    r_obs: np.ndarray,
    theta: np.ndarray,
    pts: np.ndarray | None,
    p: int,
    tol: float,
    max_iter: int,
    rcond: float = RCOND,
):
    """Run the compiled kernel in place on ``theta`` (T, 7) (and ``pts`` (T, n, 2); None:
    start from linear trilateration). Needs :func:`available`.

    Returns ``(points, status, iterations, residuals, sum of squared residuals)``.
    """
    r_obs = np.ascontiguousarray(r_obs, dtype=np.float64)
    T, n, _ = r_obs.shape
    if pts is None:
        pts = np.empty((T, n, 2))
        compile.compiled(_start)(r_obs, theta, pts)
    status = np.ones(T, np.int8)
    iters = np.zeros(T, np.int32)
    res = np.empty((T, n, 4))
    ssq = np.empty(T)
    idx, cnt = _sparsity(p)
    width = LANES if use_lanes(T, n) else 1
    kernel = compile.compiled(_kernel, helpers=(_lane_stations, block2_rcond))
    kernel(
        r_obs, theta, pts, int(p), float(tol), int(max_iter), float(rcond),
        status, iters, idx, cnt, res, ssq, width,
    )  # fmt: skip
    return pts, status, iters, res, ssq


def use_lanes(trials: int, points: int) -> bool:
    """The SIMD kernel for batches of at least half a block whose lane arrays fit in
    ``_MAX_LANE_MEMORY`` (about 19,000 points); one trial at a time otherwise."""
    return 2 * trials >= LANES and points * LANES * _LANE_BYTES <= _MAX_LANE_MEMORY


def _sparsity(p: int):
    """Global indices touched by each station's readings (those < p), in the order the kernel
    fills ``g``: station coordinates, then alpha (5), then b (6)."""
    rows = ([0, 5, 6], [1, 2, 5, 6], [3, 5, 6], [2, 4, 5, 6])
    idx = np.zeros((4, 4), np.int64)
    cnt = np.zeros(4, np.int64)
    for k, r in enumerate(rows):
        keep = [g for g in r if g < p]
        idx[k, : len(keep)] = keep
        cnt[k] = len(keep)
    return idx, cnt
