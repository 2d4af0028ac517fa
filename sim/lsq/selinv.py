"""Compiled kernels of the sparse path: triangular solves with a block of right-hand sides and
selected inversion (Takahashi's recurrence) of an ``L D L'`` factor.

The factor is stored as the strictly lower part of the unit lower triangle ``L`` in compressed
columns (``indptr``, ``indices`` sorted ascending in each column, ``data``) and the pivots
``D``. Selected inversion computes the entries of ``Z = (L D L')^-1`` on the pattern of ``L``
(and its diagonal) by Takahashi's recurrence, column by column from the last::

    Z_ij = - sum_{k > j, k in col j} L_kj Z_ik      (i > j, i in the pattern of column j)
    Z_jj = 1 / d_j - sum_{k > j, k in col j} L_kj Z_kj

Every ``Z_ik`` the sums need lies in the pattern (the rows of a column of ``L`` form a clique
of the filled graph), so the work is the sum over columns of the squared column counts: no
dense inverse, no column-by-column solves. Seed of the method: K. Takahashi, J. Fagan and
M.-S. Chen, "Formation of a sparse bus impedance matrix and its application to short circuit
study" (1973); A. M. Erisman and W. F. Tinney (1975). Every kernel runs compiled by numba when
present (:func:`sim.lsq.compile.compiled`); without it (``SIM_NO_JIT``) the substitutions are
SciPy's (``spsolve_triangular``) and the symbolic analysis, the recurrence and the look-up run
as plain Python (they have no NumPy form; small problems). Bench rows (``docs/benchmark.md``):
``selinv`` (the recurrence against column solves with the same factor) and ``sparse_solve``
(the substitutions against SciPy's).
"""

from __future__ import annotations

import numpy as np
from scipy import sparse
from scipy.sparse.linalg import spsolve_triangular

from sim.lsq import compile as jit

__all__ = ["symbolic", "filled", "forward", "backward", "takahashi", "lookup"]


def _symbolic(n, Ap, Ai, cap):  # pragma: no cover - compiled
    """Pattern ``(Lp, Li)`` of the Cholesky factor of a symmetric matrix whose strictly lower
    part has the pattern ``(Ap, Ai)`` (CSC): column ``j`` is its own rows below the diagonal
    and those of its children in the elimination tree (the filled graph), rows sorted."""
    head = np.full(n, -1, np.int64)
    nxt = np.full(n, -1, np.int64)
    mark = np.full(n, -1, np.int64)
    Lp = np.zeros(n + 1, np.int64)
    Li = np.empty(max(cap, 1), np.int64)
    nz = 0
    for j in range(n):
        start = nz
        mark[j] = j
        for p in range(Ap[j], Ap[j + 1]):
            i = Ai[p]
            if mark[i] != j:
                mark[i] = j
                if nz == Li.shape[0]:
                    grown = np.empty(2 * Li.shape[0], np.int64)
                    for q in range(nz):  # element by element: see compile.py on array copies
                        grown[q] = Li[q]
                    Li = grown
                Li[nz] = i
                nz += 1
        c = head[j]
        while c != -1:
            for p in range(Lp[c], Lp[c + 1]):
                i = Li[p]
                if mark[i] != j:
                    mark[i] = j
                    if nz == Li.shape[0]:
                        grown = np.empty(2 * Li.shape[0], np.int64)
                        for q in range(nz):  # element by element: see compile.py on array copies
                            grown[q] = Li[q]
                        Li = grown
                    Li[nz] = i
                    nz += 1
            c = nxt[c]
        Li[start:nz].sort()  # in place (an array copy compiles slowly: see compile.py)
        Lp[j + 1] = nz
        if nz > start:
            par = Li[start]
            nxt[j] = head[par]
            head[par] = j
    return Lp, Li[:nz].copy()


