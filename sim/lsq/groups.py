"""Group blocks: observations that each tie one point block to one group block.

Seed of the method: Agnard, Nolette & Gagnon (``003_5ce730a990a7ebc5.txt``), the block
adjustment of independent models (program SPACE-M): every model coordinate of a point ties
that point's ``d`` ground coordinates to the ``b`` parameters of one model (group), and
weighted point coordinates (control) tie a point alone. Everything batched over trials ``T``.

Structure (:class:`GroupStructure`): observation ``k`` of group ``obs_group[k]`` on point
``obs_point[k]`` (``K`` of them, ``m`` rows each), point rows ``c`` on ``point_rows[c]``.
Normal equations per trial, point blocks eliminated (Schur complement)::

    Nbar[g1, g2] = delta Ngg[g1] - sum_{k1, k2 on one point j} Npg_k1' Npp_j^-1 Npg_k2

so the reduced normals have one ``b x b`` block per pair of groups sharing a point; they are
assembled from the list of such pairs with sparse scatter matrices (work grows with the
pairs, not with the square of the block). Small blocks are solved densely, batched over
trials (Cholesky of the matrix scaled to unit diagonal, after the one scaled singularity rule
of :mod:`sim.lsq.normals`); from ``sparse_from`` groups up each trial's matrix is factorised
as a sparse matrix (one factorisation per trial: there the rule is replaced by a finite
solution check, an eigenvalue bound being dearer than the solve). A point block whose
normal matrix is exactly zero (every observation of the point removed) is absent: its
unknowns are not corrected and do not count. Units: those of the model.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import sparse

from .normals import RCOND, scaled_rcond

__all__ = ["GroupStructure", "GroupLinearization", "chol_solve", "step", "cofactors"]


def _indicator(rows: np.ndarray, n_rows: int) -> sparse.csr_matrix:
    """Sparse ``(n_rows, len(rows))`` matrix summing items into their rows."""
    k = rows.size
    return sparse.csr_matrix((np.ones(k), (rows, np.arange(k))), shape=(n_rows, k))


def scatter(S: sparse.csr_matrix, data: np.ndarray) -> np.ndarray:
    """Sum ``data`` ``(T, k, ...)`` over its second axis into ``S.shape[0]`` bins."""
    T, k = data.shape[:2]
    rest = data.shape[2:]
    d = np.moveaxis(data, 1, 0).reshape(k, -1)
    out = np.asarray(S @ d).reshape((S.shape[0], T) + rest)
    return np.moveaxis(out, 0, 1)


class GroupStructure:
    """Which group observes which point, and the scatter operators derived from it once.

    obs_group, obs_point : (K,); point_rows : (C,) points of the point-only rows; n_groups,
    n_points; sparse_from : groups from which the reduced normals are solved sparsely.
    ``pk1, pk2`` are all ordered pairs of observations of the same point.
    """

    def __init__(self, obs_group, obs_point, point_rows, n_groups: int, n_points: int,
                 sparse_from: int = 60):
        og = np.asarray(obs_group, np.intp)
        op = np.asarray(obs_point, np.intp)
        self.obs_group, self.obs_point = og, op
        self.point_rows = np.asarray(point_rows, np.intp)
        self.n_groups, self.n_points, self.sparse_from = n_groups, n_points, sparse_from
        order = np.argsort(op, kind="stable")
        starts = np.searchsorted(op[order], np.arange(n_points))
        ends = np.searchsorted(op[order], np.arange(n_points), side="right")
        k1, k2 = [], []
        for a, b in zip(starts, ends):  # structure only, once per block
            idx = order[a:b]
            k1.append(np.repeat(idx, idx.size))
            k2.append(np.tile(idx, idx.size))
        self.pk1 = np.concatenate(k1).astype(np.intp)
        self.pk2 = np.concatenate(k2).astype(np.intp)
        G = n_groups
        self.S_group = _indicator(og, G)
        self.S_point = _indicator(op, n_points)
        self.S_rows = _indicator(self.point_rows, n_points)
        gp, inv = np.unique(og[self.pk1] * G + og[self.pk2], return_inverse=True)
        self.S_pair = _indicator(inv.ravel(), gp.size)          # observation pair -> group pair
        self.pair_g1, self.pair_g2 = gp // G, gp % G
        self.S_pair_obs = _indicator(self.pk1, og.size)
        self.S_pair_point = _indicator(op[self.pk1], n_points)


@dataclass
class GroupLinearization:
    """Observation rows ``r`` (T, K, m), ``Jp`` (T, K, m, d), ``Jg`` (T, K, m, b), ``w``
    (T, K, m); point rows ``rc`` (T, C, m), ``Jc`` (T, C, m, d), ``wc`` (T, C, m).
    Misclosures are observed minus computed, Jacobians of the computed values."""

    r: np.ndarray
    Jp: np.ndarray
    Jg: np.ndarray
    w: np.ndarray
    rc: np.ndarray
    Jc: np.ndarray
    wc: np.ndarray


def chol_solve(N: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Solve ``N x = b`` for symmetric positive-definite ``N`` ``(T, n, n)``, ``b``
    ``(T, n, r)``, by Cholesky factorisation and substitutions vectorised over trials
    (batched LAPACK ``gesv`` is slow here when OpenBLAS threads compete for the cores).
    A non-positive-definite ``N`` raises ``numpy.linalg.LinAlgError``."""
    L = np.linalg.cholesky(N)
    n = N.shape[-1]
    y = np.empty(b.shape)
    for i in range(n):  # loop over the unknowns, vectorised over trials
        y[:, i] = (b[:, i] - np.einsum("tj,tjr->tr", L[:, i, :i], y[:, :i])) / L[:, i, i, None]
    x = np.empty(b.shape)
    for i in range(n - 1, -1, -1):
        x[:, i] = (y[:, i] - np.einsum("tj,tjr->tr", L[:, i + 1:, i], x[:, i + 1:])) / L[:, i, i, None]
    return x


