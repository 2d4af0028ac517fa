"""Compiled kernels of the group-block engine (:mod:`sim.lsq.groups`): the reduction, via numba.

Seed of the method: Agnard, Nolette & Gagnon (``003_5ce730a990a7ebc5.txt``, the reduced
normals of SPACE-M's block of independent models). Loops that NumPy can only do with large
gathered temporaries (one copy of the Jacobians per pair of observations of a point):

* :func:`pair_blocks` -- the group-pair blocks of the reduced normals,
  ``Nbar[g1, g2] = delta Ngg[g1] - sum_{k1, k2 on one point} Npg_k1' Npp^-1 Npg_k2``, and the
  reduced right-hand side ``ubar[g] = sum_{k of g} (Jg_k' W_k r_k - F_k' up_j)``, with
  ``F_k = Npp_j^-1 Npg_k``. Only the pairs with ``g1 <= g2`` are summed; the others are the
  transposes (the matrix is symmetric).
* :func:`diag_reduce` -- the whole reduction when the point Jacobians are one constant
  diagonal matrix (coordinates observed directly): diagonal point blocks, their inverse,
  and the pair blocks, ``Ngg_k`` and the pair ``(k, k)`` summed as one term.
* :func:`points_step` -- the point corrections ``Npp^-1 (up - sum_k Npg_k dg_k)``.

The solve and the cofactors are in :mod:`sim.lsq.group_kernel_solve`. Every trial is the
same arithmetic as the NumPy path of :mod:`sim.lsq.groups`, summed in another order: the
two agree to rounding (tests hold them to 1e-12 relative). Units: those of the model.
Compiled by :func:`sim.lsq.compile.compiled`; the caller runs them where
:func:`sim.lsq.compile.available`, else the NumPy path.
"""

from __future__ import annotations

import numpy as np

from sim.lsq.compile import compiled

__all__ = ["pair_blocks", "diag_reduce", "points_step", "index"]


def _pair_blocks(
    Npg, F, Jg, w, r, up, og, op, pk1, pk2, pq, mir_dst, mir_src, diag_obs, blocks, ubar
):  # pragma: no cover - compiled
    """The NumPy path of :func:`sim.lsq.groups.reduce` after ``_point_blocks``: the pair
    blocks (its batched products per bucket) and ``ubar``, trial by trial."""
    T, K, d, b = Npg.shape
    m = Jg.shape[2]
    n_pk = pk1.shape[0]
    acc = np.empty((b, b))
    for t in range(T):
        blocks[t] = 0.0
        ubar[t] = 0.0
        for q in range(n_pk):
            k1, k2, p = pk1[q], pk2[q], pq[q]
            acc[:, :] = 0.0
            for a in range(d):
                for i in range(b):
                    x = Npg[t, k1, a, i]
                    for j in range(b):
                        acc[i, j] += x * F[t, k2, a, j]
            for i in range(b):
                for j in range(b):
                    blocks[t, p, i, j] -= acc[i, j]
        for k in range(K):
            p = diag_obs[k]
            g = og[k]
            jp = op[k]
            for i in range(b):
                v = 0.0
                for c in range(m):
                    v += Jg[t, k, c, i] * (w[t, k, c] * r[t, k, c])
                for a in range(d):
                    v -= F[t, k, a, i] * up[t, jp, a]
                ubar[t, g, i] += v
            for c in range(m):
                wc = w[t, k, c]
                if wc == 0.0:
                    continue
                for i in range(b):
                    x = wc * Jg[t, k, c, i]
                    for j in range(b):
                        blocks[t, p, i, j] += x * Jg[t, k, c, j]
        for e in range(mir_dst.shape[0]):
            for i in range(b):
                for j in range(b):
                    blocks[t, mir_dst[e], i, j] = blocks[t, mir_src[e], j, i]


