"""Dense linear algebra of the group-block engine (:mod:`sim.lsq.groups`), batched over a
leading trial axis ``T``: the small point blocks (singularity rule screened by Gershgorin's
discs, 3 x 3 inverses), the reduced normals of the groups (Cholesky factorisation with
blocked substitutions; for large blocks a block-tridiagonal elimination after a
reverse Cuthill-McKee ordering of the groups) and the scaled singularity rule of
:mod:`sim.lsq.normals` applied to them. No Python loop runs per trial (the one exception:
a factorisation that fails in the banded elimination is located trial by trial).

Seed of the method: Agnard, Nolette & Gagnon (``003_5ce730a990a7ebc5.txt``, SPACE-M's
reduced normals of the models); Brown 1968 (``004_f5bd9e86c308241f.txt``) for the rule.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import sparse

from sim.lsq.normals import RCOND, scaled_rcond

__all__ = [
    "Band",
    "band_order",
    "chol_factor",
    "chol_subst",
    "chol_solve",
    "regular",
    "factor",
    "inv_points",
    "regular_points",
    "dense",
    "scaled",
    "band_solve",
]


@dataclass
class Band:
    """Block-tridiagonal layout of the reduced normals (structure only, built once): groups
    at positions ``pos`` (reverse Cuthill-McKee), ``nblk`` blocks of ``width`` groups (the
    last padded with ``pad`` identity groups); ``diag`` and ``sub`` the pair blocks that fall
    in the diagonal and sub-diagonal blocks, as ``(pairs, block, row, col)``."""

    perm: np.ndarray
    pos: np.ndarray
    width: int
    nblk: int
    pad: int
    diag: tuple
    sub: tuple


def band_order(pair_g1: np.ndarray, pair_g2: np.ndarray, G: int) -> Band:
    """Groups reordered (reverse Cuthill-McKee on the groups sharing a point) and the block
    size, in groups, at which the reordered reduced normals are block tridiagonal."""
    from scipy.sparse.csgraph import reverse_cuthill_mckee

    A = sparse.csr_matrix((np.ones(pair_g1.size), (pair_g1, pair_g2)), shape=(G, G))
    perm = np.asarray(reverse_cuthill_mckee(A, symmetric_mode=True), np.intp)
    pos = np.empty(G, np.intp)
    pos[perm] = np.arange(G)
    p1, p2 = pos[pair_g1], pos[pair_g2]
    w = max(int(np.abs(p1 - p2).max(initial=0)), 1)
    nblk = -(-G // w)
    b1, b2 = p1 // w, p2 // w
    d, s = np.flatnonzero(b1 == b2), np.flatnonzero(b1 == b2 + 1)
    return Band(
        perm,
        pos,
        w,
        nblk,
        nblk * w - G,
        (d, b1[d], p1[d] % w, p2[d] % w),
        (s, b2[s], p1[s] % w, p2[s] % w),
    )


def chol_factor(N: np.ndarray) -> np.ndarray:
    """Cholesky factor of symmetric positive-definite ``N`` (T, n, n); a non-positive-definite
    ``N`` raises ``numpy.linalg.LinAlgError``."""
    return np.linalg.cholesky(N)


def chol_subst(L: np.ndarray, b: np.ndarray, block: int | None = None) -> np.ndarray:
    """Solve ``L L' x = b`` (``b`` (T, n, r)) by blocked forward and back substitution,
    batched over trials (one matrix product per block of ``block`` unknowns)."""
    n = L.shape[-1]
    block = block or (8 if b.shape[-1] < 8 else 16)
    cuts = list(range(0, n, block)) + [n]
    inv = [np.linalg.inv(L[:, a:e, a:e]) for a, e in zip(cuts[:-1], cuts[1:])]
    y = np.empty(b.shape)
    for i, (a, e) in enumerate(zip(cuts[:-1], cuts[1:])):
        rhs = b[:, a:e] - L[:, a:e, :a] @ y[:, :a] if a else b[:, a:e]
        y[:, a:e] = inv[i] @ rhs
    x = np.empty(b.shape)
    for i in range(len(inv) - 1, -1, -1):
        a, e = cuts[i], cuts[i + 1]
        rhs = y[:, a:e] - np.swapaxes(L[:, e:, a:e], -1, -2) @ x[:, e:] if e < n else y[:, a:e]
        x[:, a:e] = np.swapaxes(inv[i], -1, -2) @ rhs
    return x


def chol_solve(N: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Solve ``N x = b`` for symmetric positive-definite ``N`` ``(T, n, n)``, ``b``
    ``(T, n, r)``, by a Cholesky factorisation and blocked substitutions vectorised over
    trials. A non-positive-definite ``N`` raises ``numpy.linalg.LinAlgError``."""
    return chol_subst(chol_factor(N), b)


