"""The one linear least-squares routine of the library: the one-step special case of the engine.

Model, per trial ``t`` (leading trial axis ``T``), with ``k`` right-hand sides that share the
design (e.g. the x and y rows of an affine, the x and y corrections of a polynomial)::

    b_t = A_t x_t + v_t,     minimise  v_t' W_t v_t     (W_t = diag(w_t))
    x_t = Q_t A_t' W_t b_t,  Q_t = (A_t' W_t A_t)^-1    (the cofactor matrix)

``s0^2 = sum_k v_k' W v_k / (k (m - p))`` is the a-posteriori variance of unit weight (pooled
over the right-hand sides), ``cov = s0^2 Q`` (or ``sigma^2 Q`` with an a-priori ``sigma``).

**The singularity rule** is the engine's one scaled rule (:func:`sim.lsq.normals.scaled_rcond`):
the normal matrix ``A' W A`` scaled to unit diagonal is singular when the ratio of its
smallest to its largest eigenvalue is not above ``rcond`` (default :data:`RCOND`), or when
the trial's design, weights or observations are not finite. A singular trial is flagged
(``status``, ``message``) with NaN solution and cofactor; it never raises and never stops
the other trials.

**Two paths.**

* *Shared design* (``A`` of shape ``(m, p)`` and weights shared by all trials, ``w`` of
  shape ``(m,)`` or none): ``sqrt(W) A = Q R`` is factorised once and every trial's
  right-hand side is solved by one operator, ``x = R^-1 Q' sqrt(W) b``: in a compiled
  kernel, one trial at a time in the cache, summing ``v' W v`` without storing the
  residuals (formed on first use, :attr:`LinearFit.residuals`); without numba in one matrix
  product over all trials (:mod:`sim.lsq.linear_kernel`).
* *Per-trial design* ``(T, m, p)`` (or per-trial weights): the designs of a Monte Carlo are
  perturbations of one nominal design, so the QR ``R0`` of the trial-mean (weighted) design
  is computed once and used as a right preconditioner: ``B_t = sqrt(W_t) A_t R0^-1`` is
  close to orthonormal, and its small normal equations ``B' B y = B' sqrt(W) b``,
  ``x = R0^-1 y``, are as accurate as a QR of each ``A_t`` (the condition of ``B' B`` is
  near 1) at the cost of two batched matrix products. Where the trial-mean design is itself
  singular the columns are equilibrated per trial instead.

Seed of the method: Brown 1968 (``004_f5bd9e86c308241f.txt``): least squares by normal
equations with the cofactors of the unknowns; Wolf & Pearsall 1976 (``000``) for the
polynomial calibration whose design is the same for every trial.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy import linalg

from sim.lsq import compile, linear_kernel
from sim.lsq.normals import RCOND, scaled_rcond

__all__ = ["LinearFit", "lstsq", "LINEAR_STATUS"]


#: per-trial status codes of :func:`lstsq` (the codes of the engine's ``STATUS`` where shared)
LINEAR_STATUS = {
    0: "solved",
    2: "singular normal equations (scaled reciprocal condition below rcond)",
    3: "non-finite design, weights or observations",
}


@dataclass
class LinearFit:
    """Result of :func:`lstsq` for ``T`` trials, ``p`` unknowns, ``m`` observations, ``k``
    right-hand sides.

    x : (T, p, k) solution (NaN where not solved); residuals : (T, m, k) ``b - A x``
    (observed minus adjusted); vtpv : (T, k) weighted square sums ``v' W v``; dof : ``m - p``
    per right-hand side; status : (T,) int8 (:data:`LINEAR_STATUS`); shared : whether the
    design was factorised once for all trials. :meth:`cofactor` gives ``Q`` (T, p, p).
    """

    x: np.ndarray
    _v: np.ndarray | None = field(repr=False)  # residuals, or None: formed when asked
    vtpv: np.ndarray
    dof: int
    status: np.ndarray
    shared: bool
    _P: np.ndarray | None = field(repr=False)  # (p, p) or (T, p, p) preconditioner
    _NBinv: np.ndarray | None = field(repr=False)  # (T, p, p) inverse of B'B (per trial)
    # (_P None: _NBinv is the cofactor itself, from a closed form such as the 2-D similarity)
    _Ab: tuple | None = field(default=None, repr=False)  # (A, b) to form the residuals from

    @property
    def residuals(self) -> np.ndarray:
        """``(T, m, k)`` residuals ``b - A x`` (NaN for unsolved trials); formed on first use
        where the solve summed ``v' W v`` without storing them (the compiled shared path),
        from the arrays given to :func:`lstsq` (not copied: do not change them in place
        before asking)."""
        if self._v is None:
            A, b = self._Ab
            self._v = b - _fitted(A, self.x)
        return self._v

    @property
    def ok(self) -> np.ndarray:
        """``(T,)`` True where the trial was solved."""
        return self.status == 0

    @property
    def message(self) -> np.ndarray:
        """Per-trial message ``(T,)`` of strings."""
        return np.array([LINEAR_STATUS[int(s)] for s in self.status], dtype=object)

    @property
    def s0(self) -> np.ndarray:
        """``(T,)`` a-posteriori standard error of unit weight, pooled over the right-hand
        sides (``k (m - p)`` degrees of freedom); NaN when there is no redundancy."""
        k = self.vtpv.shape[1]
        if self.dof <= 0:
            return np.full(self.vtpv.shape[0], np.nan)
        return np.sqrt(self.vtpv.sum(axis=1) / (k * self.dof))

    def cofactor(self) -> np.ndarray:
        """Cofactor matrix ``Q = (A' W A)^-1`` ``(T, p, p)`` (NaN for unsolved trials)."""
        T, p = self.x.shape[:2]
        if self._P is None:
            Q = np.array(self._NBinv, float)
        elif self._NBinv is None:  # shared: P = R^-1
            Q = np.broadcast_to(self._P @ self._P.T, (T, p, p)).copy()
        else:
            P = self._P
            Q = np.matmul(np.matmul(P, self._NBinv), np.swapaxes(P, -1, -2))
        Q[~self.ok] = np.nan
        return Q


def _prepare(A, b, w):
    A = np.asarray(A, float)
    b = np.asarray(b, float)
    if b.ndim not in (2, 3):
        raise ValueError(f"b must be (T, m) or (T, m, k) (got shape {b.shape})")
    squeeze = b.ndim == 2
    if squeeze:
        b = b[..., None]
    T, m, _ = b.shape
    if A.ndim not in (2, 3) or A.shape[-2] != m or (A.ndim == 3 and A.shape[0] != T):
        raise ValueError(f"A must be (m, p) or (T, m, p) matching b {b.shape} (got {A.shape})")
    if w is not None:
        w = np.asarray(w, float)
        if w.ndim == 2 and w.shape[0] == 1:
            w = w[0]
        if w.shape not in ((m,), (T, m)):
            raise ValueError(f"w must be (m,) or (T, m) (got shape {w.shape})")
    return A, b, w, squeeze


def lstsq(A, b, w=None, rcond: float = RCOND) -> LinearFit:
    """Weighted linear least squares over a leading trial axis (see the module docstring).

    Parameters
    ----------
    A : (m, p) design shared by every trial, or (T, m, p) per trial.
    b : (T, m) or (T, m, k) observations (``k`` right-hand sides sharing the design).
    w : optional non-negative weights per observation, (m,) shared or (T, m) per trial.
    rcond : threshold of the scaled singularity rule.

    Returns a :class:`LinearFit`; with ``b`` of shape (T, m) its ``x`` is still (T, p, 1).
    """
    A, b, w, _ = _prepare(A, b, w)
    T, m, k = b.shape
    p = A.shape[-1]
    if A.ndim == 2 and (w is None or w.ndim == 1):
        return _shared(A, b, w, rcond)
    fin_b = np.isfinite(b).all(axis=(1, 2))
    return _per_trial(np.broadcast_to(A, (T, m, p)), b, w, fin_b, rcond)


def _fitted(A, x):
    """``A x`` (T, m, k) for a shared (m, p) or per-trial (T, m, p) design."""
    if A.ndim == 3:
        return np.matmul(A, x)
    T, p, k = x.shape
    m = A.shape[0]
    return (A @ x.transpose(1, 0, 2).reshape(p, T * k)).reshape(m, T, k).transpose(1, 0, 2)


def _finish(A, b, w, x, status, shared, P, NBinv, v=None) -> LinearFit:
    """Residuals ``v = b - A x`` (or the given ``v``) and ``v' W v``; NaN solution where not
    solved."""
    bad = status != 0
    if bad.any():
        x[bad] = np.nan
    T, m, k = b.shape
    p = A.shape[-1]
    if v is None:
        v = b - _fitted(A, x)
    if w is None and k > 1:  # the same sums as below (over m in order), without a temporary
        vtpv = np.einsum("tmk,tmk->tk", v, v)
    else:
        vv = v * v if w is None else v * v * np.broadcast_to(w, (T, m))[..., None]
        vtpv = vv.sum(axis=1)
    return LinearFit(x, v, vtpv, m - p, status, shared, P, NBinv)


def _shared(A, b, w, rcond) -> LinearFit:
    """One factorisation for all trials: ``sqrt(W) A = Q R``; every trial's right-hand sides
    are solved by the compiled kernel (:func:`sim.lsq.linear_kernel.shared_solve`), or without
    numba in one matrix product (columns ``(trial, k)``) and one triangular solve, and their
    residuals in one more product."""
    T, m, k = b.shape
    p = A.shape[1]
    sw = np.ones(m) if w is None else np.sqrt(np.clip(w, 0.0, None))
    Aw = A * sw[:, None]
    good = bool(np.isfinite(Aw).all()) and m >= p and scaled_rcond(Aw.T @ Aw) > rcond
    if not good:
        status = np.full(T, 2 if np.isfinite(Aw).all() else 3, np.int8)
        return _finish(
            A, b, w, np.full((T, p, k), np.nan), status, True, np.full((p, p), np.nan), None
        )
    Qf, R = np.linalg.qr(Aw)  # once for all trials
    Rinv = linalg.solve_triangular(R, np.eye(p))
    if compile.available():  # x = R^-1 Q' sqrt(W) b per trial, in the cache
        x, vtpv, st = linear_kernel.shared_solve(Rinv @ (Qf.T * sw[None, :]), A, w, b)
        status = np.where(st == linear_kernel.SOLVED, 0, 3).astype(np.int8)
        return LinearFit(x, None, vtpv, m - p, status, True, Rinv, None, (A, b))
    fin_b = np.isfinite(b).all(axis=(1, 2))
    status = np.where(fin_b, 0, 3).astype(np.int8)
    plain = w is None and bool(fin_b.all())  # b needs no masking
    bw = b if plain else np.where(fin_b[:, None, None], b, 0.0) * sw[None, :, None]
    bT = bw.transpose(1, 0, 2).reshape(m, T * k)  # columns (trial, k)
    xT = linalg.solve_triangular(R, Qf.T @ bT, check_finite=False)  # all trials at once
    x = xT.reshape(p, T, k).transpose(1, 0, 2)
    if not plain or k == 1:
        return _finish(A, b, w, x, status, True, Rinv, None)
    own = not np.shares_memory(bT, b)  # bT a copy of b: residuals go there
    vT = np.subtract(bT, A @ xT, out=bT if own else None)
    return _finish(A, b, w, x, status, True, Rinv, None, vT.reshape(m, T, k).transpose(1, 0, 2))


def _equilibrated(Aw):
    """Column-equilibrated design ``B = Aw D`` and ``D`` (T, p, p) diagonal."""
    d = np.sqrt(np.einsum("tmi,tmi->ti", Aw, Aw))
    dinv = 1.0 / np.where(d > 0, d, 1.0)
    return Aw * dinv[:, None, :], dinv[:, :, None] * np.eye(Aw.shape[2])


def _screened_rule(N, NB, Q, cand, rcond):
    """The scaled rule ``scaled_rcond(N) > rcond`` for the trials ``cand`` (the same
    decisions), and ``inv(NB)`` (identity where not regular), or ``(ok, None)`` when an
    inverse failed outright. ``N = Q^-T NB Q^-1`` (``Q`` None: ``N = NB``), so
    ``N^-1 = Q NB^-1 Q'``; with ``C = S N S`` the unit-diagonal matrix of the rule,
    ``1 / (||C||_F ||C^-1||_F)`` is a lower bound of its eigenvalue ratio: the eigenvalues are
    computed only for trials whose bound is not above ``4 rcond``."""
    p = NB.shape[-1]
    try:
        NBinv = np.linalg.inv(np.where(cand[:, None, None], NB, np.eye(p)))
    except np.linalg.LinAlgError:
        return cand & (scaled_rcond(N) > rcond), None
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        Ninv = NBinv if Q is None else np.matmul(np.matmul(Q, NBinv), np.swapaxes(Q, -1, -2))
        d = np.abs(np.einsum("tii->ti", N))
        sc = np.where(d > 0, 1.0 / np.sqrt(d), 1.0)
        ss = sc[:, :, None] * sc[:, None, :]
        C, Cinv = N * ss, Ninv / ss
        lb = 1.0 / (
            np.sqrt(np.einsum("tij,tij->t", C, C)) * np.sqrt(np.einsum("tij,tij->t", Cinv, Cinv))
        )
    ok = cand & (lb > 4.0 * rcond)
    rest = cand & ~ok
    if rest.any():
        ok[rest] = scaled_rcond(N[rest]) > rcond
    return ok, np.where(ok[:, None, None], NBinv, np.eye(p))


def _per_trial(A, b, w, fin_b, rcond) -> LinearFit:
    T, m, k = b.shape
    p = A.shape[2]
    sw = None if w is None else np.sqrt(np.clip(np.broadcast_to(w, (T, m)), 0.0, None))
    Aw = A if sw is None else A * sw[..., None]
    bw = b if sw is None else b * sw[..., None]
    fin = fin_b & np.isfinite(Aw).all(axis=(1, 2))
    if not fin.all():
        Aw = np.where(fin[:, None, None], Aw, 0.0)
        bw = np.where(fin[:, None, None], bw, 0.0)
    R0 = None
    if fin.any():  # right preconditioner: R0 of the trial-mean design, factorised once
        Am = Aw.mean(axis=0) if fin.all() else Aw[fin].mean(axis=0)
        if m >= p and scaled_rcond(Am.T @ Am) > rcond:
            R0 = np.linalg.qr(Am, mode="r")
    if R0 is not None:
        R0inv = linalg.solve_triangular(R0, np.eye(p))
        B = (Aw.reshape(T * m, p) @ R0inv).reshape(T, m, p)
        NB = np.matmul(np.swapaxes(B, 1, 2), B)
        # Gershgorin: the eigenvalues of B'B lie within [1 - g, 1 + g]; keep R0 where g < 1/2
        near = np.abs(NB - np.eye(p)).sum(axis=-1).max(axis=-1) < 0.5
        P = np.broadcast_to(R0inv, (T, p, p))
        N = np.matmul(np.matmul(R0.T, NB), R0)  # A'WA for the rule
        if not near.all():
            far = ~near
            B[far], D = _equilibrated(Aw[far])
            NB[far] = np.matmul(np.swapaxes(B[far], 1, 2), B[far])
            d = 1.0 / np.einsum("tii->ti", D)
            N[far] = NB[far] * d[:, :, None] * d[:, None, :]
            P = P.copy()
            P[far] = D
    else:
        B, P = _equilibrated(Aw)
        NB = np.matmul(np.swapaxes(B, 1, 2), B)
        N = NB  # the rule is invariant to the diagonal scaling
    ok, NBinv = _screened_rule(N, NB, P if R0 is not None else None, fin & (m >= p), rcond)
    status = np.where(fin, np.where(ok, 0, 2), 3).astype(np.int8)
    if NBinv is None:
        NB = np.where(ok[:, None, None], NB, np.eye(p))
        try:
            NBinv = np.linalg.inv(NB)
        except np.linalg.LinAlgError:  # exactly singular although above rcond
            NBinv = np.linalg.pinv(NB, hermitian=True)
    y = np.matmul(NBinv, np.matmul(np.swapaxes(B, 1, 2), bw))
    x = np.matmul(P, y)
    return _finish(A, b, w, x, status, False, P, NBinv)
