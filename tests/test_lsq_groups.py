"""The group-block engine (sim.lsq.groups, sim.lsq.group_solve, sim.lsq.sparse_batch) on a
small block of independent models: the sparse L D L' and the banded elimination equal the dense
solve, a chunk of trials gives the same numbers however it is split, the size rule picks the
path, cofactors restricted to some points equal the full ones, a non-positive-definite trial
is flagged, not raised."""

from __future__ import annotations

import numpy as np
import pytest

from sim.instruments.block import independent_models as im
from sim.instruments.block.layout import make_block, select_control
from sim.lsq import compile, group_kernel, group_kernel_solve, groups, size, sparse_batch
from sim.lsq import group_solve as gs

needs_jit = pytest.mark.skipif(not compile.available(), reason="the sparse path is compiled")


@pytest.fixture(scope="module")
def setup():
    b = make_block(2, 4, n_ground=50, pass_rows=3)
    rng = np.random.default_rng(3)
    T = 3
    xm, _ = im.noisy_models(b, rng, T, 0.1)
    ctrl = select_control(b, "perimeter")
    st = im.BlockStructure(b.obs_model, b.obs_point, ctrl, b.n_models, b.n_points)
    X0 = b.points + rng.normal(0, 2.0, (T,) + b.points.shape)
    s0, R0, t0 = im.initial_values(st, xm, X0)
    w = rng.uniform(0.5, 2.0, (T, b.obs_model.size, 3))
    wc = np.full((ctrl.size, 3), 25.0)
    cx = np.broadcast_to(b.points[ctrl], (T, ctrl.size, 3))
    return b, st, xm, w, cx, wc, (s0, R0, t0, X0)


def test_banded_solve_equals_dense(setup):
    b, st, xm, w, cx, wc, (s0, R0, t0, X0) = setup
    c = np.zeros((xm.shape[0], st.n_models, 3))
    args = (st, xm, c, s0, R0, t0, X0, w, cx, np.broadcast_to(wc, (xm.shape[0],) + wc.shape))
    dg, dX = im.normal_step(*args, solver="dense")
    dg2, dX2 = im.normal_step(*args, solver="band")
    assert st.band.width < st.n_groups  # the reordering gives a band narrower than G
    assert np.allclose(dg2, dg, rtol=1e-8, atol=1e-10 * np.abs(dg).max())
    assert np.allclose(dX2, dX, rtol=1e-8, atol=1e-10 * np.abs(dX).max())


def _reduced(setup):
    b, st, xm, w, cx, wc, (s0, R0, t0, X0) = setup
    model = im.SimilarityModel(st, xm, np.zeros((xm.shape[0], st.n_models, 3)), w, cx, wc)
    return st, groups.reduce(st, model.linearize(X0, im._state(s0, R0, t0)))


@needs_jit
def test_sparse_ldl_equals_dense(setup):
    """The sparse L D L' (minimum-degree order) equals the dense Cholesky: the relative
    difference of two backward-stable solves is bounded by cond(N) eps; the reduced normals
    of this block (scaled) have cond about 1e4, so 1e-10 holds with margin."""
    st, red = _reduced(setup)
    dg, ok = groups.solve(st, red, "dense")
    dg2, ok2 = groups.solve(st, red, "sparse")
    assert ok.all() and ok2.all()
    assert np.abs(dg2 - dg).max() <= 1e-10 * np.abs(dg).max()
    pat = st.batch_pattern(7)
    assert pat.nnz < (7 * st.n_groups) * (7 * st.n_groups + 1) // 2  # a sparse factor


@needs_jit
def test_sparse_ldl_chunk_split_gives_the_same_numbers(setup):
    st, red = _reduced(setup)
    T = red.ubar.shape[0]
    rhs = red.ubar.reshape(T, -1)
    pat = st.batch_pattern(7)
    x, ok = sparse_batch.solve_batch(pat, red.blocks, rhs)
    parts = [sparse_batch.solve_batch(pat, red.blocks[i], rhs[i]) for i in ([0], [1, 2])]
    assert np.array_equal(np.concatenate([p[0] for p in parts]), x)
    assert np.concatenate([p[1] for p in parts]).tolist() == ok.tolist() == [True] * T


@needs_jit
def test_sparse_ldl_flags_an_indefinite_trial(setup):
    st, red = _reduced(setup)
    T = red.ubar.shape[0]
    blocks = red.blocks.copy()
    blocks[1, st.diag_of_group[2]] *= -1.0  # trial 1 no longer positive definite
    pat = st.batch_pattern(7)
    x, ok = sparse_batch.solve_batch(pat, blocks, red.ubar.reshape(T, -1))
    assert ok.tolist() == [True, False, True]
    x0, _ = sparse_batch.solve_batch(pat, red.blocks, red.ubar.reshape(T, -1))
    assert np.array_equal(x[[0, 2]], x0[[0, 2]])


def test_size_rule_picks_the_path():
    """One rule: 400 reduced unknowns; a block of 7-parameter models from 58 models."""
    assert im.SPARSE_FROM_MODELS == 58 and size.SPARSE_MIN_UNKNOWNS == 400
    for strips, models in ((2, 28), (2, 29)):
        b = make_block(strips, models, n_ground=4 * strips * models, pass_rows=3)
        st = im.BlockStructure(b.obs_model, b.obs_point, [0], b.n_models, b.n_points)
        assert st.sparse(7) == size.use_sparse(7 * b.n_models) == (b.n_models >= 58)