def regular(Ns: np.ndarray, ok: np.ndarray, rcond: float = RCOND):
    """The scaled singularity rule on the unit-diagonal ``Ns`` (T, n, n), screened by a
    Cholesky factorisation: every pivot is an upper bound of the smallest eigenvalue, so the
    (dear) eigenvalue ratio is evaluated only for trials with a squared pivot below
    ``sqrt(rcond)`` (or all, if the factorisation fails). Returns ``(ok, L)``: ``L`` the
    factor of ``Ns`` (identity for trials not ok on entry; None if it failed)."""
    ok = ok.copy()
    try:
        L = chol_factor(np.where(ok[:, None, None], Ns, np.eye(Ns.shape[-1])))
    except np.linalg.LinAlgError:
        return ok & (scaled_rcond(Ns) > rcond), None
    cand = ok & ((np.einsum("tii->ti", L) ** 2).min(axis=1) < np.sqrt(rcond))
    if cand.any():
        ok[cand] = scaled_rcond(Ns[cand]) > rcond
    return ok, L


def factor(Ns: np.ndarray, ok: np.ndarray, rcond: float, check: bool):
    """Cholesky factor of ``Ns`` where ``ok`` (identity elsewhere) and the updated ``ok``:
    the rule of :func:`regular` when ``check``, and whenever the factorisation fails (a
    diverging trial). Factors of trials that turn out not ok are never used."""
    L = None
    if check:
        ok, L = regular(Ns, ok, rcond)
    if L is None:
        try:
            L = chol_factor(np.where(ok[:, None, None], Ns, np.eye(Ns.shape[-1])))
        except np.linalg.LinAlgError:  # a diverging trial: find it by the rule
            ok = ok & (scaled_rcond(Ns) > rcond)
            L = chol_factor(np.where(ok[:, None, None], Ns, np.eye(Ns.shape[-1])))
    return L, ok


def inv_points(Npp: np.ndarray, use: np.ndarray) -> np.ndarray:
    """Inverse point blocks where ``use`` (zero elsewhere); 3 x 3 blocks by the adjugate of
    the matrix scaled to unit diagonal."""
    d = Npp.shape[-1]
    if d != 3:
        Ninv = np.linalg.inv(np.where(use[..., None, None], Npp, np.eye(d)))
        return np.where(use[..., None, None], Ninv, 0.0)
    dg = np.einsum("...ii->...i", Npp)
    s = np.where(use[..., None], 1.0 / np.sqrt(np.where(use[..., None], np.abs(dg), 1.0)), 0.0)
    a = Npp * s[..., :, None] * s[..., None, :]
    c00 = a[..., 1, 1] * a[..., 2, 2] - a[..., 1, 2] * a[..., 2, 1]
    c01 = a[..., 0, 2] * a[..., 2, 1] - a[..., 0, 1] * a[..., 2, 2]
    c02 = a[..., 0, 1] * a[..., 1, 2] - a[..., 0, 2] * a[..., 1, 1]
    c11 = a[..., 0, 0] * a[..., 2, 2] - a[..., 0, 2] * a[..., 2, 0]
    c12 = a[..., 0, 2] * a[..., 1, 0] - a[..., 0, 0] * a[..., 1, 2]
    c22 = a[..., 0, 0] * a[..., 1, 1] - a[..., 0, 1] * a[..., 1, 0]
    det = a[..., 0, 0] * c00 + a[..., 1, 0] * c01 + a[..., 2, 0] * c02
    inv = np.stack(
        [
            np.stack([c00, c01, c02], -1),
            np.stack([c01, c11, c12], -1),
            np.stack([c02, c12, c22], -1),
        ],
        -2,
    )
    inv = inv / np.where(use, det, 1.0)[..., None, None]
    return inv * s[..., :, None] * s[..., None, :]


def regular_points(Npp: np.ndarray, rcond: float) -> np.ndarray:
    """The scaled singularity rule on the point blocks, screened by Gershgorin's discs: a
    block of positive diagonal whose scaled off-diagonal row sums stay below ``r`` has an
    eigenvalue ratio of at least ``(1 - r) / (1 + r)``; the eigenvalues are computed only
    for the blocks this bound does not decide."""
    dg = np.einsum("...ii->...i", Npp)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        s = 1.0 / np.sqrt(dg)
        C = np.abs(Npp * s[..., :, None] * s[..., None, :])
        r = (C.sum(-1) - np.einsum("...ii->...i", C)).max(-1)
        sure = (dg > 0).all(-1) & np.isfinite(C).all((-1, -2)) & ((1 - r) / (1 + r) > rcond)
    good = sure.copy()
    rest = ~sure
    if rest.any():
        good[rest] = scaled_rcond(Npp[rest]) > rcond
    return good


