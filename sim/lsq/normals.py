"""Shared numerics of the engine: the scaled singularity rule, small symmetric inverses, the
Schur-complement reduction of the normal equations and the bordered (datum) solve.

Seed of the method: Brown 1968 (``004_f5bd9e86c308241f.txt``), whose EMBET eliminates every
point's 2 x 2 block before the globals are solved ("reduced normal equations"). Everything is
batched over a leading trial axis ``T``; no Python loop runs per trial.

Normal equations, per trial, of observations ``r`` (observed minus computed) with diagonal
weights ``w`` and Jacobians ``Jp`` (point blocks, ``d`` unknowns each) and ``Jg`` (the ``p``
free globals)::

    [Npp  Npg] [dp]   [up]        Npp = Jp^T W Jp (block diagonal, one d x d block per point)
    [Npg' Ngg] [dg] = [ug]        Nbar = Ngg - Npg' Npp^-1 Npg,  ubar = ug - Npg' Npp^-1 up

so the largest solve per trial is ``p x p`` (bordered by the ``c`` datum constraints
``C' dg = 0``: ``(p + c) x (p + c)``) and the cost is linear in the number of points.

**The singularity rule** (:func:`scaled_rcond`): a symmetric matrix is scaled to unit
diagonal (rows with a zero diagonal, the constraint rows of a bordered matrix, are left
unscaled; the constraint columns are normalised), and it is singular when the ratio of its
smallest to its largest eigenvalue modulus is not above ``rcond`` (default :data:`RCOND`,
ten digits lost) or any entry is not finite. The same rule is applied to every point block
and to the (bordered) reduced normals; a singular trial is flagged, never raised.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = [
    "RCOND",
    "scaled_rcond",
    "inv_blocks",
    "Reduced",
    "reduce",
    "reduce_blocks",
    "reduced_normals",
    "bordered_solve",
    "bordered_inverse",
]

#: default reciprocal condition number below which a scaled matrix counts as singular
RCOND = 1e-10


def scaled_rcond(M: np.ndarray) -> np.ndarray:
    """Ratio of the smallest to the largest |eigenvalue| of the symmetric ``M`` ``(..., m, m)``
    scaled to unit diagonal; 0 where an entry is not finite. Shape ``(...)``."""
    m = M.shape[-1]
    d = np.abs(np.einsum("...ii->...i", M))
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        s = np.where(d > 0, 1.0 / np.sqrt(d), 1.0)
        C = M * s[..., :, None] * s[..., None, :]
    fin = np.isfinite(C).all(axis=(-1, -2))
    C = np.where(fin[..., None, None], C, np.eye(m))
    if m == 1:
        rc = (np.abs(C[..., 0, 0]) > 0).astype(float)
    elif m == 2:  # closed form: eigenvalues t/2 +- sqrt(((a - c)/2)^2 + b^2)
        a, b, c = C[..., 0, 0], C[..., 0, 1], C[..., 1, 1]
        h, g = 0.5 * (a + c), np.sqrt((0.5 * (a - c)) ** 2 + b * b)
        l1, l2 = np.abs(h + g), np.abs(h - g)
        with np.errstate(divide="ignore", invalid="ignore"):
            rc = np.minimum(l1, l2) / np.maximum(l1, l2)
    else:
        ev = np.abs(np.linalg.eigvalsh(C))
        with np.errstate(divide="ignore", invalid="ignore"):
            rc = ev.min(-1) / ev.max(-1)
    return np.where(fin & np.isfinite(rc), rc, 0.0)


def _inv2(N, rcond, out, good):  # pragma: no cover - compiled
    """:func:`inv_blocks` of 2 x 2 blocks ``N`` (B, 2, 2) into ``out``, ``good`` (B,): the
    arithmetic of :func:`scaled_rcond`'s closed form and of the NumPy inverse, operation for
    operation (no reassociation), in one pass."""
    for k in range(N.shape[0]):
        m00, m01, m11 = N[k, 0, 0], N[k, 0, 1], N[k, 1, 1]
        d0, d1 = abs(m00), abs(m11)
        s0 = 1.0 / np.sqrt(d0) if d0 > 0 else 1.0
        s1 = 1.0 / np.sqrt(d1) if d1 > 0 else 1.0
        a, b, c = m00 * s0 * s0, m01 * s0 * s1, m11 * s1 * s1
        fin = (
            np.isfinite(a)
            and np.isfinite(b)
            and np.isfinite(c)
            and np.isfinite(N[k, 1, 0] * s1 * s0)
        )
        rc = 0.0
        if fin:
            h, g = 0.5 * (a + c), np.sqrt((0.5 * (a - c)) ** 2 + b * b)
            l1, l2 = abs(h + g), abs(h - g)
            rc = min(l1, l2) / max(l1, l2)
            if not np.isfinite(rc):
                rc = 0.0
        ok = rc > rcond
        good[k] = ok
        if not ok:
            m00, m01, m11 = 1.0, 0.0, 1.0
        inv = 1.0 / (m00 * m11 - m01 * m01)
        out[k, 0, 0] = m11 * inv
        out[k, 0, 1] = -m01 * inv
        out[k, 1, 0] = -m01 * inv
        out[k, 1, 1] = m00 * inv


def inv_blocks(N: np.ndarray, rcond: float = RCOND):
    """Inverse of symmetric blocks ``N`` ``(T, n, d, d)`` and ``ok`` ``(T,)`` (every block of
    the trial regular by the scaled rule). Singular blocks are replaced by the identity.
    2 x 2 blocks run compiled where numba is present (the same arithmetic)."""
    d = N.shape[-1]
    if d == 2:
        from sim.lsq import group_kernel

        if group_kernel.available():
            T, n = N.shape[:2]
            out, good = np.empty((T * n, 2, 2)), np.empty(T * n, np.bool_)
            group_kernel.compiled(_inv2)(
                np.ascontiguousarray(N, dtype=np.float64).reshape(T * n, 2, 2),
                float(rcond),
                out,
                good,
            )
            return out.reshape(T, n, 2, 2), good.reshape(T, n).all(axis=1)
    good = scaled_rcond(N) > rcond  # (T, n)
    ok = good.all(axis=1)
    Ns = np.where(good[..., None, None], N, np.eye(d))
    if d == 1:
        return 1.0 / Ns, ok
    if d == 2:
        a, b, c = Ns[..., 0, 0], Ns[..., 0, 1], Ns[..., 1, 1]
        inv = 1.0 / (a * c - b * b)
        return np.stack(
            [np.stack([c * inv, -b * inv], -1), np.stack([-b * inv, a * inv], -1)], -2
        ), ok
    return np.linalg.inv(Ns), ok


@dataclass
class Reduced:
    """Normal equations after eliminating the point blocks (one linearisation point).

    Ninv : (T, n, d, d) inverse point blocks; K : (T, n, d, p) = Npp^-1 Npg; Nbar : (T, p, p);
    ubar : (T, p); dp0 : (T, n, d) the point corrections for ``dg = 0``; ok : (T,) all point
    blocks regular.
    """

    Ninv: np.ndarray
    K: np.ndarray
    Nbar: np.ndarray
    ubar: np.ndarray
    dp0: np.ndarray
    ok: np.ndarray

    def points_step(self, dg: np.ndarray) -> np.ndarray:
        """Point corrections ``dp0 - K dg`` ``(T, n, d)`` for the global corrections ``dg``."""
        if dg.shape[-1] == 0:
            return self.dp0
        return self.dp0 - np.einsum("tnip,tp->tni", self.K, dg)


def reduce(r, Jp, Jg, w=None, rcond: float = RCOND) -> Reduced:
    """Form the normal equations and eliminate the point blocks (Schur complement).

    r : (T, n, k) misclosures; Jp : (T, n, k, d) or None (no point unknowns); Jg :
    (T, n, k, p) Jacobian of the free globals or None; w : weights broadcastable to
    (T, n, k) or None (unit weights).
    """
    T, n, k = r.shape
    wr = r if w is None else w * r
    p = 0 if Jg is None else Jg.shape[-1]
    if Jp is None or Jp.shape[-1] == 0:
        d = 0
        Ninv = np.zeros((T, n, 0, 0))
        dp0 = np.zeros((T, n, 0))
        ok = np.ones(T, bool)
    else:
        d = Jp.shape[-1]
        WJp = Jp if w is None else w[..., None] * Jp
        Npp = np.swapaxes(WJp, -1, -2) @ Jp  # (T, n, d, d)
        Ninv, ok = inv_blocks(Npp, rcond)
        up = np.einsum("tnki,tnk->tni", Jp, wr)
        dp0 = (Ninv @ up[..., None])[..., 0]
    if p == 0:
        return Reduced(Ninv, np.zeros((T, n, d, 0)), np.zeros((T, 0, 0)), np.zeros((T, 0)), dp0, ok)
    Jf = Jg.reshape(T, n * k, p)
    WJf = Jf if w is None else (np.broadcast_to(w, r.shape).reshape(T, n * k, 1) * Jf)
    Nbar = np.swapaxes(WJf, -1, -2) @ Jf
    ubar = (np.swapaxes(Jf, -1, -2) @ wr.reshape(T, n * k, 1))[..., 0]
    if d == 0:
        return Reduced(Ninv, np.zeros((T, n, 0, p)), Nbar, ubar, dp0, ok)
    Npg = np.swapaxes(WJp, -1, -2) @ Jg  # (T, n, d, p)
    return _eliminate(Ninv, ok, up, dp0, Npg, Nbar, ubar)


def _eliminate(Ninv, ok, up, dp0, Npg, Ngg, ug) -> Reduced:
    T, n, d, p = Npg.shape
    K = Ninv @ Npg
    Kt = K.reshape(T, n * d, p).transpose(0, 2, 1)
    Nbar = Ngg - Kt @ Npg.reshape(T, n * d, p)
    ubar = ug - (Kt @ up.reshape(T, n * d, 1))[..., 0]
    return Reduced(Ninv, K, Nbar, ubar, dp0, ok)


def reduce_blocks(Npp, up, Npg, Ngg, ug, rcond: float = RCOND) -> Reduced:
    """:func:`reduce` from normal-equation blocks that a model formed itself -- the route of
    a model whose Jacobian is mostly zero (each observation touching one point and a few
    globals, e.g. one station's coordinates in :mod:`sim.instruments.ranges.positions`), which then never
    builds the dense ``(T, n, k, p)`` Jacobian.

    Npp : (T, n, d, d) point blocks; up : (T, n, d); Npg : (T, n, d, p); Ngg : (T, p, p);
    ug : (T, p) (``Jp' W r``, ``Jp' W Jg``, ``Jg' W Jg``, ``Jg' W r`` of the free globals).
    The same elimination and singularity rule as :func:`reduce`.
    """
    Ninv, ok = inv_blocks(Npp, rcond)
    dp0 = (Ninv @ up[..., None])[..., 0]
    if Npg.shape[-1] == 0:
        return Reduced(Ninv, Npg, Ngg, ug, dp0, ok)
    return _eliminate(Ninv, ok, up, dp0, Npg, Ngg, ug)


def reduced_normals(model, points, theta, free, rcond: float = RCOND):
    """The reduced normals of ``model`` at one linearisation point: the model's own
    elimination (``model.reduced``, for Jacobians that are mostly zero: from blocks it forms
    itself, e.g. with :func:`reduce_blocks`) when it has one, else from its dense Jacobians
    (:func:`reduce`)."""
    own = getattr(model, "reduced", None)
    if own is not None:
        return own(points, theta, free, rcond)
    p = len(free)
    lin = model.linearize(points, theta, p > 0)
    return reduce(lin.r, lin.Jp, lin.Jg[..., free] if p else None, lin.w, rcond)


def _scaled_system(N: np.ndarray, C: np.ndarray | None):
    """The bordered matrix scaled to unit diagonal, and the scale ``s`` (T, p)."""
    T, p, _ = N.shape
    dg = np.abs(np.einsum("tii->ti", N))
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        s = np.where(dg > 0, 1.0 / np.sqrt(dg), 1.0)
        Ns = N * s[:, :, None] * s[:, None, :]
    if C is None or C.shape[-1] == 0:
        return Ns, s
    Cs = C * s[:, :, None]
    with np.errstate(divide="ignore", invalid="ignore"):
        Cs = Cs / np.linalg.norm(Cs, axis=1, keepdims=True)
    c = C.shape[-1]
    M = np.zeros((T, p + c, p + c))
    M[:, :p, :p] = Ns
    M[:, :p, p:] = Cs
    M[:, p:, :p] = Cs.transpose(0, 2, 1)
    return M, s


def _safe(M: np.ndarray, ok: np.ndarray) -> np.ndarray:
    return np.where(ok[:, None, None], M, np.eye(M.shape[-1]))


def _screened_inverse(M: np.ndarray, rcond: float):
    """Inverse of the symmetric ``M`` (T, m, m) and the scaled rule on it, ``ok`` (T,): the
    same decisions as ``scaled_rcond(M) > rcond``, with the eigenvalues computed only where a
    cheap bound cannot decide. With ``C = S M S`` the unit-diagonal matrix of the rule
    (:func:`scaled_rcond`), ``|lambda|max(C) <= ||C||_F`` and ``1 / |lambda|min(C) <=
    ||C^-1||_F <= ||M^-1||_F / min(s)^2``, so ``min(s)^2 / (||C||_F ||M^-1||_F)`` is a lower
    bound of the ratio; trials whose bound is above ``4 rcond`` (a margin for the rounding of
    the inverse) are regular. Returns ``(Minv, ok)``, ``Minv`` None when the factorisation of a
    trial failed outright (then every trial gets the full rule). Non-finite trials are
    singular."""
    m = M.shape[-1]
    fin = np.isfinite(M).all(axis=(1, 2))
    Ms = np.where(fin[:, None, None], M, np.eye(m))
    try:
        Minv = np.linalg.inv(Ms)
    except np.linalg.LinAlgError:
        return None, scaled_rcond(M) > rcond
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        d = np.abs(np.einsum("tii->ti", Ms))
        sc = np.where(d > 0, 1.0 / np.sqrt(d), 1.0)
        Cs = Ms * sc[:, :, None] * sc[:, None, :]
        lb = sc.min(axis=1) ** 2 / (
            np.sqrt(np.einsum("tij,tij->t", Cs, Cs)) * np.sqrt(np.einsum("tij,tij->t", Minv, Minv))
        )
    ok = fin & (lb > 4.0 * rcond)
    rest = fin & ~ok
    if rest.any():
        ok[rest] = scaled_rcond(M[rest]) > rcond
    return Minv, ok


def bordered_solve(Nbar, ubar, C=None, rcond: float = RCOND):
    """Solve ``Nbar dg = ubar`` subject to ``C' dg = 0`` (``C`` (T, p, c) or None) on the
    scaled system. Returns ``(dg (T, p), ok (T,))``; singular trials get ``dg = 0``."""
    T, p = ubar.shape
    M, s = _scaled_system(Nbar, C)
    Minv, ok = _screened_inverse(M, rcond)
    rhs = np.zeros((T, M.shape[-1]))
    rhs[:, :p] = np.where(np.isfinite(ubar), ubar, 0.0) * s
    if Minv is not None:  # the rule's inverse solves the system too
        y = np.einsum("tij,tj->ti", Minv, rhs)
    else:
        try:
            y = np.linalg.solve(_safe(M, ok), rhs[..., None])[..., 0]
        except np.linalg.LinAlgError:  # exactly singular although above rcond: never raise
            y = (np.linalg.pinv(_safe(M, ok)) @ rhs[..., None])[..., 0]
    return np.where(ok[:, None], y[:, :p] * s, 0.0), ok


def bordered_inverse(Nbar, C=None, rcond: float = RCOND):
    """Cofactor ``Qgg`` (T, p, p) of the globals in the datum ``C' dg = 0`` (the top-left block
    of the bordered inverse) and ``ok`` (T,); NaN for singular trials."""
    p = Nbar.shape[-1]
    M, s = _scaled_system(Nbar, C)
    Minv, ok = _screened_inverse(M, rcond)
    if Minv is None:
        try:
            Minv = np.linalg.inv(_safe(M, ok))
        except np.linalg.LinAlgError:  # exactly singular although above rcond: never raise
            Minv, ok = np.full_like(M, np.nan), ok.copy()
            for t in np.flatnonzero(ok):
                try:
                    Minv[t] = np.linalg.inv(M[t])
                except np.linalg.LinAlgError:
                    ok[t] = False
    Q = Minv[:, :p, :p] * s[:, :, None] * s[:, None, :]
    Q[~ok] = np.nan
    return Q, ok