def regular(Ns: np.ndarray, ok: np.ndarray, rcond: float = RCOND) -> np.ndarray:
    """The scaled singularity rule on the unit-diagonal ``Ns`` (T, n, n), screened by a
    Cholesky factorisation: every pivot is an upper bound of the smallest eigenvalue, so the
    (dear) eigenvalue ratio is evaluated only for trials with a squared pivot below
    ``sqrt(rcond)`` (or all, if the factorisation fails)."""
    ok = ok.copy()
    try:
        L = np.linalg.cholesky(np.where(ok[:, None, None], Ns, np.eye(Ns.shape[-1])))
    except np.linalg.LinAlgError:
        return ok & (scaled_rcond(Ns) > rcond)
    cand = ok & ((np.einsum("tii->ti", L) ** 2).min(axis=1) < np.sqrt(rcond))
    if cand.any():
        ok[cand] = scaled_rcond(Ns[cand]) > rcond
    return ok


@dataclass
class GroupReduced:
    blocks: np.ndarray   # (T, n_pairs, b, b)
    ubar: np.ndarray     # (T, G, b)
    Ninv: np.ndarray     # (T, P, d, d), zero for absent points
    up: np.ndarray       # (T, P, d)
    Npg: np.ndarray      # (T, K, d, b)
    ok: np.ndarray       # (T,)