def dense(st, blocks: np.ndarray) -> np.ndarray:
    """The reduced normal matrix ``(T, G b, G b)`` from its pair blocks."""
    T, G, b = blocks.shape[0], st.n_groups, blocks.shape[-1]
    N = np.zeros((T, G, b, G, b))
    N[:, st.pair_g1, :, st.pair_g2, :] = np.moveaxis(blocks, 0, 1)
    return N.reshape(T, G * b, G * b)


def scaled(N: np.ndarray):
    """``N`` scaled to unit diagonal (in place) and the scale ``s`` (T, n)."""
    dgn = np.abs(np.einsum("tii->ti", N))
    s = np.where(dgn > 0, 1.0 / np.sqrt(dgn), 1.0)
    N *= s[:, :, None]
    N *= s[:, None, :]
    return N, s


def band_solve(st, blocks: np.ndarray, rhs: np.ndarray):
    """Solve the reduced normals of a large block batched over trials: the matrix, in the
    group order of :func:`band_order` and scaled to unit diagonal, is assembled as its
    diagonal and sub-diagonal blocks of ``width`` groups only and factorised block by block
    (Cholesky), with block substitutions. Returns ``(x (T, G b), ok (T,))``; a trial whose
    factorisation fails or whose solution is not finite is flagged."""
    bd = st.band
    T, b = rhs.shape[0], blocks.shape[-1]
    w, nb = bd.width, bd.nblk
    B = w * b
    D = np.zeros((T, nb, w, w, b, b))
    pr, k, r, c = bd.diag
    D[:, k, r, c] = blocks[:, pr]
    for o in range(w - bd.pad, w):
        D[:, -1, o, o] = np.eye(b)
    E = np.zeros((T, nb - 1, w, w, b, b))
    pr, k, r, c = bd.sub
    E[:, k, r, c] = blocks[:, pr]
    D = D.transpose(0, 1, 2, 4, 3, 5).reshape(T, nb, B, B)
    E = E.transpose(0, 1, 2, 4, 3, 5).reshape(T, nb - 1, B, B)
    y = np.zeros((T, nb * w, b))
    y[:, bd.pos] = rhs.reshape(T, -1, b)
    y = y.reshape(T, nb, B)
    dgn = np.abs(np.einsum("tkii->tki", D))
    s = np.where(dgn > 0, 1.0 / np.sqrt(dgn), 1.0)
    D = D * s[..., :, None] * s[..., None, :]
    E = E * s[:, 1:, :, None] * s[:, :-1, None, :]
    y = y * s
    ok = (
        np.isfinite(D).all(axis=(1, 2, 3))
        & np.isfinite(E).all(axis=(1, 2, 3))
        & np.isfinite(y).all(axis=(1, 2))
    )
    D = np.where(ok[:, None, None, None], D, np.eye(B))
    E = np.where(ok[:, None, None, None], E, 0.0)
    y = np.where(ok[:, None, None], y, 0.0)[..., None]
    Ls, Ms = [], []  # inverse diagonal factors, sub-diagonal blocks L_{i+1,i}
    for i in range(nb):
        A = D[:, i] - Ms[-1] @ np.swapaxes(Ms[-1], -1, -2) if i else D[:, i]
        try:
            L = np.linalg.cholesky(A)
        except np.linalg.LinAlgError:  # a diverging trial: flag it, go on with the others
            bad = np.zeros(T, bool)
            for t in range(T):  # the rare failure only: locate the trial
                try:
                    np.linalg.cholesky(A[t])
                except np.linalg.LinAlgError:
                    bad[t] = True
            ok &= ~bad
            L = np.linalg.cholesky(np.where(bad[:, None, None], np.eye(B), A))
        Ls.append(np.linalg.inv(L))
        if i < nb - 1:
            Ms.append(E[:, i] @ np.swapaxes(Ls[-1], -1, -2))
    z = []
    for i in range(nb):
        z.append(Ls[i] @ (y[:, i] - Ms[i - 1] @ z[-1] if i else y[:, i]))
    x = [None] * nb
    for i in range(nb - 1, -1, -1):
        r = z[i] - np.swapaxes(Ms[i], -1, -2) @ x[i + 1] if i < nb - 1 else z[i]
        x[i] = np.swapaxes(Ls[i], -1, -2) @ r
    xs = (np.stack(x, 1)[..., 0] * s).reshape(T, nb * w, b)
    out = xs[:, bd.pos].reshape(T, -1)
    return out, ok & np.isfinite(out).all(axis=1)