def _diag_reduce(
    Jg,
    w,
    r,
    wc,
    rc,
    jp,
    jc,
    og,
    op,
    rows,
    diag_obs,
    xk1,
    xk2,
    xq,
    mir_dst,
    mir_src,
    npp,
    up,
    Npg,
    F,
    ok,
    blocks,
    ubar,
):  # pragma: no cover - compiled
    """:func:`sim.lsq.groups.reduce` (``_point_blocks``, then the pair blocks) where the
    point Jacobians are the constant diagonal ``jp`` (rows ``jc`` of the point-only rows):
    diagonal point blocks, their inverse by the rule of ``_point_blocks`` (positive and
    finite, or a point without observations), and ``Ngg_k`` with the pair ``(k, k)``."""
    T, K = Jg.shape[0], Jg.shape[1]
    m, b = D_POINT, B_GROUP  # noqa: F821 (compile-time constants, set by compile.compiled; m = d)
    P = npp.shape[1]
    C = rows.shape[0]
    for t in range(T):
        npp[t] = 0.0
        up[t] = 0.0
        for k in range(K):
            j = op[k]
            for a in range(m):
                wp = w[t, k, a] * jp[a]
                npp[t, j, a] += wp * jp[a]
                up[t, j, a] += wp * r[t, k, a]
        for c in range(C):
            j = rows[c]
            for a in range(m):
                wq = wc[t, c, a] * jc[a]
                npp[t, j, a] += wq * jc[a]
                up[t, j, a] += wq * rc[t, c, a]
        good = True
        for j in range(P):
            absent = True
            use = True
            for a in range(m):
                x = npp[t, j, a]
                if x != 0.0:
                    absent = False
                if not (x > 0.0 and np.isfinite(x)):
                    use = False
            if not (use or absent):
                good = False
            for a in range(m):
                npp[t, j, a] = 1.0 / npp[t, j, a] if use else 0.0  # now Npp^-1
        ok[t] = good
        blocks[t] = 0.0
        ubar[t] = 0.0
        for k in range(K):
            j, g, p = op[k], og[k], diag_obs[k]
            for a in range(m):
                wa = w[t, k, a]
                wp = wa * jp[a]
                ni = npp[t, j, a]
                for i in range(b):
                    x = wp * Jg[t, k, a, i]
                    Npg[t, k, a, i] = x
                    F[t, k, a, i] = ni * x
                coef = wa - wp * wp * ni  # Ngg_k minus the pair (k, k)
                for i in range(b):
                    x = coef * Jg[t, k, a, i]
                    for jj in range(b):
                        blocks[t, p, i, jj] += x * Jg[t, k, a, jj]
            for i in range(b):
                v = 0.0
                for a in range(m):
                    v += Jg[t, k, a, i] * (w[t, k, a] * r[t, k, a]) - F[t, k, a, i] * up[t, j, a]
                ubar[t, g, i] += v
        for q in range(xk1.shape[0]):
            k1, k2, p = xk1[q], xk2[q], xq[q]
            for a in range(m):
                for i in range(b):
                    x = Npg[t, k1, a, i]
                    for jj in range(b):
                        blocks[t, p, i, jj] -= x * F[t, k2, a, jj]
        for e in range(mir_dst.shape[0]):
            for i in range(b):
                for jj in range(b):
                    blocks[t, mir_dst[e], i, jj] = blocks[t, mir_src[e], jj, i]


def _points_step(Npg, Ninv, up, dg, og, op, out):  # pragma: no cover - compiled
    """The NumPy path of :func:`sim.lsq.groups.points_step`:
    ``Ninv @ (up - scatter(Npg @ dg[og]))`` per trial and point."""
    T, K, d, b = Npg.shape
    P = up.shape[1]
    u = np.empty((P, d))
    for t in range(T):
        for j in range(P):  # element by element: an array copy would compile numba's
            for a in range(d):  # broadcasting checks and their messages (seconds per process)
                u[j, a] = up[t, j, a]
        for k in range(K):
            j, g = op[k], og[k]
            for a in range(d):
                v = 0.0
                for i in range(b):
                    v += Npg[t, k, a, i] * dg[t, g, i]
                u[j, a] -= v
        for j in range(P):
            for a in range(d):
                v = 0.0
                for c in range(d):
                    v += Ninv[t, j, a, c] * u[j, c]
                out[t, j, a] = v


def _c(a: np.ndarray) -> np.ndarray:
    return np.ascontiguousarray(a, dtype=np.float64)


def pair_blocks(st, Npg, F, Jg, w, r, up):
    """``(blocks (T, n_pairs, b, b), ubar (T, G, b))`` of the reduced normals (see the module
    docstring); ``st`` a :class:`sim.lsq.groups.GroupStructure` (its ``kernel_index``)."""
    T, K, d, b = Npg.shape
    blocks = np.empty((T, st.pair_g1.size, b, b))
    ubar = np.empty((T, st.n_groups, b))
    ix = st.kernel_index
    compiled(_pair_blocks)(
        _c(Npg),
        _c(F),
        _c(Jg),
        _c(w),
        _c(r),
        _c(up),
        ix["og"],
        ix["op"],
        ix["pk1"],
        ix["pk2"],
        ix["pq"],
        ix["mir_dst"],
        ix["mir_src"],
        ix["diag_obs"],
        blocks,
        ubar,
    )
    return blocks, ubar