def _forward(indptr, indices, data, D, X):  # pragma: no cover - compiled
    """``X <- D^-1 L^-1 X`` in place, ``X`` (n, T)."""
    n, T = X.shape
    for j in range(n):
        for p in range(indptr[j], indptr[j + 1]):
            i = indices[p]
            v = data[p]
            for t in range(T):
                X[i, t] -= v * X[j, t]
        dj = 1.0 / D[j]
        for t in range(T):
            X[j, t] *= dj


def _backward(indptr, indices, data, X):  # pragma: no cover - compiled
    """``X <- L'^-1 X`` in place, ``X`` (n, T)."""
    n, T = X.shape
    for j in range(n - 1, -1, -1):
        for p in range(indptr[j], indptr[j + 1]):
            i = indices[p]
            v = data[p]
            for t in range(T):
                X[j, t] -= v * X[i, t]


def _takahashi(indptr, indices, data, D, Zx, Zd):  # pragma: no cover - compiled
    """Selected inverse on the pattern of ``L`` into ``Zx`` (the strictly lower entries, in
    ``L``'s layout) and ``Zd`` (the diagonal). Returns False if an entry the recurrence needs
    is not in the pattern (a pattern that is not a filled graph)."""
    n = D.shape[0]
    for j in range(n - 1, -1, -1):
        p0 = indptr[j]
        k = indptr[j + 1] - p0
        s = np.zeros(k)
        for a in range(k):
            s[a] = data[p0 + a] * Zd[indices[p0 + a]]
        for b in range(k):
            rb = indices[p0 + b]
            lb = data[p0 + b]
            q = indptr[rb]
            qe = indptr[rb + 1]
            for a in range(b + 1, k):
                ra = indices[p0 + a]
                while q < qe and indices[q] < ra:
                    q += 1
                if q == qe or indices[q] != ra:
                    return False
                z = Zx[q]  # Z[ra, rb]
                s[a] += lb * z
                s[b] += data[p0 + a] * z
        dd = 1.0 / D[j]
        for a in range(k):
            Zx[p0 + a] = -s[a]
            dd += data[p0 + a] * s[a]
        Zd[j] = dd
    return True


def _lookup(indptr, indices, Zx, Zd, rows, cols, out):  # pragma: no cover - compiled
    """``out[t] = Z[rows[t], cols[t]]`` (symmetric; NaN where not in the pattern)."""
    for t in range(rows.shape[0]):
        i, j = rows[t], cols[t]
        if i < j:
            i, j = j, i
        if i == j:
            out[t] = Zd[i]
            continue
        lo, hi = indptr[j], indptr[j + 1]
        while lo < hi:
            mid = (lo + hi) // 2
            if indices[mid] < i:
                lo = mid + 1
            else:
                hi = mid
        out[t] = Zx[lo] if lo < indptr[j + 1] and indices[lo] == i else np.nan


def _fn(f):
    return jit.compiled(f) if jit.available() else f