def reduce(st: GroupStructure, lin: GroupLinearization, rcond: float = RCOND) -> GroupReduced:
    """Normal equations with the point blocks eliminated (pair blocks of the groups)."""
    WJp = lin.w[..., None] * lin.Jp
    WJc = lin.wc[..., None] * lin.Jc
    Npp = (scatter(st.S_point, np.swapaxes(WJp, -1, -2) @ lin.Jp)
           + scatter(st.S_rows, np.swapaxes(WJc, -1, -2) @ lin.Jc))       # (T, P, d, d)
    up = (scatter(st.S_point, np.einsum("tkmi,tkm->tki", WJp, lin.r))
          + scatter(st.S_rows, np.einsum("tkmi,tkm->tki", WJc, lin.rc)))
    d = Npp.shape[-1]
    absent = ~np.any(Npp != 0, axis=(-1, -2))
    good = (scaled_rcond(Npp) > rcond) | absent
    ok = good.all(axis=1)
    Ninv = np.linalg.inv(np.where((good & ~absent)[..., None, None], Npp, np.eye(d)))
    Ninv = np.where((good & ~absent)[..., None, None], Ninv, 0.0)
    Npg = np.swapaxes(WJp, -1, -2) @ lin.Jg                             # (T, K, d, b)
    Ngg = scatter(st.S_group, np.swapaxes(lin.w[..., None] * lin.Jg, -1, -2) @ lin.Jg)
    ug = scatter(st.S_group, np.einsum("tkmi,tkm->tki", lin.Jg, lin.w * lin.r))
    NinvK = Ninv[:, st.obs_point] @ Npg                                  # (T, K, d, b)
    C = np.swapaxes(Npg[:, st.pk1], -1, -2) @ NinvK[:, st.pk2]          # (T, pairs, b, b)
    blocks = -scatter(st.S_pair, C)
    diag = st.pair_g1 == st.pair_g2
    blocks[:, diag] += Ngg[:, st.pair_g1[diag]]
    ubar = ug - scatter(st.S_group, np.einsum("tkib,tki->tkb", NinvK, up[:, st.obs_point]))
    return GroupReduced(blocks, ubar, Ninv, up, Npg, ok)


def dense(st: GroupStructure, blocks: np.ndarray) -> np.ndarray:
    """The reduced normal matrix ``(T, G b, G b)`` from its pair blocks."""
    T, G, b = blocks.shape[0], st.n_groups, blocks.shape[-1]
    N = np.zeros((T, G, G, b, b))
    N[:, st.pair_g1, st.pair_g2] = blocks
    return N.transpose(0, 1, 3, 2, 4).reshape(T, G * b, G * b)


