"""The sparse path of the engine: sparse normal equations, one factorisation per design, blocks
of right-hand sides, selected inversion for the precision, and the Gauss-Newton loop that
reuses the factor for every trial.

A problem whose every observation row ties a few unknowns (a network, a grid plate, a block of
models) has a Jacobian with a fixed pattern: ``cols`` ``(m, s)`` the column of each of the ``s``
slots of a row (``-1``: unused) and ``vals`` ``(..., m, s)`` the derivatives. Weights ``w``
``(m,)`` (``1 / sigma^2``) make the cofactors covariances.

* :func:`design` -- the weighted design in compressed rows; :func:`normals` -- ``N = A' W A``
  (sparse);
* :func:`factorize` -- ``N`` scaled to unit diagonal, a fill-reducing order (SuperLU's minimum
  degree on ``N``'s own pattern: ``MMD_AT_PLUS_A``, the symmetric mode, no pivoting, so the LU
  factor is ``L D L'``) and one numerical factorisation; a rank defect ``G`` (the datum's null
  space, ``d`` columns) is taken out by holding the ``d`` unknowns that span it best (pivoted
  QR of the null space of the unit-diagonal normals, ``diag(N)^(1/2) G``, so the choice is
  free of ``G``'s basis and units) and the datum constraints ``C' dx = 0`` are restored by an
  S-transformation (``d = c``) or bordered as a low-rank correction (a regular ``N`` with constraints). The
  scaled singularity rule of the sparse path: a pivot of the unit-diagonal normals at or below
  ``rcond`` (or not finite) -- the pivots bound the smallest eigenvalue from above, so what the
  dense rule (:func:`sim.lsq.normals.scaled_rcond`) refuses with a pivot that small is
  refused here too; the factor then names the unknown of its smallest pivot (``weak``; for an
  exactly zero pivot, which SuperLU does not locate, from the normals shifted by ``rcond``);
* :meth:`Factor.solve` -- a block of right-hand sides ``(p, T)`` in one pass of compiled
  triangular solves (:mod:`sim.lsq.selinv`);
* :meth:`Factor.entries` -- any entries of the cofactor matrix in the datum that lie in the
  factor's pattern (point blocks, the pairs an observation joins) by selected inversion
  (Takahashi's recurrence) plus the datum's low-rank terms: no dense inverse;
* :func:`gauss_newton_shared` -- the Gauss-Newton loop of a batch of trials that all start at
  the nominal unknowns: the normals factorised there serve every iteration and every trial
  (each iteration's gradient is taken at the trial's current unknowns, so the fixed point is
  the least-squares solution; the contraction is the small change of the Jacobian over the
  corrections); a trial stops when its largest correction is below ``tol`` or below the
  rounding of its largest free unknown (64 ulp). Status codes as
  :data:`sim.lsq.result.STATUS`.

Units are those of the problem (mm, rad, ...). Library: SciPy's SuperLU (``splu``), which
installs with SciPy on every machine; the selected inversion and the block solves are the
project's own compiled kernels on the factor it returns (docs/sparse.md says why).
Seed of the method: Brown 1968 (``004_f5bd9e86c308241f.txt``: normal equations of large
comparator networks), Takahashi et al. 1973 (selected inversion).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

import numpy as np
import scipy.linalg as sla
from scipy import sparse
from scipy.sparse.linalg import splu

from sim.lsq import selinv
from sim.lsq.gauss_newton import _Progress
from sim.lsq.normals import RCOND

__all__ = [
    "design",
    "normals",
    "Factor",
    "factorize",
    "gauss_newton_shared",
    "factor_nonzeros",
    "normals_nonzeros",
]


def _free_cols(cols: np.ndarray, free: np.ndarray, q: int) -> np.ndarray:
    """``cols`` (global indices, -1 unused) mapped to positions among ``free`` (-1: not free)."""
    pos = np.full(q + 1, -1, np.int64)
    pos[free] = np.arange(len(free))
    return pos[np.where(cols >= 0, cols, q)]


def design(cols: np.ndarray, vals: np.ndarray, w: np.ndarray, free: np.ndarray, q: int):
    """The weighted design ``W^(1/2) A`` ``(m, p)`` (CSR) of one Jacobian ``vals`` (m, s)
    over the free unknowns (``q`` globals in all)."""
    fc = _free_cols(cols, free, q)
    m, s = fc.shape
    use = fc >= 0
    rows = np.repeat(np.arange(m), s).reshape(m, s)
    A = sparse.csr_matrix(
        ((vals * np.sqrt(w)[:, None])[use], (rows[use], fc[use])), shape=(m, len(free))
    )
    A.sum_duplicates()
    return A


def normals(cols, vals, w, free, q, pairs=None) -> sparse.csc_matrix:
    """``N = A' W A`` over the free unknowns, sparse (CSC), summed row by row from each row's
    slot pairs: every pair of unknowns an observation joins is in the pattern, also where
    its sum cancels to zero (the selected inverse is wanted there); ``pairs`` (k, 2) global
    indices of more pairs to hold in the pattern (e.g. x and y of every point)."""
    fc = _free_cols(cols, free, q)
    a = np.where(fc >= 0, vals * np.sqrt(w)[:, None], 0.0)
    r = np.broadcast_to(fc[:, :, None], fc.shape + fc.shape[1:2])
    c = np.swapaxes(r, 1, 2)
    use = (r >= 0) & (c >= 0)
    v = (a[:, :, None] * a[:, None, :])[use]
    r, c = r[use], c[use]
    if pairs is not None:
        pp = _free_cols(np.asarray(pairs, np.int64), free, q)
        pp = pp[(pp >= 0).all(axis=1)]
        r = np.concatenate([r, pp[:, 0], pp[:, 1]])
        c = np.concatenate([c, pp[:, 1], pp[:, 0]])
        v = np.concatenate([v, np.zeros(2 * len(pp))])
    p = len(free)
    return sparse.csc_matrix((v, (r, c)), shape=(p, p))


def normals_nonzeros(cols: np.ndarray, q: int) -> int:
    """Nonzeros of ``N = A' W A`` (both triangles, as :func:`normals` holds them) of a Jacobian
    pattern ``cols`` (m, s) over ``q`` globals (-1: unused slot): the distinct pairs of
    columns the rows join. Not the rows' slot pairs ``m s^2``: a regular network joins each
    pair of points from both ends, and unused slots join nothing (a nearest-8 trilateration
    grid of 10,000 points: 3.6e5 nonzeros, ``m s^2`` = 2.9e6)."""
    cols = np.asarray(cols, np.int64)
    r, c = cols[:, :, None], cols[:, None, :]
    code = (r * (q + 1) + c)[(r >= 0) & (c >= 0)]
    return int(np.unique(code).size)


def factor_nonzeros(p: int, nnz_n: int) -> float:
    """Order-of-magnitude nonzeros of the factor of a plane network's normals (``p`` unknowns,
    ``nnz_n`` nonzeros of ``N``): minimum degree on a planar graph fills ``O(p log p)``
    (measured: 20,000 unknowns, nearest-8 trilateration, 1.4e6; this model gives about 2e6),
    at most the lower triangle's ``p (p + 1) / 2``."""
    return min(float(nnz_n) * max(np.log2(max(p, 2)), 1.0) / 3.0 + 4.0 * p, p * (p + 1) / 2)


