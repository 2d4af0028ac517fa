"""Compiled Gauss-Newton kernel for Brown's multilateration (optional, via numba).

The same model, parameterisation and reduction as the NumPy engine in
:mod:`sim.instruments.ranges.multilateration` (seed ``004_f5bd9e86c308241f.txt``): ranges
``r = sqrt(d^2 - b) - alpha`` with ``b = beta^2``, Brown's datum, the 2x2 point blocks
eliminated per point (reduced normal equations, Brown's EMBET), a scaled Cholesky solve of
the p x p reduced normals (p <= 7), convergence when the largest correction -- or the
remaining error estimated from the observed contraction, rho / (1 - rho) x correction with
rho the ratio of the last two corrections -- is below the tolerance. No Python runs per
trial: the kernel is compiled, and it adjusts ``LANES`` trials at a time in lock-step with
the trial axis innermost, so the compiler turns each sweep over the trials into SIMD
instructions (AVX on x86). Each trial's arithmetic is the scalar algorithm's, operation for
operation, so the results are bit-identical whatever the lane width; a test checks this.
The NumPy engine stays the reference implementation and the tests require both to agree.
The kernel's source is :mod:`sim.instruments.ranges.multilateration_kernel`; this module compiles it (per lane
width), starts the points and dispatches.

Status codes as in :class:`sim.instruments.ranges.multilateration.AdjustResult`: 0 converged, 1 iteration limit,
2 singular normals (a 2x2 point block with det below ``rcond`` of its scale, or a squared
Cholesky pivot of the scaled reduced normals below ``rcond_g`` = 1e-10, i.e. a condition
number of about 1e10: ten digits lost), 3 non-finite corrections.
"""

from __future__ import annotations

import numpy as np

from sim.instruments.ranges.multilateration_kernel import (  # the kernel's source
    _kernel,
    _lane_stations,
    _start,
)

try:
    from numba import njit

    AVAILABLE = True
except ImportError:  # pragma: no cover - the NumPy engine is used instead
    AVAILABLE = False

__all__ = ["AVAILABLE", "LANES", "gauss_newton"]

LANES = 64  # trials per SIMD block; 8 or 16 leave the sweeps scalar (see make bench)
_LANE_BYTES = 216  # bytes of lane arrays per point and lane (R, X, Y, K, Ninv, up, D)
_MAX_LANE_MEMORY = 256 * 2**20


def _compile(fn, name: str, width: int):
    """``fn`` compiled with the global ``W`` frozen to ``width`` (numba treats globals as
    compile-time constants), cached on disk under its own name."""
    import types

    glb = dict(fn.__globals__, W=width, _lane_stations=_lane_stations)  # the compiled one
    f = types.FunctionType(fn.__code__, glb, name, fn.__defaults__, fn.__closure__)
    f.__qualname__ = name
    # error_model="numpy": no ZeroDivisionError branches, which would block vectorisation
    return njit(cache=True, error_model="numpy")(f)


if AVAILABLE:
    _lane_stations = njit(cache=True)(_lane_stations)
    _kernel_lanes = _compile(_kernel, "_kernel_lanes", LANES)
    _kernel_one = _compile(_kernel, "_kernel_one", 1)
    _start = njit(cache=True)(_start)


def gauss_newton(
    r_obs: np.ndarray,
    theta: np.ndarray,
    pts: np.ndarray | None,
    p: int,
    tol: float,
    max_iter: int,
    rcond: float = 1e-13,
    rcond_g: float = 1e-10,
):
    """Run the compiled kernel in place on ``theta`` (T, 7) (and ``pts`` (T, n, 2); None:
    start from linear trilateration). Needs numba (:data:`AVAILABLE`).

    Returns ``(points, status, iterations, residuals, sum of squared residuals)``.
    """
    if not AVAILABLE:
        raise RuntimeError("numba is not installed")
    r_obs = np.ascontiguousarray(r_obs, dtype=np.float64)
    T, n, _ = r_obs.shape
    if pts is None:
        pts = np.empty((T, n, 2))
        _start(r_obs, theta, pts)
    status = np.ones(T, np.int8)
    iters = np.zeros(T, np.int32)
    res = np.empty((T, n, 4))
    ssq = np.empty(T)
    idx, cnt = _sparsity(p)
    kernel = _kernel_lanes if use_lanes(T, n) else _kernel_one
    kernel(
        r_obs,
        theta,
        pts,
        int(p),
        float(tol),
        int(max_iter),
        float(rcond),
        float(rcond_g),
        status,
        iters,
        idx,
        cnt,
        res,
        ssq,
    )
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