def _sparse_solve(st: GroupStructure, blocks: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """One sparse LU per trial (each trial a whole block of about 9 non-zero blocks per
    group): far less than the dense ``(G b)^3`` once ``G`` reaches a few hundred."""
    from scipy.sparse.linalg import spsolve

    b = blocks.shape[-1]
    n = st.n_groups * b
    i = np.arange(b)
    shape = (st.pair_g1.size, b, b)
    rows = np.broadcast_to(b * st.pair_g1[:, None, None] + i[None, :, None], shape).ravel()
    cols = np.broadcast_to(b * st.pair_g2[:, None, None] + i[None, None, :], shape).ravel()
    out = np.empty(rhs.shape)
    for t in range(blocks.shape[0]):  # one sparse factorisation per simulated block
        out[t] = spsolve(sparse.csc_matrix((blocks[t].ravel(), (rows, cols)), shape=(n, n)),
                         rhs[t])
    return out


def solve(st: GroupStructure, red: GroupReduced, solver: str = "auto",
          rcond: float = RCOND, check: bool = True):
    """Group corrections ``dg`` (T, G, b) and ``ok`` (T,); singular trials get zeros.

    ``check``: apply the scaled singularity rule (:func:`regular`; the loop applies it at the
    first linearisation, where rank defects of the geometry show, and again whenever a
    factorisation fails)."""
    T, G, b = red.ubar.shape
    rhs = red.ubar.reshape(T, G * b)
    if solver == "auto":
        solver = "sparse" if G >= st.sparse_from else "dense"
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        if solver == "sparse":
            dg = _sparse_solve(st, red.blocks, rhs)
            ok = np.isfinite(dg).all(axis=1)
        else:
            N = dense(st, red.blocks)
            dgn = np.abs(np.einsum("tii->ti", N))
            s = np.where(dgn > 0, 1.0 / np.sqrt(dgn), 1.0)
            Ns = N * s[:, :, None] * s[:, None, :]
            ok = np.isfinite(Ns).all(axis=(1, 2))
            if check:
                ok = regular(Ns, ok, rcond)
            try:
                y = chol_solve(np.where(ok[:, None, None], Ns, np.eye(G * b)),
                               (rhs * s)[..., None])
            except np.linalg.LinAlgError:  # a diverging trial: find it by the rule
                ok &= scaled_rcond(Ns) > rcond
                y = chol_solve(np.where(ok[:, None, None], Ns, np.eye(G * b)),
                               (rhs * s)[..., None])
            dg = y[..., 0] * s
    ok &= red.ok
    return np.where(ok[:, None], dg, 0.0).reshape(T, G, b), ok


def points_step(st: GroupStructure, red: GroupReduced, dg: np.ndarray) -> np.ndarray:
    """Point corrections ``Npp^-1 (up - sum_k Npg_k dg_k)`` (T, P, d)."""
    u = red.up - scatter(st.S_point, np.einsum("tkib,tkb->tki", red.Npg, dg[:, st.obs_group]))
    return (red.Ninv @ u[..., None])[..., 0]


def step(st: GroupStructure, lin: GroupLinearization, solver: str = "auto",
         rcond: float = RCOND, check: bool = True):
    """One Gauss-Newton correction: ``(dp (T, P, d), dg (T, G b), ok (T,))``."""
    red = reduce(st, lin, rcond)
    dg, ok = solve(st, red, solver, rcond, check)
    return points_step(st, red, dg), dg.reshape(dg.shape[0], -1), ok


@dataclass
class GroupCofactors:
    """Cofactors at one linearisation point: ``Q`` (T, G, G, b, b) of the groups, the reduced
    pieces, and accessors for the point blocks and the observation residuals."""

    Q: np.ndarray
    red: GroupReduced
    st: GroupStructure

    def _cross(self):
        st, Q, Npg = self.st, self.Q, self.red.Npg
        og = st.obs_group
        return np.einsum("tpab,tpcb->tpac", Q[:, og[st.pk1], og[st.pk2]], Npg[:, st.pk2])

    @property
    def points(self) -> np.ndarray:
        """Point cofactor blocks ``Ninv + Ninv (sum Npg_k1 Q Npg_k2') Ninv`` (T, P, d, d)."""
        st, Ninv = self.st, self.red.Ninv
        inner = np.einsum("tpib,tpbc->tpic", self.red.Npg[:, st.pk1], self._cross())
        return Ninv + Ninv @ scatter(st.S_pair_point, inner) @ Ninv

    def residuals(self, lin: GroupLinearization) -> np.ndarray:
        """Diagonal of ``Q_vv = W^-1 - A Q_xx A'`` of the observation rows (T, K, m); NaN
        where the weight is zero."""
        st, Ninv = self.st, self.red.Ninv
        og, op = st.obs_group, st.obs_point
        Qgp = -scatter(st.S_pair_obs, self._cross()) @ Ninv[:, op]      # (T, K, b, d)
        Qgg = self.Q[:, og, og]                                         # (T, K, b, b)
        aqa = (np.einsum("tkmb,tkbc,tkmc->tkm", lin.Jg, Qgg, lin.Jg)
               + 2 * np.einsum("tkmb,tkbd,tkmd->tkm", lin.Jg, Qgp, lin.Jp)
               + np.einsum("tkmd,tkde,tkme->tkm", lin.Jp, self.points[:, op], lin.Jp))
        w = lin.w
        return np.where(w > 0, 1.0 / np.where(w > 0, w, 1.0) - aqa, np.nan)


def cofactors(st: GroupStructure, lin: GroupLinearization, rcond: float = RCOND) -> GroupCofactors:
    """Cofactors (dense inverse of the reduced normals; NaN for singular trials)."""
    red = reduce(st, lin, rcond)
    N = dense(st, red.blocks)
    T, n = N.shape[:2]
    dgn = np.abs(np.einsum("tii->ti", N))
    s = np.where(dgn > 0, 1.0 / np.sqrt(dgn), 1.0)
    Ns = N * s[:, :, None] * s[:, None, :]
    ok = regular(Ns, np.isfinite(Ns).all(axis=(1, 2)) & red.ok, rcond)
    Q = chol_solve(np.where(ok[:, None, None], Ns, np.eye(n)),
                   np.broadcast_to(np.eye(n), (T, n, n)).copy())
    Q = Q * s[:, :, None] * s[:, None, :]
    Q[~ok] = np.nan
    G = st.n_groups
    b = n // G
    return GroupCofactors(Q.reshape(T, G, b, G, b).transpose(0, 1, 3, 2, 4), red, st)