@dataclass
class Factor:
    """``L D L'`` of the scaled, reordered normals over the unknowns that stay free of the
    datum, and the datum's low-rank terms. Arrays only (picklable: a chunk of trials in
    another process gets the factor, not the design)."""

    p: int  # free unknowns
    keep: np.ndarray  # (p_r,) the unknowns in the factor (positions among the free)
    pos: np.ndarray  # (p_r,) their positions in the factor's order
    s: np.ndarray  # (p_r,) scaling to unit diagonal
    indptr: np.ndarray
    indices: np.ndarray
    data: np.ndarray  # strictly lower part of the unit L (CSC, sorted)
    D: np.ndarray  # pivots
    ok: bool
    message: str = ""
    weak: int = -1  # not ok from a pivot: the free unknown (position) of the smallest one
    C: np.ndarray | None = None  # (p, c) constraints C' dx = 0
    P: np.ndarray | None = None  # (p, c): x = y - P C' y restores them
    terms: list = field(default_factory=list)  # [(Lm, Rm)]: Q += Lm Rm' (low rank)
    transformed: bool = False  # Q = S Q_r S' (a datum over a rank defect)
    Zx: np.ndarray | None = field(default=None, repr=False)
    Zd: np.ndarray | None = field(default=None, repr=False)

    @property
    def nnz(self) -> int:
        """Nonzeros of the factor (strictly lower part plus diagonal)."""
        return int(self.data.size + self.D.size)

    def _solve_r(self, B: np.ndarray) -> np.ndarray:
        """``Q_r B``: the inverse of the normals with the datum unknowns held (rows zero)."""
        B = np.asarray(B, float)
        one = B.ndim == 1
        B2 = B[:, None] if one else B
        X = np.zeros((self.p, B2.shape[1]))
        Y = np.zeros((len(self.keep), B2.shape[1]))
        Y[self.pos] = B2[self.keep] * self.s[:, None]
        selinv.forward(self.indptr, self.indices, self.data, self.D, Y)
        selinv.backward(self.indptr, self.indices, self.data, Y)
        X[self.keep] = Y[self.pos] * self.s[:, None]
        return X[:, 0] if one else X

    def solve(self, B: np.ndarray) -> np.ndarray:
        """``x`` (p,) or (p, T): the solution of the normals ``N x = B`` in the datum (the
        constrained solution ``C' x = 0``), for a block of right-hand sides at once."""
        X = self._solve_r(B)
        if self.P is not None:
            X = X - self.P @ (self.C.T @ X)
        return X

    def cov_times(self, B: np.ndarray) -> np.ndarray:
        """``Q B`` for any ``B`` (p, k): the cofactor matrix in the datum times ``B`` (where
        :meth:`solve` takes right-hand sides of the normals, orthogonal to the defect)."""
        if self.transformed:
            B = B - self.C @ (self.P.T @ B)
        return self.solve(B)

    def selected_inverse(self) -> None:
        """Compute (once) the selected inverse on the factor's pattern."""
        if self.Zx is None:
            self.Zx, self.Zd = selinv.takahashi(self.indptr, self.indices, self.data, self.D)

    def entries(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """Cofactor entries ``Q[a, b]`` in the datum (``a``, ``b``: positions among the free
        unknowns, equal shapes). Each pair must lie in the pattern of ``N`` (the same
        unknown, or two unknowns one observation joins); NaN otherwise."""
        self.selected_inverse()
        a, b = np.asarray(a, np.int64), np.asarray(b, np.int64)
        shape = np.broadcast(a, b).shape
        a, b = np.broadcast_to(a, shape).ravel(), np.broadcast_to(b, shape).ravel()
        where = np.full(self.p, -1, np.int64)
        where[self.keep] = np.arange(len(self.keep))
        ra, rb = where[a], where[b]
        both = (ra >= 0) & (rb >= 0)
        out = np.zeros(a.shape[0])
        if both.any():
            z = selinv.lookup(
                self.indptr,
                self.indices,
                self.Zx,
                self.Zd,
                self.pos[ra[both]],
                self.pos[rb[both]],
            )
            out[both] = z * self.s[ra[both]] * self.s[rb[both]]
        for Lm, Rm in self.terms:
            out += np.einsum("ki,ki->k", Lm[a], Rm[b])
        return out.reshape(shape)


def _order_out(G: np.ndarray) -> np.ndarray:
    """The ``d`` unknowns that span the null space ``G`` (p, d) best (pivoted QR of ``G'``)."""
    _, piv = sla.qr(G.T, mode="r", pivoting=True)
    return np.sort(piv[: G.shape[1]])


def _fail(p: int, msg: str, weak: int = -1) -> Factor:
    e = np.zeros(0)
    z = np.zeros(1, np.int64)
    return Factor(p, np.zeros(0, int), np.zeros(0, int), e, z, z[:0], e, e, False, msg, weak)


def _splu(Ns: sparse.csc_matrix):
    """SuperLU's ``L D L'`` of the unit-diagonal normals (symmetric mode, no pivoting)."""
    return splu(
        Ns,
        permc_spec="MMD_AT_PLUS_A",
        diag_pivot_thresh=0.0,
        options={"SymmetricMode": True},
    )


def _smallest_pivot(lu, D: np.ndarray) -> int:
    """The unknown (position in the factorised normals) of the smallest pivot in ``D`` (a
    non-finite one first): where the elimination met the weak direction. ``perm_c`` puts
    column ``i`` at position ``perm_c[i]``."""
    j = int(np.argmin(np.where(np.isfinite(D), D, -np.inf)))
    return int(np.flatnonzero(np.asarray(lu.perm_c) == j)[0])


def _zero_pivot(Ns: sparse.csc_matrix, rcond: float) -> int:
    """The unknown of an exactly zero pivot (SuperLU names none): the normals shifted by
    ``rcond`` on their unit diagonal are positive definite, and their smallest pivot (about
    ``rcond``) falls on an unknown of the singular direction; -1 if that fails too. One
    more factorisation of the same pattern: the cost of the first, no dense matrix."""
    try:
        lu = _splu(sparse.csc_matrix(Ns + rcond * sparse.identity(Ns.shape[0], format="csc")))
    except RuntimeError:  # pragma: no cover - a shifted positive semi-definite matrix is regular
        return -1
    return _smallest_pivot(lu, lu.U.diagonal())


def factorize(
    N: sparse.spmatrix,
    G: np.ndarray | None = None,
    C: np.ndarray | None = None,
    rcond: float = RCOND,
) -> Factor:
    """Factorise the normals ``N`` (p, p) once: see the module doc. ``G`` (p, d): the null
    space of ``N`` (the datum defect; None or d = 0: ``N`` regular); ``C`` (p, c): the datum
    constraints ``C' x = 0`` (with a defect, ``c = d`` and ``C' G`` regular). A factor that
    is not ``ok`` carries its one-line ``message`` (and, failed at a pivot, the ``weak``
    unknown)."""
    N = sparse.csc_matrix(N)
    p = N.shape[0]
    d = 0 if G is None else G.shape[1]
    c = 0 if C is None else C.shape[1]
    if d and c != d:
        return _fail(p, f"the datum has {c} constraints for a rank defect of {d}")
    # the unknowns held are chosen on the null space of the unit-diagonal normals (the scaled
    # system factorised below): independent of the basis and the units of G
    nd = np.sqrt(np.nan_to_num(np.abs(N.diagonal())))
    out = _order_out(G * nd[:, None]) if d else np.zeros(0, int)
    keep = np.setdiff1d(np.arange(p), out)
    Nr = N[keep][:, keep] if d else N
    diag = Nr.diagonal()
    if not (np.all(np.isfinite(Nr.data)) and np.all(diag > 0)):
        return _fail(p, "an unknown has no observation (a zero or non-finite normal)")
    s = 1.0 / np.sqrt(diag)
    Ns = sparse.csc_matrix(Nr, copy=True)  # scaled in place: explicit zeros stay
    Ns.data *= s[Ns.indices] * np.repeat(s, np.diff(Ns.indptr))
    try:
        lu = _splu(Ns)
    except RuntimeError:
        weak = _zero_pivot(Ns, rcond)
        return _fail(
            p,
            "the normal equations are singular (an exactly zero pivot)",
            int(keep[weak]) if weak >= 0 else -1,
        )
    if not np.array_equal(lu.perm_r, lu.perm_c):  # SPD keeps the diagonal: nearly singular
        weak = _zero_pivot(Ns, rcond)  # (rounding made it indefinite: seen on an AMD EPYC)
        return _fail(
            p,
            "the normal equations are singular (not positive definite in rounding)",
            int(keep[weak]) if weak >= 0 else -1,
        )
    D = lu.U.diagonal().copy()
    if not (np.all(np.isfinite(D)) and D.min(initial=1.0) > rcond):
        return _fail(
            p,
            f"the normal equations are singular (a scaled pivot of {D.min(initial=0.0):.3g}"
            f" is not above rcond {rcond:g})",
            int(keep[_smallest_pivot(lu, D)]),
        )
    L, perm = lu.L, np.asarray(lu.perm_c, np.int64)  # L: unit lower, its diagonal too
    del lu  # SuperLU's own L and U, as large as the factor, not held from here
    low = sparse.coo_matrix(Ns)
    use = perm[low.row] > perm[low.col]
    low = sparse.csc_matrix(
        (low.data[use], (perm[low.row[use]], perm[low.col[use]])), shape=Ns.shape
    )
    del use, Ns, Nr
    low.sort_indices()
    Lp, Li, Lx = selinv.filled(len(keep), low, L)
    f = Factor(p, keep, perm, s, Lp, Li, Lx, D, True)
    if c:
        _constrain(f, G if d else None, np.asarray(C, float), rcond)
    return f


def _constrain(f: Factor, G: np.ndarray | None, C: np.ndarray, rcond: float) -> None:
    """Add the datum constraints to the factor ``f`` as low-rank terms (``G`` and ``C`` are
    scaled to unit columns first: the same subspaces, a condition number free of units)."""
    C = C / np.linalg.norm(C, axis=0)
    G = None if G is None else G / np.linalg.norm(G, axis=0)
    W = f._solve_r(C)  # (p, c)
    if G is not None:  # S-transformation of the g-inverse: Q = S Q_r S', S = I - G (C'G)^-1 C'
        CG = C.T @ G
        if np.linalg.cond(CG) * rcond >= 1:
            f.ok, f.message = False, "the datum constraints do not cover the rank defect"
            return
        U = G @ np.linalg.inv(CG)
        K = C.T @ W
        f.C, f.P, f.transformed = C, U, True
        f.terms = [(-U, W), (-W, U), (U @ K, U)]
    else:  # regular normals with constraints: Q = Q_r - W (C' W)^-1 W'
        M = C.T @ W
        if np.linalg.cond(M) * rcond >= 1:
            f.ok, f.message = False, "the constraints are dependent"
            return
        WM = W @ np.linalg.inv(M)
        f.C, f.P = C, WM
        f.terms = [(-WM, W)]


def gauss_newton_shared(
    gradient: Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]],
    theta0: np.ndarray,
    free: np.ndarray,
    factor: Factor,
    w: np.ndarray,
    tol: float,
    max_iter: int,
    linear: bool = False,
):
    """Gauss-Newton of a batch that starts at the nominal unknowns ``theta0`` (T, q), with the
    normals factorised once there (``factor``) for every trial and iteration.

    ``gradient(theta, trials)`` returns ``r`` (k, m) observed minus computed and ``A' W r``
    (k, p) of the ``trials`` (k,) at their current unknowns ``theta`` (k, q) (the trial's own Jacobian: the fixed point is the least-squares
    solution); ``w`` (m,) the weights; ``linear``: the observations are linear in the
    unknowns, so the first step is the solution (status 0 after one iteration). Returns ``theta`` (T, q), ``vpv`` (T,), ``iterations``
    (T,) and ``status`` (T,) int8 (0 converged, 1 not within ``max_iter``, 2 singular,
    3 non-finite)."""
    theta = np.array(theta0, float, copy=True)
    T = theta.shape[0]
    prog = _Progress(T)
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        if not factor.ok:
            prog.update(1, np.zeros(T, bool), np.full(T, np.nan), tol)
        for it in range(1, max_iter + 1):
            if not prog.active.any():
                break
            act = np.flatnonzero(prog.active)
            _, g = gradient(theta[act], act)
            dx = factor.cov_times(np.ascontiguousarray(g.T)).T  # the bordered step Q g
            step = np.where(np.isfinite(dx).all(axis=1), np.abs(dx).max(axis=1, initial=0), np.nan)
            full = np.full(T, np.nan)
            full[act] = step
            # the step itself must fall below tol: with the normals of the nominal the
            # corrections need not shrink at one rate (a pair of iterations can alternate a
            # small and a large ratio), so the contraction estimate is not used here
            prog.prev[:] = np.nan
            # a correction below the unknowns' own rounding (64 ulp of the largest free one)
            # cannot be resolved: in a field network of 10 km in mm it is about 1e-9 mm
            floor = 64 * np.finfo(float).eps * np.abs(theta[act][:, free]).max(axis=1, initial=0)
            full[act] = np.where(step <= floor, 0.0, step)
            upd = prog.update(it, np.ones(T, bool), full, np.inf if linear else tol)
            theta[np.ix_(act[upd[act]], free)] += dx[upd[act]]
        r, _ = gradient(theta, np.arange(T))
        vpv = (w * r * r).sum(axis=1)
    return theta, vpv, prog.iters, prog.status
