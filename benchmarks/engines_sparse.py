"""Engine rows of the sparse path (issue 23): the compiled kernels of :mod:`sim.lsq.selinv`,
:mod:`sim.lsq.sparse_batch` and :mod:`sim.studies.network.kernel` against the NumPy / SciPy
way of getting the same numbers, on the same inputs.

* ``selinv``: the 2 x 2 covariance block of every point of a triangulation grid (directions to
  the 8 nearest, two corners fixed: a regular datum, so the blocks are the selected inverse
  alone), from the factor of its normals (:func:`sim.studies.network.sparse_analysis.factor`)
  by selected inversion (:meth:`sim.lsq.sparse.Factor.entries`: the filled pattern, Takahashi's
  recurrence, the look-up) against column solves with the *same* factor (SciPy's
  ``spsolve_triangular``, 256 columns a block, the two columns of each point); the per-trial
  loop solves the two columns of one point at a time. A "trial" of this row is a point.
* ``sparse_solve``: :meth:`sim.lsq.sparse.Factor.solve` of a block of right-hand sides (one
  per Monte-Carlo trial) with the compiled substitutions of :mod:`sim.lsq.selinv` against
  SciPy's ``spsolve_triangular`` on the same factor (the path under ``SIM_NO_JIT=1``); the
  per-trial loop solves one right-hand side at a time with SciPy.
* ``block_sparse``: the reduced normals of the independent-model block of
  ``studies/agnard_block_104.toml`` (seed ``003``: 4 strips of 26 models, 1,150 ground points,
  control on the perimeter) solved for every trial by the batched sparse ``L D L'``
  (:func:`sim.lsq.sparse_batch.solve_batch`) against the banded NumPy elimination it replaced
  (:func:`sim.lsq.group_solve.band_solve`, the path under ``SIM_NO_JIT=1``); the per-trial
  loop assembles each trial's sparse matrix and solves it with SciPy's ``splu`` (minimum
  degree, symmetric mode), as a user would.
* ``network_gradient``: the residuals and gradient ``A' W r`` of every trial of a chunk of
  ``studies/network_gridplate_2500.toml`` (2,500 points, 25,000 observations), the compiled
  kernel against its NumPy twin (:func:`sim.studies.network.kernel.residual_gradient_numpy`,
  the path under ``SIM_NO_JIT=1``); the per-trial loop is the NumPy twin trial by trial.

Every row checks both sides equal on the first trials before it times them (the case's
tolerance, relative to the size of the quantity); CPU times, the best of alternating rounds
(:mod:`benchmarks.engines`).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from scipy import sparse
from scipy.sparse.linalg import splu, spsolve_triangular

from benchmarks.case import Case
from sim.instruments.block import independent_models as im
from sim.instruments.block.layout import make_block, select_control
from sim.lsq import group_solve, groups, sparse_batch
from sim.mc.config import validate
from sim.studies import load_study
from sim.studies.network.definition import build
from sim.studies.network.gama import merge_gama
from sim.studies.network.kernel import residual_gradient, residual_gradient_numpy
from sim.studies.network.model import datum, simulate
from sim.studies.network.schema import SCHEMA
from sim.studies.network.sparse_analysis import factor

__all__ = ["selinv", "sparse_solve", "block_sparse", "network_gradient"]

ROOT = Path(__file__).resolve().parent.parent
#: the selected inverse and the column solves agree to rounding: covariances (mm^2) of a
#: well-conditioned network, relative to the largest entry
TOL_SELINV = 1e-10
#: substitutions of the same factor in another order: relative to the largest solution
TOL_SOLVE = 1e-12
#: two factorisations of the reduced normals (cond ~1e6 scaled): relative to the largest
#: correction
TOL_BLOCK = 1e-8
#: the same sums in another order: relative to the largest gradient entry
TOL_GRADIENT = 1e-12
_WHY_SPARSE = (
    "each trial is one compiled SuperLU call on a few thousand unknowns; the loop's "
    "overhead is small beside it"
)


def _triangulation(side: int):
    """A triangulation grid of ``side`` x ``side`` points (directions to the 8 nearest, one
    orientation per station, two corners fixed; the bench's scaling network)."""
    raw = {
        "trials": 40,
        "chunk": 20,
        "network.grids": [
            {"prefix": "P", "nx": side, "ny": side, "spacing_mm": 1e5, "origin_mm": [0.0, 0.0]}
        ],
        "network.points": [
            {"name": "A", "x_mm": -1e5, "y_mm": -1e5, "role": "fixed"},
            {"name": "B", "x_mm": 1e5 * side, "y_mm": -1e5, "role": "fixed"},
        ],
        "network.generate": [
            {"kind": "direction", "from": "P*", "to": "P*", "nearest": 8, "sigma_arcsec": 1.0},
            {"kind": "distance", "from": ["A", "B"], "to": "P*", "nearest": 3, "sigma_mm": 1.0},
        ],
        "datum.kind": "fixed",
    }
    cfg = validate(raw, SCHEMA)
    net = build(cfg)
    return net, factor(net, datum(net, cfg))


def _lower(f):
    """The factor's unit lower triangle ``L`` and ``L'`` (CSR) for SciPy's substitutions."""
    n = f.D.size
    L = sparse.csc_matrix((f.data, f.indices, f.indptr), shape=(n, n)) + sparse.identity(n)
    return sparse.csr_matrix(L), sparse.csr_matrix(L.T)


def _rel(x: np.ndarray) -> np.ndarray:
    """``x`` over its largest magnitude (the rows compare relative differences)."""
    return np.asarray(x) / np.abs(x).max()


def selinv(T: int) -> Case:
    """Point covariance blocks of a grid of about ``T`` points (side ``round(sqrt(T))``)."""
    side = max(int(round(np.sqrt(T))), 4)
    net, f = _triangulation(side)
    a, b = f.pos[0 : 2 * side * side : 2], f.pos[1 : 2 * side * side : 2]  # x, y of P*
    s = f.s[0 : 2 * side * side]
    sa, sb = s[0::2], s[1::2]
    L, LT = _lower(f)
    ref = []

    def engine():
        f.Zx = f.Zd = None  # the selected inverse again, each call
        x, y = np.arange(0, 2 * side * side, 2), np.arange(1, 2 * side * side, 2)
        out = np.stack([f.entries(x, x), f.entries(x, y), f.entries(y, y)], 1)
        if not ref:
            ref.append(np.abs(out).max())
        return out / ref[0]

    def columns(idx: np.ndarray) -> np.ndarray:
        out = []
        for k in range(0, len(idx), 256):
            cols = idx[k : k + 256]
            B = np.zeros((f.D.size, cols.size))
            B[cols, np.arange(cols.size)] = 1.0
            Y = spsolve_triangular(L, B, lower=True, unit_diagonal=True) / f.D[:, None]
            out.append(spsolve_triangular(LT, Y, lower=False, unit_diagonal=True))
        return np.concatenate(out, 1)

    def numpy():
        Za, Zb = columns(a), columns(b)
        k = np.arange(a.size)
        out = np.stack([Za[a, k] * sa * sa, Za[b, k] * sa * sb, Zb[b, k] * sb * sb], 1)
        return out / ref[0]

    def one(t):
        Z = columns(np.array([a[t], b[t]]))
        return (
            np.array([Z[a[t], 0] * sa[t] ** 2, Z[b[t], 0] * sa[t] * sb[t], Z[b[t], 1] * sb[t] ** 2])
            / ref[0]
        )

    engine()
    return Case(
        side * side,
        engine,
        one,
        TOL_SELINV,
        "relative to the largest covariance",
        "scipy.sparse.linalg.spsolve_triangular, two columns per point",
        _WHY_SPARSE,
        module="sim.lsq.selinv (takahashi and lookup)",
        numpy=numpy,
        numpy_label="column solves with the same factor (SciPy spsolve_triangular)",
    )


def sparse_solve(T: int, side: int = 50) -> Case:
    """A block of ``T`` right-hand sides on the factor of a ``side`` x ``side`` grid."""
    net, f = _triangulation(side)
    rng = np.random.default_rng(11)
    B = rng.normal(size=(f.p, T))
    L, LT = _lower(f)
    scale = np.abs(f.solve(B[:, :1])).max()

    def engine():
        return (f.solve(B) / scale).T

    def one(t):
        Y = np.zeros(f.D.size)
        Y[f.pos] = B[f.keep, t] * f.s
        Y = spsolve_triangular(L, Y, lower=True, unit_diagonal=True) / f.D
        Y = spsolve_triangular(LT, Y, lower=False, unit_diagonal=True)
        x = np.zeros(f.p)
        x[f.keep] = Y[f.pos] * f.s
        return x / scale

    return Case(
        net.n,
        engine,
        one,
        TOL_SOLVE,
        "relative to the largest solution",
        "scipy.sparse.linalg.spsolve_triangular, one right-hand side at a time",
        _WHY_SPARSE,
        module="sim.lsq.selinv (forward and backward)",
    )


def _assemble(st, blocks: np.ndarray, b: int) -> sparse.csc_matrix:
    """One trial's reduced normals (``blocks`` (n_pairs, b, b)) as a sparse matrix."""
    ii, jj = np.meshgrid(np.arange(b), np.arange(b), indexing="ij")
    r = (st.pair_g1[:, None, None] * b + ii).ravel()
    c = (st.pair_g2[:, None, None] * b + jj).ravel()
    n = st.n_groups * b
    return sparse.csc_matrix((blocks.ravel(), (r, c)), shape=(n, n))


def block_sparse(T: int, seed: int = 5) -> Case:
    """The reduced normals of agnard_block_104's block, ``T`` trials."""
    rng = np.random.default_rng(seed)
    blk = make_block(4, 26, n_ground=1150, pass_rows=4)
    xm, _ = im.noisy_models(blk, rng, T, 0.05)
    ctrl = select_control(blk, "perimeter")
    st = im.BlockStructure(blk.obs_model, blk.obs_point, ctrl, blk.n_models, blk.n_points)
    X0 = blk.points + rng.normal(0, 2.0, (T,) + blk.points.shape)
    s0, R0, t0 = im.initial_values(st, xm, X0)
    w = np.ones((T, blk.obs_model.size, 3))
    cx = np.broadcast_to(blk.points[ctrl], (T, ctrl.size, 3))
    model = im.SimilarityModel(
        st, xm, np.zeros((T, st.n_models, 3)), w, cx, np.full((ctrl.size, 3), 25.0)
    )
    red = groups.reduce(st, model.linearize(X0, im._state(s0, R0, t0)))
    b = red.ubar.shape[-1]
    rhs = red.ubar.reshape(T, -1)
    pat = st.batch_pattern(b)
    scale = []

    def engine():
        x, ok = sparse_batch.solve_batch(pat, red.blocks, rhs)
        if not ok.all():
            raise RuntimeError("bench: block_sparse: a trial of the block is singular")
        if not scale:
            scale.append(np.abs(x).max())
        return x / scale[0]

    def numpy():
        x, _ = group_solve.band_solve(st, red.blocks, rhs)
        return x / scale[0]

    def one(t):
        N = _assemble(st, red.blocks[t], b)
        d = 1.0 / np.sqrt(N.diagonal())
        Ns = sparse.csc_matrix(sparse.diags(d) @ N @ sparse.diags(d))
        lu = splu(
            Ns, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, options={"SymmetricMode": True}
        )
        return lu.solve(rhs[t] * d) * d / scale[0]

    engine()
    return Case(
        blk.n_points,
        engine,
        one,
        TOL_BLOCK,
        "relative to the largest model correction",
        "scipy.sparse.linalg.splu per trial (minimum degree, symmetric mode)",
        _WHY_SPARSE,
        module="sim.lsq.sparse_batch",
        numpy=numpy,
        numpy_label="the banded NumPy elimination (group_solve.band_solve, SIM_NO_JIT=1)",
    )


def network_gradient(T: int, seed: int = 2500) -> Case:
    """Residuals and gradient of ``T`` trials of network_gridplate_2500 near the truth."""
    _, cfg = load_study(ROOT / "studies" / "network_gridplate_2500.toml", [])
    cfg = merge_gama(cfg)
    net = build(cfg)
    free = datum(net, cfg).free_index(net.q)
    fpos = np.full(net.q, -1, np.int64)
    fpos[free] = np.arange(len(free))
    rng = np.random.default_rng(seed)
    obs = simulate(net, rng, T)
    theta = net.theta_true()[None] + rng.normal(0.0, 1e-3, (T, net.q))
    scale = np.abs(residual_gradient_numpy(net, fpos, theta[:1], obs[:1])[1]).max()

    def engine():
        return residual_gradient(net, fpos, theta, obs)[1] / scale

    def one(t):
        return residual_gradient_numpy(net, fpos, theta[t : t + 1], obs[t : t + 1])[1][0] / scale

    return Case(
        net.n,
        engine,
        one,
        TOL_GRADIENT,
        "relative to the largest gradient entry",
        "the NumPy twin, one trial at a time",
        "the NumPy twin is already vectorised over the observations of one trial",
        module="sim.studies.network.kernel",
        numpy=lambda: residual_gradient_numpy(net, fpos, theta, obs)[1] / scale,
        numpy_label="its NumPy twin (residual_gradient_numpy, SIM_NO_JIT=1)",
    )