def test_band_solve_flags_an_indefinite_trial(setup):
    b, st, xm, w, cx, wc, (s0, R0, t0, X0) = setup
    model = im.SimilarityModel(st, xm, np.zeros((xm.shape[0], st.n_models, 3)), w, cx, wc)
    lin = model.linearize(X0, im._state(s0, R0, t0))
    red = groups.reduce(st, lin)
    blocks = red.blocks.copy()
    blocks[1, st.diag_of_group[2]] *= -1.0  # trial 1 no longer positive definite
    x, ok = gs.band_solve(st, blocks, red.ubar.reshape(xm.shape[0], -1))
    assert ok.tolist() == [True, False, True]
    x0, _ = gs.band_solve(st, red.blocks, red.ubar.reshape(xm.shape[0], -1))
    assert np.allclose(x[[0, 2]], x0[[0, 2]])


def test_residual_cofactors_of_some_points_equal_all(setup):
    b, st, xm, w, cx, wc, (s0, R0, t0, X0) = setup
    model = im.SimilarityModel(st, xm, np.zeros((xm.shape[0], st.n_models, 3)), w, cx, wc)
    lin = model.linearize(X0, im._state(s0, R0, t0))
    cof = groups.cofactors(st, lin)
    q = cof.residuals(lin)
    sub = cof.residuals(lin, b.is_pass)
    k = b.is_pass[b.obs_point]
    assert np.allclose(sub[:, k], q[:, k], rtol=1e-12)
    assert np.isnan(sub[:, ~k]).all()


def test_chol_subst_blocks_match_numpy():
    rng = np.random.default_rng(2)
    a = rng.normal(size=(3, 45, 45))
    N = a @ a.transpose(0, 2, 1) + 45 * np.eye(45)
    rhs = rng.normal(size=(3, 45, 4))
    for block in (1, 7, 32, 64):
        x = gs.chol_subst(np.linalg.cholesky(N), rhs, block)
        assert np.allclose(x, np.linalg.solve(N, rhs), rtol=1e-10, atol=1e-12)


def test_compiled_kernels_equal_numpy(setup):
    """The compiled pair blocks and residual cofactors (sim.lsq.group_kernel) equal the NumPy
    path to rounding, with a removed observation (weight 0)."""
    if not compile.available():
        pytest.skip("numba not installed")
    b, st, xm, w, cx, wc, (s0, R0, t0, X0) = setup
    w = w.copy()
    w[:, 4] = 0.0
    model = im.SimilarityModel(st, xm, np.zeros((xm.shape[0], st.n_models, 3)), w, cx, wc)
    lin = model.linearize(X0, im._state(s0, R0, t0))
    r0, r1 = groups.reduce(st, lin, jit=False), groups.reduce(st, lin, jit=True)
    blocks, ubar = group_kernel.pair_blocks(st, r0.Npg, r0.NinvK, lin.Jg, lin.w, lin.r, r0.up)
    dg = np.random.default_rng(5).normal(size=r0.ubar.shape)
    L = np.linalg.cholesky(gs.dense(st, r0.blocks))
    y = r0.ubar.reshape(len(L), -1)
    for a, c in (
        (r0.blocks, r1.blocks),
        (r0.ubar, r1.ubar),
        (r0.Ninv, r1.Ninv),
        (r0.NinvK, r1.NinvK),
        (r0.up, r1.up),
        (r0.blocks, blocks),
        (r0.ubar, ubar),
        (
            groups.points_step(st, r0, dg),
            np.einsum(
                "tpij,tpj->tpi",
                r0.Ninv,
                r0.up - groups.scatter(st.S_point, (r0.Npg * dg[:, st.obs_group, None, :]).sum(-1)),
            ),
        ),
        (gs.chol_subst(L, y[..., None])[..., 0], group_kernel_solve.chol_vec(L, y)),
        (
            gs.chol_subst(L, np.broadcast_to(np.eye(L.shape[1]), L.shape).copy()),
            group_kernel_solve.chol_inv(L),
        ),
    ):
        assert np.abs(c - a).max() <= 1e-12 * np.abs(a).max()
    assert r1.ok.tolist() == r0.ok.tolist()
    for a, c in zip(
        gs.scaled(gs.dense(st, r0.blocks)), group_kernel_solve.dense_scaled(st, r0.blocks)
    ):
        assert np.array_equal(a, c)
    cof = groups.cofactors(st, lin)
    for pts in (None, b.is_pass):
        q0, q1 = cof.residuals(lin, pts, jit=False), cof.residuals(lin, pts, jit=True)
        assert np.array_equal(np.isnan(q0), np.isnan(q1))
        # relative to the scale of Q_vv, W^-1 (a point seen once has q_vv = 0)
        assert np.nanmax(np.abs(q1 - q0) * w) <= 1e-12


def test_singular_and_non_finite_trials_are_flagged(setup):
    """A trial whose model 0 lost every observation (singular normals) and one with a
    non-finite model coordinate are flagged; the others are the same as adjusted alone."""
    b, st, xm, w, cx, wc, (s0, R0, t0, X0) = setup
    xm, w = xm.copy(), w.copy()
    w[0, st.obs_model == 0] = 0.0
    xm[2, 3, 1] = np.nan
    res = im.adjust_block(st, xm, w, cx, wc, s0, R0, t0, X0)
    assert res.status[0] == 2 and res.status[2] != 0 and not res.converged[[0, 2]].any()
    one = im.adjust_block(st, xm[1:2], w[1:2], cx[1:2], wc, s0[1:2], R0[1:2], t0[1:2], X0[1:2])
    assert res.status[1] == 0
    assert np.allclose(res.X[1], one.X[0], rtol=0, atol=1e-9)
