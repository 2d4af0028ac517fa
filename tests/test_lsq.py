"""The batched least-squares engine (sim.lsq): fast path, singularity rule, cofactors."""

import numpy as np
import pytest

from sim import lsq
from sim.instruments.plates import grid_points
from sim.instruments.ranges import multilateration as ml
from sim.instruments.ranges import positions as po

H = 122.5 + 45.0
PTS = grid_points(5, 55.0)
THETA = ml.design_theta(H, 0.5, 1.0)


def batch(a, T):
    return np.broadcast_to(a, (T,) + a.shape).copy()


@pytest.mark.skipif(not ml.jit.available(), reason="numba not installed")
@pytest.mark.parametrize("model", list(ml.MODELS))
def test_generic_engine_equals_compiled_fast_path(model):
    """The engine's loop and the registered numba kernel on the same trials.

    Measured (200 trials, 2 um ranges, 25 points): points and station coordinates agree to
    ~1e-15 of the comparator scale, alpha to ~5e-13 mm, ``b = beta^2`` to ~2e-11 relative
    (its column is the worst conditioned one: summation order in the reduced normals),
    sigma0 to ~5e-12 relative (residuals of um are differences of 170 mm quantities). The
    tolerances are the tightest these levels allow."""
    T = 200
    rng = np.random.default_rng(5)
    r = ml.simulate_ranges(batch(PTS, T), batch(THETA, T), rng, setting_sigma_um=2.0, settings=1)
    t0 = THETA.copy()
    t0[5 : ml.MODELS[model]] = 0.0
    a = ml.adjust(r, model, t0, engine="numpy")
    b = ml.adjust(r, model, t0, engine="numba")
    assert np.array_equal(a.status, b.status) and a.converged.all()
    assert np.array_equal(a.iterations, b.iterations)
    scale = np.abs(b.points).max()
    assert np.abs(a.points - b.points).max() <= 1e-12 * scale
    assert np.abs(a.theta[:, :6] - b.theta[:, :6]).max() <= 1e-12 * scale
    assert np.abs(a.theta[:, 6] - b.theta[:, 6]).max() <= 1e-10 * np.abs(b.theta[:, 6]).max()
    assert np.abs(a.residuals - b.residuals).max() <= 1e-12 * scale
    assert np.allclose(a.sigma0, b.sigma0, rtol=1e-10, atol=0)


def test_fast_engine_refuses_what_it_cannot_do():
    r = ml.ranges(batch(PTS, 2), batch(THETA, 2))
    m = po.RangeModel(r)  # no Brown layout: no fast path
    with pytest.raises(ValueError, match="fast path"):
        lsq.gauss_newton(m, po.from_brown_theta(batch(THETA, 2)), engine="fast")


def test_singular_and_bad_trials_are_flagged_with_a_message_not_raised():
    """One collinear trial and one NaN observation among good trials: the bad trials get
    status 2/3 and a message, the good ones are exactly what they are alone."""
    T = 5
    rng = np.random.default_rng(3)
    pts = batch(PTS, T)
    pts[1] = np.stack([np.linspace(-50, 50, len(PTS)), np.zeros(len(PTS))], 1)
    r = ml.simulate_ranges(pts, batch(THETA, T), rng, setting_sigma_um=1.0, settings=1)
    r[3, 4, 2] = np.nan
    t0 = THETA.copy()
    t0[5:] = 0.0
    res = ml.adjust(r, "pivot", t0, engine="numpy")
    assert res.status[1] in (2, 3) and res.status[3] in (2, 3)
    assert res.converged[[0, 2, 4]].all()
    assert "singular" in res.message[1] or "non-finite" in res.message[1]
    assert res.message[0] == "converged"
    alone = ml.adjust(r[[0, 2, 4]], "pivot", t0, engine="numpy")
    assert np.array_equal(alone.points, res.points[[0, 2, 4]])


def test_scaled_rule_ignores_units_and_sees_rank():
    rng = np.random.default_rng(1)
    A = rng.normal(size=(4, 6, 3))
    N = A.transpose(0, 2, 1) @ A
    D = np.diag([1e-6, 1.0, 1e6])
    assert np.allclose(lsq.scaled_rcond(D @ N @ D), lsq.scaled_rcond(N), rtol=1e-8)
    A[..., 2] = A[..., 0] + A[..., 1]
    assert (lsq.scaled_rcond(A.transpose(0, 2, 1) @ A) < lsq.RCOND).all()
    two = np.array([[[4.0, 1.0], [1.0, 9.0]]])
    ev = np.linalg.eigvalsh(two / np.sqrt(np.outer([4, 9], [4, 9])))
    assert lsq.scaled_rcond(two)[0] == pytest.approx(ev.min() / ev.max(), rel=1e-14)


