"""Datum of a free network: S-transformations of point covariances and error vectors.

Seed: ``004_f5bd9e86c308241f.txt`` (Brown 1968). Coordinates recovered by a self-calibrating
multilateration have no precision of their own apart from the datum that fixes them: Brown's
datum ``x1 = x3 = 0, y4 = -y2`` leans on the station estimates. The S-transformation
(Baarda) moves a cofactor matrix ``Q`` of the points (``2n x 2n``, order x1, y1, x2, ...) into
the datum defined by minimal constraints ``H^T W (x - x0) = 0``::

    S = I - H (H^T W H)^-1 H^T W,        Q_S = S Q S^T,       e_S = S e

with ``H`` ``(2n, d)`` the null space of the network (translations and rotation, ``d = 3``;
with a scale column ``d = 4`` when a similarity is fitted) and ``W`` a diagonal 0/1
selection of the datum points. ``W = I``, ``d = 3`` is the inner-constraint (minimum trace)
datum over all points. Selecting four corner points with a 4-column ``H`` gives the
coordinates after the least-squares similarity transformation onto the corners' reference
coordinates, the step a user applies in practice (reference coordinates taken as exact).
Since ``S H = 0`` and any two datums differ by a term ``H t``, ``Q_S`` is the same whichever
datum ``Q`` started in: the datum-invariant precision. Units: whatever ``Q`` is in.
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "null_basis",
    "s_matrix",
    "s_transform",
    "inner",
    "similarity_onto",
    "corner_indices",
    "point_sigmas",
    "result_in_datum",
]


def null_basis(points: np.ndarray, scale: bool = False) -> np.ndarray:
    """Columns spanning translation x, translation y, rotation (and scale) of the points,
    about their centroid, normalised; ``points`` ``(..., n, 2)`` -> ``(..., 2n, 3|4)``."""
    c = points - points.mean(axis=-2, keepdims=True)
    sh = points.shape[:-2]
    n = points.shape[-2]
    one, zero = np.ones(sh + (n,)), np.zeros(sh + (n,))
    cols = [
        np.stack([one, zero], -1),
        np.stack([zero, one], -1),
        np.stack([-c[..., 1], c[..., 0]], -1),
    ]
    if scale:
        cols.append(c)
    H = np.stack([x.reshape(sh + (2 * n,)) for x in cols], -1)
    return H / np.linalg.norm(H, axis=-2, keepdims=True)


def s_matrix(H: np.ndarray, w: np.ndarray | None = None) -> np.ndarray:
    """``S = I - H (H^T W H)^-1 H^T W`` for ``H`` ``(..., m, d)`` and diagonal ``w`` ``(m,)``."""
    m = H.shape[-2]
    w = np.ones(m) if w is None else np.asarray(w, float)
    HtW = np.swapaxes(H, -1, -2) * w
    return np.eye(m) - H @ np.linalg.solve(HtW @ H, HtW)


def s_transform(Q: np.ndarray, S: np.ndarray) -> np.ndarray:
    """``S Q S^T`` (batched)."""
    return S @ Q @ np.swapaxes(S, -1, -2)


def corner_indices(points: np.ndarray) -> np.ndarray:
    """Indices of the four points nearest the corners of their bounding square, ``(4,)``."""
    ext = np.abs(points).max()
    corners = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]]) * ext
    d = np.linalg.norm(points[None, :, :] - corners[:, None, :], axis=-1)
    return np.argmin(d, axis=1)


def _weights(n: int, idx) -> np.ndarray:
    w = np.zeros(2 * n)
    idx = np.asarray(idx)
    w[2 * idx] = 1.0
    w[2 * idx + 1] = 1.0
    return w


def inner(points: np.ndarray) -> np.ndarray:
    """S matrix of the inner-constraint datum over all ``points`` ``(..., n, 2)``."""
    return s_matrix(null_basis(points))


def similarity_onto(points: np.ndarray, idx, scale: bool = True) -> np.ndarray:
    """S matrix of a least-squares similarity (``scale=True``) or rigid transformation onto
    the reference points ``idx``: ``e_S = S e`` are the coordinate errors after the fit."""
    return s_matrix(null_basis(points, scale=scale), _weights(points.shape[-2], idx))


def point_sigmas(Q: np.ndarray) -> np.ndarray:
    """Per-point ``(sigma_x, sigma_y)`` from a full ``(..., 2n, 2n)`` cofactor: ``(..., n, 2)``."""
    d = np.sqrt(np.maximum(np.einsum("...ii->...i", Q), 0.0))
    return d.reshape(d.shape[:-1] + (-1, 2))


def result_in_datum(result, S: np.ndarray) -> np.ndarray:
    """Full point cofactor ``(T, 2n, 2n)`` of an engine result (:class:`sim.lsq.Result`,
    e.g. from :func:`sim.instruments.ranges.positions.adjust`) moved into the datum of ``S``."""
    return s_transform(result.full_point_cofactor(), S)
