"""Pre-analysis and Monte Carlo of a large network on the sparse path (:mod:`sim.lsq.sparse`).

The same quantities as :mod:`sim.studies.network.analysis` -- per point covariance blocks and
ellipses (mm^2), redundancy numbers, Baarda's MDB (mm or rad), the bias-to-noise ratio, the
degrees of freedom -- from one sparse factorisation of the normals at the true coordinates and
the selected inverse (Takahashi's recurrence) on its pattern, never the dense inverse. What
differs: the external reliability ``ext_max_mm`` is the largest displacement an undetected MDB
causes at the points its observation ties (its own end points), where the dense path takes
the largest over all points; in a fixed datum the two agree on ordinary networks, in a free
datum the dense one also carries the datum's shift of every point.

The Monte Carlo (:func:`mc_chunk_sparse`) reads the same simulated observations as the dense
chunk (same seed, same numbers) and adjusts them with the one factor, every trial of the chunk
as one block of right-hand sides (:func:`sim.lsq.sparse.gauss_newton_shared`). Units: mm and
rad. Seeds: Baarda's reliability theory (``004``), Takahashi et al. 1973.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass

import numpy as np

from sim import lsq
from sim.lsq import sparse as lsq_sparse
from sim.mc.network_size import network_counts, sparse_chunk_bytes
from sim.mc.progress import phase
from sim.studies.network.analysis import (
    Analytic,
    analyse,
    chunk_output,
    datum_weights,
    delta0,
    inner_defect,
)
from sim.studies.network.definition import Network
from sim.studies.network.kernel import residual_gradient
from sim.studies.network.model import (
    SPARSE_MIN_UNKNOWNS,
    defect_basis,
    jacobian_sparse,
    pattern,
    simulate,
    use_sparse,
    weighted_design,
)

__all__ = [
    "SPARSE_MIN_UNKNOWNS",
    "use_sparse",
    "SparseAnalytic",
    "factor",
    "analyse_sparse",
    "pre_analysis",
    "in_datum_sparse",
    "variances",
    "mc_chunk_sparse",
    "chunk_bytes",
    "PHASE_FROM_UNKNOWNS",
    "shows_phases",
    "shows_phases_of",
]


#: unknowns from which the steps before the Monte Carlo (building, factorising, the
#: pre-analysis) are shown on a terminal (:func:`sim.mc.progress.phase`): measured, one
#: core, 10,000 unknowns about 2 s of building and pre-analysis, 100,000 about 35 s
PHASE_FROM_UNKNOWNS = 10_000


def shows_phases(unknowns: float) -> bool:
    """Whether a network of ``unknowns`` shows its setup steps (:data:`PHASE_FROM_UNKNOWNS`)."""
    return unknowns >= PHASE_FROM_UNKNOWNS


def shows_phases_of(cfg: dict) -> bool:
    """:func:`shows_phases` of the network ``cfg`` declares, before it is built (its unknowns
    as the work estimate counts them, :func:`sim.mc.network_size.network_counts`)."""
    try:
        return shows_phases(network_counts(cfg).unknowns)
    except (TypeError, ValueError, KeyError, OverflowError):
        return False


@dataclass
class SparseAnalytic(Analytic):
    """:class:`~sim.studies.network.analysis.Analytic` of the sparse path: ``Q`` is None (no
    dense covariance, :func:`variances` reads its diagonal); ``factor`` the sparse factor in
    the datum."""

    factor: lsq_sparse.Factor | None = None


def chunk_bytes(net: Network, chunk: int) -> float:
    """Bytes one Monte-Carlo chunk of the sparse path holds at once
    (:func:`sim.mc.network_size.sparse_chunk_bytes`: the trials' readings, residuals and
    steps, the factor and its selected inverse by nonzeros). The factor's nonzeros follow from
    ``N``'s own (the distinct pairs of estimated unknowns the rows join), not from the rows'
    slot pairs, which counted a 10,000-point trilateration grid's factor 11 times too large
    and refused a 50,000-point one at every chunk (it ran in 1.3 GiB); nor over the fixed
    points' coordinates, which the factor does not hold."""
    cols = pattern(net)
    held = [net.i_constant] * (not net.estimate_constant) + [net.i_scale] * (not net.estimate_scale)
    fixed = np.flatnonzero(net.role == 1)
    held = np.concatenate([held, 2 * fixed, 2 * fixed + 1])
    nnz_n = lsq_sparse.normals_nonzeros(np.where(np.isin(cols, held), -1, cols), net.q)
    free = max(net.q - 2 * fixed.size, 1)
    return sparse_chunk_bytes(chunk, net.m, net.q, lsq_sparse.factor_nonzeros(free, nnz_n))