def symbolic(n: int, indptr: np.ndarray, indices: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The filled pattern ``(Lp, Li)`` (strictly lower, CSC, sorted) of the factor of a
    symmetric matrix with strictly lower pattern ``(indptr, indices)``."""
    return _fn(_symbolic)(
        int(n),
        np.asarray(indptr, np.int64),
        np.asarray(indices, np.int64),
        int(2 * len(indices) + n),
    )


def _scatter(Lp, Li, Ap, Ai, Ax, out):  # pragma: no cover - compiled
    """``out`` (on the pattern ``(Lp, Li)``) <- the strictly lower entries of ``(Ap, Ai,
    Ax)`` (CSC, any order in a column); False if one lies outside the pattern."""
    n = Lp.shape[0] - 1
    for j in range(n):
        for p in range(Ap[j], Ap[j + 1]):
            i = Ai[p]
            if i <= j:
                continue
            lo, hi = Lp[j], Lp[j + 1]
            while lo < hi:
                mid = (lo + hi) // 2
                if Li[mid] < i:
                    lo = mid + 1
                else:
                    hi = mid
            if lo == Lp[j + 1] or Li[lo] != i:
                return False
            out[lo] = Ax[p]
    return True


def filled(n: int, lower, L) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``L`` (CSC; its diagonal and anything above it left out, so a library's unit lower
    factor as it comes; a library may leave out entries that cancelled to zero) on the filled
    pattern of ``lower`` (the strictly lower part of the factored matrix, CSC): ``(indptr,
    indices, data)``, zeros where ``L`` has no entry -- the pattern the selected inversion
    needs. Compiled, each entry is put in place by a search of its column: no index arrays
    of the factor's size besides the pattern (the NumPy twin's keys, three of them, were
    0.6 GiB of a 90,000-point network's 17 million nonzeros)."""
    Lp, Li = symbolic(n, lower.indptr, lower.indices)
    data = np.zeros(Li.size)
    if jit.available():
        if not jit.compiled(_scatter)(Lp, Li, L.indptr, L.indices, L.data, data):
            raise ValueError("the factor has entries outside its symbolic pattern")
        return Lp, Li, data
    L = sparse.tril(L, k=-1, format="csc")
    L.sort_indices()
    key = np.repeat(np.arange(n, dtype=np.int64), np.diff(Lp)) * n + Li
    have = np.repeat(np.arange(n, dtype=np.int64), np.diff(L.indptr)) * n + L.indices
    at = np.searchsorted(key, have)
    if np.any(at >= key.size) or np.any(key[np.minimum(at, key.size - 1)] != have):
        raise ValueError("the factor has entries outside its symbolic pattern")
    data[at] = L.data
    return Lp, Li, data


def _unit_lower(indptr, indices, data) -> sparse.csr_matrix:
    """The unit lower triangle ``L`` (CSR) from its strictly lower part (CSC)."""
    n = len(indptr) - 1
    L = sparse.csc_matrix((data, indices, indptr), shape=(n, n))
    return sparse.csr_matrix(L + sparse.identity(n, format="csc"))


def forward(indptr, indices, data, D, X: np.ndarray) -> None:
    """``X <- D^-1 L^-1 X`` in place (``X`` C-contiguous float64 (n, T))."""
    if jit.available():
        jit.compiled(_forward)(indptr, indices, data, D, X)
    elif X.size:
        L = _unit_lower(indptr, indices, data)
        X[:] = spsolve_triangular(L, X, lower=True, unit_diagonal=True) / D[:, None]


def backward(indptr, indices, data, X: np.ndarray) -> None:
    """``X <- L'^-1 X`` in place (``X`` C-contiguous float64 (n, T))."""
    if jit.available():
        jit.compiled(_backward)(indptr, indices, data, X)
    elif X.size:
        LT = sparse.csr_matrix(_unit_lower(indptr, indices, data).T)
        X[:] = spsolve_triangular(LT, X, lower=False, unit_diagonal=True)


def takahashi(indptr, indices, data, D) -> tuple[np.ndarray, np.ndarray]:
    """The selected inverse ``(Zx, Zd)`` of ``L D L'`` on the pattern of ``L``."""
    Zx, Zd = np.zeros_like(data), np.zeros_like(D)
    if not _fn(_takahashi)(indptr, indices, data, D, Zx, Zd):
        raise ValueError("selected inversion: the factor's pattern is not a filled graph")
    return Zx, Zd


def lookup(indptr, indices, Zx, Zd, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
    """Entries ``Z[rows, cols]`` of the selected inverse (positions in the factor's order)."""
    rows = np.ascontiguousarray(rows, dtype=np.int64).ravel()
    cols = np.ascontiguousarray(cols, dtype=np.int64).ravel()
    out = np.empty(rows.shape[0])
    _fn(_lookup)(indptr, indices, Zx, Zd, rows, cols, out)
    return out