@pytest.mark.parametrize("datum", ["brown", "inner"])
def test_bordered_cofactors_equal_dense_constrained_inverse(datum):
    """Point cofactors from the Schur complement and the bordered reduced normals equal the
    dense bordered inverse of the full normal matrix with the datum constraints."""
    th = po.from_brown_theta(THETA)
    P, n = 4, len(PTS)
    m = po.RangeModel(None, P=P)
    lin = m.linearize(PTS[None], th[None], True)
    A = np.zeros((P * n, 2 * n + 2 * P + 2))
    for j in range(n):
        A[P * j : P * j + P, 2 * j : 2 * j + 2] = lin.Jp[0, j]
        A[P * j : P * j + P, 2 * n :] = lin.Jg[0, j]
    C = np.zeros((2 * n + 2 * P + 2, 3))
    C[2 * n :] = po.datum_constraints(th[None], 2 * P + 2, datum)[0]
    M = np.block([[A.T @ A, C], [C.T, np.zeros((3, 3))]])
    dense = np.linalg.inv(M)[: 2 * n, : 2 * n]
    full = po.full_point_covariance(PTS[None], th[None], "pivot", datum)[0]
    assert np.allclose(full, dense, rtol=1e-7, atol=1e-9 * np.abs(dense).max())
    Qpp = po.covariance(PTS[None], th[None], "pivot", datum)[0][0]
    assert np.allclose(Qpp[3], full[6:8, 6:8], rtol=1e-12)


def test_result_accessors_match_module_covariance():
    T = 3
    rng = np.random.default_rng(2)
    r = ml.simulate_ranges(batch(PTS, T), batch(THETA, T), rng, setting_sigma_um=1.0, settings=1)
    t0 = THETA.copy()
    t0[5:] = 0.0
    res = ml.adjust(r, "pivot", t0)
    Qpp, Qgg = ml.covariance(res.points, res.theta, "pivot")[:2]
    assert np.allclose(res.point_cofactors(), Qpp, rtol=1e-12)
    assert np.allclose(res.global_cofactor(), Qgg, rtol=1e-12)
    full = res.full_point_cofactor()
    assert np.allclose(full[:, 2:4, 2:4], Qpp[:, 1], rtol=1e-12)


def test_screened_rule_decides_like_the_eigenvalue_ratio():
    """The bordered solve screens the scaled rule with a norm bound: its decisions equal
    ``scaled_rcond > rcond`` on matrices from well conditioned to singular, and its inverse
    is the plain inverse."""
    from sim.lsq import normals

    rng = np.random.default_rng(5)
    T, m = 400, 6
    Q, _ = np.linalg.qr(rng.normal(size=(T, m, m)))
    ev = np.ones((T, m))
    ev[:, 0] = 10.0 ** rng.uniform(-14, 0, T) * rng.choice([-1.0, 1.0], T)  # indefinite too
    M = np.einsum("tij,tj,tkj->tik", Q, ev, Q)
    M[0, 0, 0] = np.nan
    for rc in (1e-10, 1e-6):
        Minv, ok = normals._screened_inverse(M, rc)
        ref = normals.scaled_rcond(M) > rc
        assert np.array_equal(ok, ref) and 0 < ref.sum() < T
        np.testing.assert_array_equal(Minv[ok], np.linalg.inv(M[ok]))


def test_block2_rcond_is_the_scaled_rule_of_2x2_blocks():
    """The scalar rule the compiled kernels apply to 2 x 2 blocks (normals.block2_rcond)
    equals scaled_rcond bit for bit, singular, NaN, infinite and zero blocks included."""
    from sim.lsq import normals

    rng = np.random.default_rng(0)
    N = rng.normal(size=(300, 2, 2))
    N = N @ N.transpose(0, 2, 1)
    N[3] = [[1.0, 1.0], [1.0, 1.0]]  # singular
    N[5, 0, 1] = np.nan
    N[7] = [[1e-30, 0.0], [0.0, 1.0]]  # regular once scaled
    N[8] = 0.0
    N[9, 0, 0] = np.inf
    N[10] = [[1.0, 1.0], [1.0, 1.0 + 1e-12]]  # below rcond
    N[11] = [[-2.0, 0.5], [0.5, 3.0]]  # indefinite
    with np.errstate(invalid="ignore"):
        rc = np.array([normals.block2_rcond(m[0, 0], m[0, 1], m[1, 0], m[1, 1]) for m in N])
    np.testing.assert_array_equal(rc, normals.scaled_rcond(N))
    assert list(np.flatnonzero(~(rc > normals.RCOND))) == [3, 5, 8, 9, 10]