def diag_reduce(st, lin, jp: np.ndarray, jc: np.ndarray):
    """The whole reduction for constant diagonal point Jacobians ``jp``, ``jc`` (d,) (point
    coordinates observed directly): diagonal point blocks, their elimination and the pair
    blocks. Returns ``(blocks, ubar, Ninv (T, P, d, d), up, Npg, F, ok)`` as
    :func:`sim.lsq.groups.reduce`."""
    T, K, m, b = lin.Jg.shape
    P = st.n_points
    ix = st.kernel_index
    ninv, up = np.empty((T, P, m)), np.empty((T, P, m))
    Npg, F = np.empty((T, K, m, b)), np.empty((T, K, m, b))
    ok = np.empty(T, np.bool_)
    blocks = np.empty((T, st.pair_g1.size, b, b))
    ubar = np.empty((T, st.n_groups, b))
    kernel = compiled(_diag_reduce, D_POINT=m, B_GROUP=b)
    kernel(
        _c(lin.Jg),
        _c(lin.w),
        _c(lin.r),
        _c(lin.wc),
        _c(lin.rc),
        _c(jp),
        _c(jc),
        ix["og"],
        ix["op"],
        ix["rows"],
        ix["diag_obs"],
        ix["xk1"],
        ix["xk2"],
        ix["xq"],
        ix["mir_dst"],
        ix["mir_src"],
        ninv,
        up,
        Npg,
        F,
        ok,
        blocks,
        ubar,
    )
    return blocks, ubar, ninv[..., :, None] * np.eye(m), up, Npg, F, ok


def points_step(st, Npg, Ninv, up, dg) -> np.ndarray:
    """Point corrections ``Npp^-1 (up - sum_k Npg_k dg_k)`` (T, P, d)."""
    ix = st.kernel_index
    out = np.empty(up.shape)
    compiled(_points_step)(_c(Npg), _c(Ninv), _c(up), _c(dg), ix["og"], ix["op"], out)
    return out


def index(
    og: np.ndarray,
    op: np.ndarray,
    pk1: np.ndarray,
    pk2: np.ndarray,
    pair_of: np.ndarray,
    pair_g1: np.ndarray,
    pair_g2: np.ndarray,
    diag_of_group: np.ndarray,
    n_points: int,
    rows: np.ndarray,
) -> dict:
    """Integer arrays the kernels read (structure only, built once): the observation pairs
    with ``g1 <= g2`` and their pair block ``pq``, the mirrored pair blocks, each
    observation's diagonal block, the pairs of distinct observations (``xk1, xk2, xq``)
    likewise, the point rows, and the observations of each point (CSR)."""
    G = int(max(pair_g1.max(initial=0), pair_g2.max(initial=0))) + 1
    lower = pair_g1[pair_of] <= pair_g2[pair_of]
    cross = lower & (pk1 != pk2)
    key = pair_g1 * G + pair_g2
    lookup = {int(v): i for i, v in enumerate(key)}
    mir = np.flatnonzero(pair_g1 > pair_g2)
    src = np.array([lookup[int(pair_g2[p] * G + pair_g1[p])] for p in mir], np.int64)
    order = np.argsort(op, kind="stable")
    counts = np.bincount(op, minlength=n_points)
    i64 = lambda a: np.ascontiguousarray(a, np.int64)  # noqa: E731
    return {
        "og": i64(og),
        "op": i64(op),
        "pk1": i64(pk1[lower]),
        "pk2": i64(pk2[lower]),
        "pq": i64(pair_of[lower]),
        "pg1": i64(pair_g1),
        "pg2": i64(pair_g2),
        "mir_dst": i64(mir),
        "mir_src": i64(src),
        "diag_obs": i64(diag_of_group[og]),
        "xk1": i64(pk1[cross]),
        "xk2": i64(pk2[cross]),
        "xq": i64(pair_of[cross]),
        "rows": i64(rows),
        "pstart": i64(np.concatenate([[0], np.cumsum(counts)])),
        "pobs": i64(order),
    }