def _pairs(net: Network) -> np.ndarray:
    """Pairs of globals ``(k, 2)`` the pattern must hold beyond the Jacobian's: x and y of
    every point (its covariance block) and every coordinate of the two points of a
    coordinate difference (the displacement its MDB causes at its points)."""
    a = np.arange(net.n)
    out = [np.stack([2 * a, 2 * a + 1], 1)]
    d = np.flatnonzero(np.isin(net.kind, (3, 4)))
    if d.size:
        c = np.stack([2 * net.i[d], 2 * net.i[d] + 1, 2 * net.j[d], 2 * net.j[d] + 1], 1)
        out.append(np.stack(np.broadcast_arrays(c[:, :, None], c[:, None, :]), -1).reshape(-1, 2))
    return np.concatenate(out)


def factor(net: Network, datum: lsq.Datum) -> lsq_sparse.Factor:
    """The sparse factor of ``net``'s normals at the true coordinates in ``datum``."""
    free = datum.free_index(net.q)
    _, vals = jacobian_sparse(net, net.theta_true()[None])
    N = lsq_sparse.normals(pattern(net), vals[0], 1.0 / net.sigma**2, free, net.q, _pairs(net))
    C = datum.constraint_matrix(net.theta_true()[None])
    C = None if C is None else np.asarray(C[0], float)
    G = defect_basis(net, free)
    G = G if (G.shape[1] and C is not None) else None
    return lsq_sparse.factorize(N, G, C)


def _free_pos(net: Network, free: np.ndarray) -> np.ndarray:
    """Position among ``free`` of every global (-1 where not free), ``(q,)``."""
    pos = np.full(net.q + 1, -1, np.int64)
    pos[free] = np.arange(len(free))
    return pos


