"""Compiled kernels of the group-block engine (:mod:`sim.lsq.groups`), via numba.

Seed of the method: Agnard, Nolette & Gagnon (``003_5ce730a990a7ebc5.txt``, the reduced
normals of SPACE-M's block of independent models). Two loops that NumPy can only do with
large gathered temporaries (one copy of the Jacobians per pair of observations of a point):

* :func:`pair_blocks` -- the group-pair blocks of the reduced normals,
  ``Nbar[g1, g2] = delta Ngg[g1] - sum_{k1, k2 on one point} Npg_k1' Npp^-1 Npg_k2``, and the
  reduced right-hand side ``ubar[g] = sum_{k of g} (Jg_k' W_k r_k - F_k' up_j)``, with
  ``F_k = Npp_j^-1 Npg_k``. Only the pairs with ``g1 <= g2`` are summed; the others are the
  transposes (the matrix is symmetric).
* :func:`residual_cofactors` -- the diagonal of ``Q_vv = W^-1 - A Q_xx A'`` of the
  observation rows of chosen points, from the dense group cofactors ``Q`` (T, G b, G b):
  ``H_k = sum_{k2 on j} Q[g_k, g_k2] F_k2'``, ``Q(p_j) = Npp_j^-1 + sum_{k on j} F_k H_k``.

Every trial is the same arithmetic as the NumPy path of :mod:`sim.lsq.groups`, summed in
another order: the two agree to rounding (a test holds them to 1e-12 relative). Units: those
of the model. numba is imported on first use and the compiled code cached on disk; without
numba (or with ``SIM_NO_JIT`` set) :data:`AVAILABLE` is False and the NumPy path runs.
"""
from __future__ import annotations

import os

import numpy as np

__all__ = ["available", "pair_blocks", "diag_reduce", "points_step", "dense_scaled", "chol_vec",
           "residual_cofactors"]

_compiled: dict | None = None


def _pair_blocks(Npg, F, Jg, w, r, up, og, op, pk1, pk2, pq, mir_dst, mir_src, diag_obs,
                 blocks, ubar):  # pragma: no cover - compiled
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


def _residual_cofactors(Q, F, Ninv, Jg, Jp, w, og, op, pts, pstart, pobs, out):
    # pragma: no cover - compiled
    T = F.shape[0]
    d, b, m = D_POINT, B_GROUP, M_ROWS    # compile-time constants (see _specialised)
    nmax = 0
    for j in pts:
        nmax = max(nmax, pstart[j + 1] - pstart[j])
    H = np.empty((nmax, b, d))
    Qpp = np.empty((d, d))
    JH = np.empty((m, d))
    JQ = np.empty((m, b))
    for t in range(T):
        for j in pts:
            s0, s1 = pstart[j], pstart[j + 1]
            n = s1 - s0
            for u in range(n):
                k = pobs[s0 + u]
                gk = og[k] * b
                for i in range(b):
                    for a in range(d):
                        H[u, i, a] = 0.0
                for u2 in range(n):
                    k2 = pobs[s0 + u2]
                    g2 = og[k2] * b
                    for i in range(b):
                        for jj in range(b):
                            qv = Q[t, gk + i, g2 + jj]
                            for a in range(d):
                                H[u, i, a] += qv * F[t, k2, a, jj]
            for a in range(d):
                for c in range(d):
                    Qpp[a, c] = Ninv[t, j, a, c]
            for u in range(n):
                k = pobs[s0 + u]
                for a in range(d):
                    for c in range(d):
                        v = 0.0
                        for i in range(b):
                            v += F[t, k, a, i] * H[u, i, c]
                        Qpp[a, c] += v
            for u in range(n):
                k = pobs[s0 + u]
                gk = og[k] * b
                for c in range(m):
                    for i in range(b):
                        v = 0.0
                        for jj in range(b):
                            v += Jg[t, k, c, jj] * Q[t, gk + jj, gk + i]
                        JQ[c, i] = v
                    for a in range(d):
                        v = 0.0
                        for i in range(b):
                            v += Jg[t, k, c, i] * H[u, i, a]
                        JH[c, a] = v
                for c in range(m):
                    aqa = 0.0
                    for i in range(b):
                        aqa += JQ[c, i] * Jg[t, k, c, i]
                    x = 0.0
                    for a in range(d):
                        x += JH[c, a] * Jp[t, k, c, a]
                    aqa -= 2.0 * x
                    for a in range(d):
                        v = 0.0
                        for e in range(d):
                            v += Jp[t, k, c, e] * Qpp[e, a]
                        aqa += v * Jp[t, k, c, a]
                    wc = w[t, k, c]
                    out[t, k, c] = 1.0 / wc - aqa if wc > 0 else np.nan


