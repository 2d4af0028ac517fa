"""Group blocks: observations that each tie one point block to one group block.

Seed of the method: Agnard, Nolette & Gagnon (``003_5ce730a990a7ebc5.txt``), the block
adjustment of independent models (program SPACE-M): every model coordinate of a point ties
that point's ``d`` ground coordinates to the ``b`` parameters of one model (group), and
weighted point coordinates (control) tie a point alone. Everything batched over trials ``T``.

Structure (:class:`GroupStructure`): observation ``k`` of group ``obs_group[k]`` on point
``obs_point[k]`` (``K`` of them, ``m`` rows each), point rows ``c`` on ``point_rows[c]``.
Normal equations per trial, point blocks eliminated (Schur complement)::

    Nbar[g1, g2] = delta Ngg[g1] - sum_{k1, k2 on one point j} Npg_k1' Npp_j^-1 Npg_k2

so the reduced normals have one ``b x b`` block per pair of groups sharing a point. Each
block is one matrix product over the stacked observation pairs it sums (pairs bucketed by
their number, so one batched product per bucket; work grows with the pairs, not with the
square of the block). Point Jacobians that are one constant diagonal matrix (coordinates
observed directly) make the point blocks diagonal and their elimination elementwise. Small
blocks are solved densely, batched over trials (Cholesky of the matrix scaled to unit
diagonal, after the one scaled singularity rule of :mod:`sim.lsq.normals`); large ones (the
engine's size rule, :func:`sim.lsq.size.use_sparse` on the ``G b`` reduced unknowns) by the
sparse ``L D L'`` of :mod:`sim.lsq.sparse_batch`: the groups ordered by minimum degree and
the factor's pattern analysed once per structure, every trial factorised on it in one
compiled pass (a scaled pivot at or below ``rcond`` flags the trial). Without the compiled
kernels, and as ``solver="band"``, the groups are reordered to a narrow band and eliminated
block by block, still batched (:mod:`sim.lsq.group_solve`; there the rule is replaced by a
finite solution check). Cofactors need only the
group-pair blocks of the inverse: per observation ``H_k`` (see :class:`GroupCofactors`),
one batched product per bucket of points with the same number of observations, and
optionally only for the points asked for. A point block whose
normal matrix is exactly zero (every observation of the point removed) is absent: its
unknowns are not corrected and do not count. Units: those of the model.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import sparse

from sim.lsq import compile, group_kernel, group_kernel_solve, sparse_batch
from sim.lsq.group_solve import (
    band_order,
    band_solve,
    chol_solve,
    chol_subst,
    dense,
    factor,
    inv_points,
    regular_points,
    scaled,
)
from sim.lsq.normals import RCOND
from sim.lsq.size import use_sparse

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


def _buckets(keys: np.ndarray, n: int) -> list[tuple[np.ndarray, np.ndarray]]:
    """Items grouped by ``keys`` (in ``range(n)``) and bucketed by how many share a key:
    ``[(ids (n_c,), items (n_c, c)), ...]`` -- one batched product per bucket (structure
    only, built once)."""
    order = np.argsort(keys, kind="stable")
    counts = np.bincount(keys, minlength=n)
    starts = np.cumsum(counts) - counts
    return [
        (ids, order[starts[ids][:, None] + np.arange(c)])
        for c in np.unique(counts[counts > 0])
        for ids in [np.flatnonzero(counts == c)]
    ]


class GroupStructure:
    """Which group observes which point, and the scatter operators derived from it once.

    obs_group, obs_point : (K,); point_rows : (C,) points of the point-only rows; n_groups,
    n_points; sparse_from : groups from which the reduced normals are solved on the sparse
    path (None: the engine's size rule on the reduced unknowns, :func:`sim.lsq.size.use_sparse`). ``pk1, pk2`` are all ordered pairs of observations of the same point;
    ``gp_buckets`` the observation pairs summed into each group pair, ``group_buckets`` the
    observations of each group and ``point_buckets`` those of each point, bucketed by count.
    """

    def __init__(
        self,
        obs_group,
        obs_point,
        point_rows,
        n_groups: int,
        n_points: int,
        sparse_from: int | None = None,
    ):
        og = np.asarray(obs_group, np.intp)
        op = np.asarray(obs_point, np.intp)
        self.obs_group, self.obs_point = og, op
        self.point_rows = np.asarray(point_rows, np.intp)
        self.n_groups, self.n_points, self.sparse_from = n_groups, n_points, sparse_from
        self.point_buckets = _buckets(op, n_points)
        k1, k2 = [], []
        for _, items in self.point_buckets:  # structure only, once per block
            c = items.shape[1]
            k1.append(np.repeat(items, c, axis=1).ravel())
            k2.append(np.tile(items, (1, c)).ravel())
        self.pk1 = np.concatenate(k1).astype(np.intp)
        self.pk2 = np.concatenate(k2).astype(np.intp)
        G = n_groups
        self.S_group = _indicator(og, G)
        self.S_point = _indicator(op, n_points)
        self.S_rows = _indicator(self.point_rows, n_points)
        gp, inv = np.unique(og[self.pk1] * G + og[self.pk2], return_inverse=True)
        self.pair_g1, self.pair_g2 = gp // G, gp % G
        self.pair_of = inv.ravel()
        self.gp_buckets = _buckets(inv.ravel(), gp.size)
        self.group_buckets = _buckets(og, G)
        diag = np.flatnonzero(self.pair_g1 == self.pair_g2)
        self.diag_of_group = np.full(G, -1, np.intp)
        self.diag_of_group[self.pair_g1[diag]] = diag
        self.band = band_order(self.pair_g1, self.pair_g2, G)
        self._kernel_index = None
        self._batch: dict = {}

    def batch_pattern(self, b: int) -> sparse_batch.BatchPattern:
        """The order and factor pattern of the reduced normals with ``b`` unknowns a group
        (:func:`sim.lsq.sparse_batch.analyse`, once per structure)."""
        if b not in self._batch:
            self._batch[b] = sparse_batch.analyse(self.pair_g1, self.pair_g2, self.n_groups, b)
        return self._batch[b]

    def sparse(self, b: int) -> bool:
        """Whether the reduced normals (``b`` unknowns a group) take the sparse path."""
        if self.sparse_from is None:
            return use_sparse(self.n_groups * b)
        return self.n_groups >= self.sparse_from

    @property
    def kernel_index(self) -> dict:
        """Index arrays of the compiled kernels (:func:`sim.lsq.group_kernel.index`)."""
        if self._kernel_index is None:
            self._kernel_index = group_kernel.index(
                self.obs_group,
                self.obs_point,
                self.pk1,
                self.pk2,
                self.pair_of,
                self.pair_g1,
                self.pair_g2,
                self.diag_of_group,
                self.n_points,
                self.point_rows,
            )
        return self._kernel_index


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


@dataclass
class GroupReduced:
    blocks: np.ndarray  # (T, n_pairs, b, b)
    ubar: np.ndarray  # (T, G, b)
    Ninv: np.ndarray  # (T, P, d, d), zero for absent points
    up: np.ndarray  # (T, P, d)
    Npg: np.ndarray  # (T, K, d, b)
    NinvK: np.ndarray  # (T, K, d, b) = Ninv_j Npg_k
    ok: np.ndarray  # (T,)


def _tn(A: np.ndarray, B: np.ndarray) -> np.ndarray:
    """``A' B`` over the last two axes of stacks of small matrices."""
    return np.swapaxes(A, -1, -2) @ B


def _const_diag(J: np.ndarray) -> np.ndarray | None:
    """The diagonal ``(d,)`` when ``J`` (T, n, d, d) is one constant diagonal matrix
    broadcast over trials and rows (coordinates observed directly), else None."""
    if J.ndim != 4 or J.shape[-1] != J.shape[-2] or J.strides[:2] != (0, 0):
        return None
    J0 = J[0, 0]
    dg = np.diag(J0).copy()
    return dg if np.array_equal(J0, np.diag(dg)) else None


def _point_blocks(st: GroupStructure, lin: GroupLinearization, rcond: float):
    """``(Ninv, up, Npg, NinvK, ok)`` of the point blocks; with constant diagonal point
    Jacobians (:func:`_const_diag`) the blocks are diagonal and everything is elementwise."""
    jp, jc = _const_diag(lin.Jp), _const_diag(lin.Jc)
    if jp is not None and jc is not None and (jp != 0).all():
        wp, wc = lin.w * jp, lin.wc * jc
        npp = scatter(st.S_point, wp * jp) + scatter(st.S_rows, wc * jc)  # (T, P, d)
        up = scatter(st.S_point, wp * lin.r) + scatter(st.S_rows, wc * lin.rc)
        absent = ~np.any(npp != 0, axis=-1)
        use = (npp > 0).all(-1) & np.isfinite(npp).all(-1)  # scaled: the identity
        ok = (use | absent).all(axis=1)
        ninv = np.where(use[..., None], 1.0 / np.where(use[..., None], npp, 1.0), 0.0)
        Ninv = ninv[..., :, None] * np.eye(npp.shape[-1])
        Npg = wp[..., None] * lin.Jg  # (T, K, d, b)
        return Ninv, up, Npg, ninv[:, st.obs_point, :, None] * Npg, ok
    WJp = lin.w[..., None] * lin.Jp
    WJc = lin.wc[..., None] * lin.Jc
    Npp = scatter(st.S_point, _tn(WJp, lin.Jp)) + scatter(st.S_rows, _tn(WJc, lin.Jc))
    up = scatter(st.S_point, np.einsum("tkmi,tkm->tki", WJp, lin.r)) + scatter(
        st.S_rows, np.einsum("tkmi,tkm->tki", WJc, lin.rc)
    )
    absent = ~np.any(Npp != 0, axis=(-1, -2))
    good = regular_points(Npp, rcond) | absent
    Ninv = inv_points(Npp, good & ~absent)
    Npg = _tn(WJp, lin.Jg)  # (T, K, d, b)
    return Ninv, up, Npg, Ninv[:, st.obs_point] @ Npg, good.all(axis=1)


def reduce(
    st: GroupStructure, lin: GroupLinearization, rcond: float = RCOND, jit: bool | None = None
) -> GroupReduced:
    """Normal equations with the point blocks eliminated (pair blocks of the groups): the
    compiled kernel :func:`sim.lsq.group_kernel.pair_blocks` (``jit`` None: when numba is
    there), else one batched product per bucket of group pairs with the same number of
    shared points."""
    jit = compile.available() if jit is None else jit
    if jit:
        jp, jc = _const_diag(lin.Jp), _const_diag(lin.Jc)
        if jp is not None and jc is not None and (jp != 0).all():
            return GroupReduced(*group_kernel.diag_reduce(st, lin, jp, jc))
    Ninv, up, Npg, NinvK, ok = _point_blocks(st, lin, rcond)
    if jit:
        blocks, ubar = group_kernel.pair_blocks(st, Npg, NinvK, lin.Jg, lin.w, lin.r, up)
        return GroupReduced(blocks, ubar, Ninv, up, Npg, NinvK, ok)
    T, K, m, b = lin.Jg.shape
    d = Npg.shape[2]
    blocks = np.empty((T, st.pair_g1.size, b, b))
    for ids, items in st.gp_buckets:
        n, c = items.shape
        X = Npg[:, st.pk1[items]].reshape(T, n, c * d, b)
        Y = NinvK[:, st.pk2[items]].reshape(T, n, c * d, b)
        blocks[:, ids] = -_tn(X, Y)
    WJg = lin.w[..., None] * lin.Jg
    for ids, items in st.group_buckets:
        n, c = items.shape
        X = WJg[:, items].reshape(T, n, c * m, b)
        Y = lin.Jg[:, items].reshape(T, n, c * m, b)
        blocks[:, st.diag_of_group[ids]] += _tn(X, Y)
    v = (lin.Jg * (lin.w * lin.r)[..., None]).sum(2) - (NinvK * up[:, st.obs_point, :, None]).sum(2)
    ubar = scatter(st.S_group, v)
    return GroupReduced(blocks, ubar, Ninv, up, Npg, NinvK, ok)


def solve(
    st: GroupStructure,
    red: GroupReduced,
    solver: str = "auto",
    rcond: float = RCOND,
    check: bool = True,
):
    """Group corrections ``dg`` (T, G, b) and ``ok`` (T,); singular trials get zeros.

    ``check``: apply the scaled singularity rule (:func:`~sim.lsq.group_solve.regular`; the loop applies it at the
    first linearisation, where rank defects of the geometry show, and again whenever a
    factorisation fails). ``auto``: ``sparse`` where :meth:`GroupStructure.sparse` says so,
    else ``dense``. ``sparse``: :func:`sim.lsq.sparse_batch.solve_batch` (a scaled pivot at or
    below ``rcond``, or a non-finite solution, flags the trial) when the compiled kernels run,
    else ``band``: the banded elimination of :func:`~sim.lsq.group_solve.band_solve`, where a
    failed factorisation or a non-finite solution flags the trial."""
    T, G, b = red.ubar.shape
    rhs = red.ubar.reshape(T, G * b)
    if solver == "auto":
        solver = "sparse" if st.sparse(b) else "dense"
    if solver == "sparse" and not compile.available():
        solver = "band"
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        if solver == "sparse":
            dg, ok = sparse_batch.solve_batch(st.batch_pattern(b), red.blocks, rhs, rcond)
        elif solver == "band":
            dg, ok = band_solve(st, red.blocks, rhs)
        else:
            Ns, s = (
                group_kernel_solve.dense_scaled(st, red.blocks)
                if compile.available()
                else scaled(dense(st, red.blocks))
            )
            L, ok = factor(Ns, np.isfinite(Ns).all(axis=(1, 2)), rcond, check)
            if compile.available():
                dg = group_kernel_solve.chol_vec(L, rhs * s) * s
            else:
                dg = chol_subst(L, (rhs * s)[..., None])[..., 0] * s
    ok &= red.ok
    return np.where(ok[:, None], dg, 0.0).reshape(T, G, b), ok


def points_step(st: GroupStructure, red: GroupReduced, dg: np.ndarray) -> np.ndarray:
    """Point corrections ``Npp^-1 (up - sum_k Npg_k dg_k)`` (T, P, d)."""
    if compile.available():
        return group_kernel.points_step(st, red.Npg, red.Ninv, red.up, dg)
    u = red.up - scatter(st.S_point, (red.Npg * dg[:, st.obs_group, None, :]).sum(-1))
    return (red.Ninv @ u[..., None])[..., 0]


def step(
    st: GroupStructure,
    lin: GroupLinearization,
    solver: str = "auto",
    rcond: float = RCOND,
    check: bool = True,
):
    """One Gauss-Newton correction: ``(dp (T, P, d), dg (T, G b), ok (T,))``."""
    red = reduce(st, lin, rcond)
    dg, ok = solve(st, red, solver, rcond, check)
    return points_step(st, red, dg), dg.reshape(dg.shape[0], -1), ok


@dataclass
class GroupCofactors:
    """Cofactors at one linearisation point: ``Q`` (T, G, G, b, b) of the groups, the reduced
    pieces, and accessors for the point blocks and the observation residuals.

    With ``F_k = Npp_j^-1 Npg_k`` and ``H_k = sum_{k2 on point j} Q[g_k, g_k2] F_k2'``
    (b x d): ``Q(g_k, p_j) = -H_k`` and ``Q(p_j) = Npp_j^-1 + sum_{k on j} F_k H_k``."""

    Q: np.ndarray
    red: GroupReduced
    st: GroupStructure
    _H: np.ndarray | None = None

    def _h(self, points: np.ndarray | None = None) -> np.ndarray:
        """``H_k`` (T, K, b, d) for the observations of ``points`` (bool (P,); None: all;
        NaN elsewhere): one batched product per bucket of points with the same number of
        observations."""
        st, Q, F = self.st, self.Q, self.red.NinvK
        T, K, d, b = F.shape
        H = np.empty((T, K, b, d)) if points is None else np.full((T, K, b, d), np.nan)
        og = st.obs_group
        for ids, items in st.point_buckets:
            if points is not None:
                items = items[points[ids]]
            n, c = items.shape
            if n == 0:
                continue
            g = og[items]
            Qj = Q[:, g[:, :, None], g[:, None, :]]  # (T, n, c, c, b, b)
            Qj = Qj.transpose(0, 1, 2, 4, 3, 5).reshape(T, n, c * b, c * b)
            Fj = np.swapaxes(F[:, items], -1, -2).reshape(T, n, c * b, d)
            H[:, items] = (Qj @ Fj).reshape(T, n, c, b, d)
        return H

    @property
    def H(self) -> np.ndarray:
        """``H_k`` (T, K, b, d) of every observation (computed once)."""
        if self._H is None:
            self._H = self._h()
        return self._H

    @property
    def points(self) -> np.ndarray:
        """Point cofactor blocks ``Ninv + Ninv (sum Npg_k1 Q Npg_k2') Ninv`` (T, P, d, d)."""
        return self.red.Ninv + scatter(self.st.S_point, self.red.NinvK @ self.H)

    def residuals(
        self, lin: GroupLinearization, points: np.ndarray | None = None, jit: bool | None = None
    ) -> np.ndarray:
        """Diagonal of ``Q_vv = W^-1 - A Q_xx A'`` of the observation rows (T, K, m); NaN
        where the weight is zero, and, with ``points`` (bool (P,)), for the observations of
        the other points (not computed). ``jit`` (None: when numba is there): by the
        compiled kernel :func:`sim.lsq.group_kernel_solve.residual_cofactors`."""
        st = self.st
        og, op = st.obs_group, st.obs_point
        if compile.available() if jit is None else jit:
            T, G, _, b, _ = self.Q.shape
            Q = self.Q.transpose(0, 1, 3, 2, 4).reshape(T, G * b, G * b)
            pts = (
                np.arange(st.n_points)
                if points is None
                else np.flatnonzero(np.asarray(points, bool))
            )
            return group_kernel_solve.residual_cofactors(
                st, Q, self.red.NinvK, self.red.Ninv, lin.Jg, lin.Jp, lin.w, pts
            )
        if points is None:
            ks, H, Qpp = slice(None), self.H, self.points
        else:
            points = np.asarray(points, bool)
            ks = np.flatnonzero(points[op])
            H = self._h(points)
            X = np.zeros(self.red.Ninv.shape[:1] + H.shape[1:2] + self.red.Ninv.shape[2:])
            X[:, ks] = self.red.NinvK[:, ks] @ H[:, ks]
            Qpp = self.red.Ninv + scatter(st.S_point, X)
        Jg, Jp, w = lin.Jg[:, ks], lin.Jp[:, ks], lin.w[:, ks]
        Qgg = self.Q[:, og[ks], og[ks]]  # (T, k, b, b)
        aqa = ((Jg @ Qgg) * Jg).sum(-1)
        aqa -= 2 * ((Jg @ H[:, ks]) * Jp).sum(-1)
        aqa += ((Jp @ Qpp[:, op[ks]]) * Jp).sum(-1)
        out = np.full(lin.w.shape, np.nan)
        out[:, ks] = np.where(w > 0, 1.0 / np.where(w > 0, w, 1.0) - aqa, np.nan)
        return out


def cofactors(st: GroupStructure, lin: GroupLinearization, rcond: float = RCOND) -> GroupCofactors:
    """Cofactors (dense inverse of the reduced normals; NaN for singular trials)."""
    red = reduce(st, lin, rcond)
    Ns, s = (
        group_kernel_solve.dense_scaled(st, red.blocks)
        if compile.available()
        else scaled(dense(st, red.blocks))
    )
    T, n = Ns.shape[:2]
    L, ok = factor(Ns, np.isfinite(Ns).all(axis=(1, 2)) & red.ok, rcond, True)
    Q = (
        group_kernel_solve.chol_inv(L)
        if compile.available()
        else chol_subst(L, np.broadcast_to(np.eye(n), (T, n, n)).copy())
    )
    Q = Q * s[:, :, None] * s[:, None, :]
    Q[~ok] = np.nan
    G = st.n_groups
    b = n // G
    return GroupCofactors(Q.reshape(T, G, b, G, b).transpose(0, 1, 3, 2, 4), red, st)