def _entries(f: lsq_sparse.Factor, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``f.entries`` with zeros where ``a`` or ``b`` is -1 (not a free unknown)."""
    use = (a >= 0) & (b >= 0)
    out = np.zeros(np.broadcast(a, b).shape)
    a, b = np.broadcast_to(a, out.shape), np.broadcast_to(b, out.shape)
    out[use] = f.entries(a[use], b[use])
    return out


def _point_blocks(net: Network, pos: np.ndarray, f: lsq_sparse.Factor) -> np.ndarray:
    """Point covariances ``(n, 2, 2)`` (zero for coordinates not estimated)."""
    px, py = pos[0 : 2 * net.n : 2], pos[1 : 2 * net.n : 2]
    cxx, cxy, cyy = _entries(f, px, px), _entries(f, px, py), _entries(f, py, py)
    return np.stack([np.stack([cxx, cxy], -1), np.stack([cxy, cyy], -1)], -2)


#: observation rows of the reliability taken at a time (:func:`_reliability`): each row looks
#: up its ``s x s`` block of cofactors (49 entries for a direction), and the whole network's
#: at once, with the datum's low-rank terms gathered for every entry, was the peak of
#: loading a 90,000-point network (2.5 GiB, the factor and its selected inverse 1.3)
RELIABILITY_ROWS = 1 << 14


def _reliability(net: Network, pos: np.ndarray, f: lsq_sparse.Factor, a0: float, power: float):
    """Redundancy numbers, MDB, bias-to-noise ratio and the local external reliability, by
    blocks of :data:`RELIABILITY_ROWS` rows (each row's own numbers: the same values)."""
    cols = pattern(net)
    _, vals = jacobian_sparse(net, net.theta_true()[None])
    fc = pos[np.where(cols >= 0, cols, net.q)]  # (m, s) free positions, -1 unused
    a = np.where(fc >= 0, vals[0] / net.sigma[:, None], 0.0)  # weighted rows
    del vals
    h = np.empty(net.m)
    for lo in range(0, net.m, RELIABILITY_ROWS):
        b = slice(lo, lo + RELIABILITY_ROWS)
        Qrow = _entries(f, fc[b, :, None], fc[b, None, :])  # (rows, s, s)
        h[b] = np.einsum("mu,muv,mv->m", a[b], Qrow, a[b])
    r = np.clip(1.0 - h, 0.0, 1.0)
    d0 = delta0(a0, power)
    with np.errstate(divide="ignore", invalid="ignore"):
        controlled = r > 1e-9
        mdb = np.where(controlled, d0 * net.sigma / np.sqrt(r), np.inf)
        bnr = np.where(controlled, d0 * np.sqrt((1 - r) / r), np.inf)
        gain = np.where(controlled, mdb / net.sigma, 0.0)
    disp = np.zeros(net.m)
    for e in (net.i, net.j, net.k):  # the points the observation ties
        ex = pos[np.where(e >= 0, 2 * e, net.q)]
        ey = pos[np.where(e >= 0, 2 * e + 1, net.q)]
        for lo in range(0, net.m, RELIABILITY_ROWS):
            b = slice(lo, lo + RELIABILITY_ROWS)
            sx = np.einsum("mu,mu->m", _entries(f, ex[b, None], fc[b]), a[b]) * gain[b]
            sy = np.einsum("mu,mu->m", _entries(f, ey[b, None], fc[b]), a[b]) * gain[b]
            disp[b] = np.maximum(disp[b], np.hypot(sx, sy))
    ext = np.where(controlled, disp, np.inf)
    return r, mdb, ext, bnr


def analyse_sparse(net: Network, datum: lsq.Datum, a0: float, power: float) -> SparseAnalytic:
    """The analytic pre-analysis of ``net`` in ``datum`` on the sparse path (see the module
    doc); ``ok`` False (and NaN measures) when the normals are singular in the datum."""
    free = datum.free_index(net.q)
    show = shows_phases(net.q)
    with phase(f"network: factorising the normals ({net.q:,} unknowns)", show):
        f = factor(net, datum)
    C = datum.constraint_matrix(net.theta_true()[None])
    c = 0 if C is None else C.shape[-1]
    if not f.ok:
        nan = np.full(net.m, np.nan)
        cov = np.full((net.n, 2, 2), np.nan)
        return SparseAnalytic(free, None, cov, nan, nan, nan, nan, 0, False, factor=f)
    pos = _free_pos(net, free)
    with phase("network: pre-analysis (covariances, redundancy numbers, MDBs)", show):
        cov = _point_blocks(net, pos, f)
        r, mdb, ext, bnr = _reliability(net, pos, f, a0, power)
    dof = net.m - len(free) + c
    A = weighted_design(net, free)
    n_diag = np.asarray(A.multiply(A).sum(axis=0)).ravel()  # diagonal of A'PA
    return SparseAnalytic(free, None, cov, r, mdb, ext, bnr, int(dof), True, n_diag, factor=f)


def pre_analysis(net: Network, datum: lsq.Datum, a0: float, power: float) -> Analytic:
    """The analytic pre-analysis on the path the network's size calls for: the dense one
    (:func:`sim.studies.network.analysis.analyse`) below :data:`SPARSE_MIN_UNKNOWNS`
    unknowns, the sparse one from there."""
    if not use_sparse(net):
        return analyse(net, datum, a0, power)
    key = _key(net, datum, a0, power)
    an = _LAST.get(key)  # `sim run` checks the config, then runs it: one analysis for both
    if an is None:  # (held here: a thread's load of another network clears it meanwhile)
        an = analyse_sparse(net, datum, a0, power)
        _LAST.clear()
        _LAST[key] = an
    return an


#: the last sparse pre-analysis of this process, by the digest of its inputs
_LAST: dict[str, SparseAnalytic] = {}


def _key(net: Network, datum: lsq.Datum, a0: float, power: float) -> str:
    """Digest of everything a pre-analysis reads: the network's arrays and parameters, the
    datum's free unknowns and constraints, the test's level and power."""
    h = hashlib.sha256(repr((net.name, net.names, net.stations, a0, power)).encode())
    for a in (net.xy, net.role, net.kind, net.i, net.j, net.k, net.sigma, net.oset):
        h.update(np.ascontiguousarray(a).tobytes())
    h.update(
        repr(
            (
                net.constant_mm,
                net.estimate_constant,
                net.offset_mm,
                net.scale_ppm,
                net.estimate_scale,
            )
        ).encode()
    )
    h.update(np.asarray(datum.free_index(net.q)).tobytes())
    C = datum.constraint_matrix(net.theta_true()[None])
    h.update(b"" if C is None else np.ascontiguousarray(C).tobytes())
    return h.hexdigest()


def variances(an: Analytic, idx: np.ndarray) -> np.ndarray:
    """Cofactor diagonal of the free unknowns at positions ``idx`` (dense or sparse path)."""
    idx = np.asarray(idx, int)
    if isinstance(an, SparseAnalytic):
        return an.factor.entries(idx, idx)
    return an.Q[idx, idx]


def in_datum_sparse(
    net: Network, an: SparseAnalytic, points: list[int], H: np.ndarray | None = None
) -> np.ndarray:
    """Point covariances ``(n, 2, 2)`` in the inner datum over ``points``, removing every
    defect the network has (:func:`sim.studies.network.analysis.inner_defect`: translation,
    rotation and, for a network without a length, scale; as the dense
    :func:`~sim.studies.network.analysis.in_datum`): ``S Q S'`` with
    ``S = I - H (H' W H)^-1 H' W`` as a low-rank correction of the selected entries (``d``
    solves with the factor, no dense matrix); or the defects ``H`` only (those the fixed
    points leave, :func:`~sim.studies.network.analysis.held_defect`)."""
    f = an.factor
    Q0 = _point_blocks(net, _free_pos(net, an.free), f)
    H = inner_defect(net) if H is None else H  # (2n, d)
    if not H.shape[1]:
        return Q0
    V = H * datum_weights(net, points)[:, None]
    U = H @ np.linalg.inv(H.T @ V)
    pos = _free_pos(net, an.free)[: 2 * net.n]
    est = pos >= 0
    B = np.zeros((f.p, H.shape[1]))
    B[pos[est]] = V[est]
    QV = np.zeros_like(H)
    QV[est] = f.cov_times(B)[pos[est]]
    K = V.T @ QV
    out = np.empty_like(Q0)
    for u in range(2):
        for v in range(2):
            a, b = np.arange(net.n) * 2 + u, np.arange(net.n) * 2 + v
            out[:, u, v] = (
                Q0[:, u, v]
                - np.einsum("ki,ki->k", U[a], QV[b])
                - np.einsum("ki,ki->k", QV[a], U[b])
                + np.einsum("ki,ij,kj->k", U[a], K, U[b])
            )
    return out


def mc_chunk_sparse(
    rng: np.random.Generator,
    n: int,
    net: Network,
    free: np.ndarray,
    fac: lsq_sparse.Factor,
    cov_inv: np.ndarray,
    pts: np.ndarray,
    crit: float,
    tol: float,
    max_iter: int,
    dof: int,
    par: np.ndarray | None = None,
) -> dict:
    """One chunk of ``n`` simulated adjustments on the sparse path: the outputs of
    :func:`sim.studies.network.analysis.mc_chunk` (same keys, same simulated readings)."""
    obs = simulate(net, rng, n)
    theta0 = np.repeat(net.theta_true()[None], n, 0)
    fpos = _free_pos(net, free)[: net.q]
    theta, vpv, iters, status = lsq_sparse.gauss_newton_shared(
        lambda th, rows: residual_gradient(net, fpos, th, obs[rows]),
        theta0,
        free,
        fac,
        1.0 / net.sigma**2,
        tol,
        max_iter,
        linear=bool(np.isin(net.kind, (3, 4, 5, 6)).all()),
    )
    ok = status == 0
    vpv = vpv if dof > 0 else np.zeros(n)
    s0 = np.sqrt(vpv / dof) if dof > 0 else np.full(n, np.nan)
    return chunk_output(net, theta - theta0, ok, pts, cov_inv, vpv, crit, par, status, s0, iters)