def _diag_reduce(Jg, w, r, wc, rc, jp, jc, og, op, rows, diag_obs, xk1, xk2, xq, mir_dst,
                 mir_src, npp, up, Npg, F, ok, blocks, ubar):  # pragma: no cover - compiled
    T, K = Jg.shape[0], Jg.shape[1]
    m, b = D_POINT, B_GROUP    # compile-time constants (see _specialised); m = d here
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
                npp[t, j, a] = 1.0 / npp[t, j, a] if use else 0.0   # now Npp^-1
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
                coef = wa - wp * wp * ni     # Ngg_k minus the pair (k, k)
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
    T, K, d, b = Npg.shape
    P = up.shape[1]
    u = np.empty((P, d))
    for t in range(T):
        u[:, :] = up[t]
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


def _dense_scaled(blocks, pg1, pg2, N, s):  # pragma: no cover - compiled
    T, n_p, b = blocks.shape[0], blocks.shape[1], blocks.shape[2]
    n = N.shape[1]
    for t in range(T):
        N[t] = 0.0
        for p in range(n_p):
            r0, c0 = pg1[p] * b, pg2[p] * b
            for i in range(b):
                for j in range(b):
                    N[t, r0 + i, c0 + j] = blocks[t, p, i, j]
        for i in range(n):
            dg = abs(N[t, i, i])
            s[t, i] = 1.0 / np.sqrt(dg) if dg > 0 else 1.0
        for i in range(n):
            for j in range(n):
                N[t, i, j] = N[t, i, j] * s[t, i] * s[t, j]


def _chol_vec(L, y, x):  # pragma: no cover - compiled
    T, n = y.shape
    z = np.empty(n)
    for t in range(T):
        for i in range(n):
            v = y[t, i]
            for k in range(i):
                v -= L[t, i, k] * z[k]
            z[i] = v / L[t, i, i]
        for i in range(n - 1, -1, -1):
            v = z[i]
            for k in range(i + 1, n):
                v -= L[t, k, i] * x[t, k]
            x[t, i] = v / L[t, i, i]


def _kernels() -> dict | None:
    """The compiled kernels (compiled or loaded from the disk cache once per process), or
    None without numba."""
    global _compiled
    if _compiled is None:
        if os.environ.get("SIM_NO_JIT"):
            _compiled = {}
        else:
            try:
                from numba import njit
            except ImportError:  # pragma: no cover - the NumPy path runs
                _compiled = {}
            else:
                jit = njit(cache=True, error_model="numpy")
                _compiled = {"pairs": jit(_pair_blocks), "dense": jit(_dense_scaled),
                             "points": jit(_points_step),
                             "chol": jit(_chol_vec)}
    return _compiled or None


def _specialised(fn, d: int, b: int, m: int):
    """``fn`` compiled with the block sizes ``d`` (point unknowns), ``b`` (group unknowns)
    and ``m`` (rows per observation) frozen to constants (numba treats globals as such),
    which lets the compiler unroll and vectorise the small loops; cached on disk under its
    own name."""
    import types

    from numba import njit

    key = (fn.__name__, d, b, m)
    if key not in _compiled:
        name = f"{fn.__name__}_{d}_{b}_{m}"
        f = types.FunctionType(fn.__code__, dict(fn.__globals__, D_POINT=d, B_GROUP=b, M_ROWS=m),
                               name, fn.__defaults__, fn.__closure__)
        f.__qualname__ = name
        _compiled[key] = njit(cache=True, error_model="numpy")(f)
    return _compiled[key]


def available() -> bool:
    """Whether the compiled kernels run (numba installed and ``SIM_NO_JIT`` unset)."""
    return _kernels() is not None


def _c(a: np.ndarray) -> np.ndarray:
    return np.ascontiguousarray(a, dtype=np.float64)


