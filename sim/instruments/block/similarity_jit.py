"""Compiled linearisation of the independent-model similarity (optional, via numba).

Seed: ``003_5ce730a990a7ebc5.txt`` (Agnard, Nolette & Gagnon), the block of independent
models of :mod:`sim.instruments.block.independent_models`. For observation ``k`` of model ``m`` on point ``j``
the computed value is ``y + t'_m`` with ``y = s_m R_m (x_k - c_m)``; the misclosure
``r_k = X_j - (y + t'_m)`` (m) and the Jacobian with respect to the model corrections
``(dl, dtheta, dt)``: ``[y, -skew(y), I]`` (3 x 7). The same operations in the same order
as the NumPy code of :meth:`sim.instruments.block.independent_models.SimilarityModel.linearize` (one pass over
the observations instead of a dozen temporaries of the whole batch); a test holds the two
equal. numba is imported on first use (cached on disk); without it, or with ``SIM_NO_JIT``
set, :func:`linearize` returns None and the NumPy code runs.
"""

from __future__ import annotations

import numpy as np

__all__ = ["linearize"]


def _linearize(xm, c, theta, X, om, op, r, J):  # pragma: no cover - compiled
    T, K = xm.shape[0], xm.shape[1]
    d = np.empty(3)
    y = np.empty(3)
    for t in range(T):
        for k in range(K):
            m, j = om[k], op[k]
            s = theta[t, m, 0]
            for a in range(3):
                d[a] = xm[t, k, a] - c[t, m, a]
            for i in range(3):
                y[i] = s * (
                    theta[t, m, 1 + 3 * i] * d[0]
                    + theta[t, m, 2 + 3 * i] * d[1]
                    + theta[t, m, 3 + 3 * i] * d[2]
                )
            for i in range(3):
                r[t, k, i] = -((y[i] + theta[t, m, 10 + i]) - X[t, j, i])
                for q in range(7):
                    J[t, k, i, q] = 0.0
                J[t, k, i, 0] = y[i]
                J[t, k, i, 4 + i] = 1.0
            J[t, k, 0, 2] = y[2]
            J[t, k, 0, 3] = -y[1]
            J[t, k, 1, 1] = -y[2]
            J[t, k, 1, 3] = y[0]
            J[t, k, 2, 1] = y[1]
            J[t, k, 2, 2] = -y[0]


def _compiled():
    from sim.lsq import group_kernel

    # numba missing or SIM_NO_JIT: None, and the NumPy code runs
    return group_kernel.compiled(_linearize) if group_kernel.available() else None


def linearize(xm, c, theta, X, om, op):
    """``(r (T, K, 3), J (T, K, 3, 7))`` as described above, or None without numba."""
    k = _compiled()
    if k is None:
        return None
    T, K = xm.shape[:2]
    r, J = np.empty((T, K, 3)), np.empty((T, K, 3, 7))
    f = lambda a: np.ascontiguousarray(a, dtype=np.float64)  # noqa: E731
    k(f(xm), f(c), f(theta), f(X), np.asarray(om, np.int64), np.asarray(op, np.int64), r, J)
    return r, J