def pair_blocks(st, Npg, F, Jg, w, r, up):
    """``(blocks (T, n_pairs, b, b), ubar (T, G, b))`` of the reduced normals (see the module
    docstring); ``st`` a :class:`sim.lsq.groups.GroupStructure` (its ``kernel_index``)."""
    T, K, d, b = Npg.shape
    blocks = np.empty((T, st.pair_g1.size, b, b))
    ubar = np.empty((T, st.n_groups, b))
    ix = st.kernel_index
    _kernels()["pairs"](_c(Npg), _c(F), _c(Jg), _c(w), _c(r), _c(up), ix["og"], ix["op"],
                        ix["pk1"], ix["pk2"], ix["pq"], ix["mir_dst"], ix["mir_src"],
                        ix["diag_obs"], blocks, ubar)
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
    _kernels()
    _specialised(_diag_reduce, m, b, m)(_c(lin.Jg), _c(lin.w), _c(lin.r), _c(lin.wc), _c(lin.rc), _c(jp), _c(jc),
                       ix["og"], ix["op"], ix["rows"], ix["diag_obs"], ix["xk1"], ix["xk2"],
                       ix["xq"], ix["mir_dst"], ix["mir_src"], ninv, up, Npg, F, ok, blocks,
                       ubar)
    return blocks, ubar, ninv[..., :, None] * np.eye(m), up, Npg, F, ok


def points_step(st, Npg, Ninv, up, dg) -> np.ndarray:
    """Point corrections ``Npp^-1 (up - sum_k Npg_k dg_k)`` (T, P, d)."""
    ix = st.kernel_index
    out = np.empty(up.shape)
    _kernels()["points"](_c(Npg), _c(Ninv), _c(up), _c(dg), ix["og"], ix["op"], out)
    return out


def dense_scaled(st, blocks: np.ndarray):
    """The reduced normal matrix (T, G b, G b) from its pair blocks, scaled to unit diagonal,
    and the scale ``s`` (T, G b): :func:`sim.lsq.group_solve.dense` then ``scaled``."""
    T, n_p, b = blocks.shape[:3]
    n = st.n_groups * b
    N, s = np.empty((T, n, n)), np.empty((T, n))
    ix = st.kernel_index
    _kernels()["dense"](_c(blocks), ix["pg1"], ix["pg2"], N, s)
    return N, s


def chol_vec(L: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Solve ``L L' x = y`` for ``L`` (T, n, n) lower triangular, ``y`` (T, n)."""
    x = np.empty(y.shape)
    _kernels()["chol"](_c(L), _c(y), x)
    return x


def residual_cofactors(st, Q, F, Ninv, Jg, Jp, w, points: np.ndarray) -> np.ndarray:
    """Diagonal of ``Q_vv`` (T, K, m) for the observations of ``points`` (indices), NaN
    elsewhere and where the weight is zero; ``Q`` (T, G b, G b) the group cofactors."""
    ix = st.kernel_index
    out = np.full(w.shape, np.nan)
    T, K, d, b = F.shape
    _kernels()
    _specialised(_residual_cofactors, d, b, Jg.shape[2])(_c(Q), _c(F), _c(Ninv), _c(Jg), _c(Jp), _c(w), ix["og"], ix["op"],
                        np.asarray(points, np.int64), ix["pstart"], ix["pobs"], out)
    return out


def index(og: np.ndarray, op: np.ndarray, pk1: np.ndarray, pk2: np.ndarray,
          pair_of: np.ndarray, pair_g1: np.ndarray, pair_g2: np.ndarray,
          diag_of_group: np.ndarray, n_points: int, rows: np.ndarray) -> dict:
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
    return {"og": i64(og), "op": i64(op), "pk1": i64(pk1[lower]), "pk2": i64(pk2[lower]),
            "pq": i64(pair_of[lower]), "pg1": i64(pair_g1), "pg2": i64(pair_g2), "mir_dst": i64(mir), "mir_src": i64(src),
            "diag_obs": i64(diag_of_group[og]), "xk1": i64(pk1[cross]),
            "xk2": i64(pk2[cross]), "xq": i64(pair_of[cross]), "rows": i64(rows),
            "pstart": i64(np.concatenate([[0], np.cumsum(counts)])), "pobs": i64(order)}
