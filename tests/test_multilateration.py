"""Brown's multilateration: analytic covariance, solver, invariances, Monte Carlo."""

import numpy as np
import pytest

from sim.claims.intervals import std_rel_se
from sim.instruments.plates import grid_points
from sim.instruments.ranges import multilateration as ml

H = 122.5 + 45.0
PTS = grid_points(5, 55.0)
THETA = ml.design_theta(H, 0.5, 1.0)


def batch(a, T):
    return np.broadcast_to(a, (T,) + a.shape).copy()


def sigmas(pts, theta, model):
    Q = ml.covariance(pts[None], theta[None], model)[0][0]
    return np.sqrt(np.stack([Q[:, 0, 0], Q[:, 1, 1]], 1))


def test_known_centre_is_sigma_over_root2():
    s = sigmas(np.array([[0.0, 0.0], [50.0, 20.0], [-30.0, 70.0]]), ml.design_theta(H), "known")
    assert s[0] == pytest.approx([2**-0.5, 2**-0.5], abs=1e-12)
    # four unit vectors: trace(N) = 4, so the pooled sigma is >= 1/sqrt(2), equal only at
    # the centre where N is isotropic
    assert np.all(np.sqrt((s[1:] ** 2).mean(1)) > 2**-0.5 + 1e-6)


@pytest.mark.parametrize("model", list(ml.MODELS))
def test_noise_free_ranges_recover_truth(model):
    T = 8
    P = batch(PTS, T)
    r = ml.ranges(P, batch(THETA, T))
    t0 = THETA.copy()
    p = ml.MODELS[model]
    t0[: min(p, 5)] += np.array([2.0, -1.5, 0.8, 1.2, -2.0])[: min(p, 5)]  # a poor start
    t0[5:p] = 0.0
    res = ml.adjust(r, model, t0, tol_mm=1e-12)
    assert res.converged.all()
    assert np.abs(res.points - P).max() < 1e-9
    assert np.abs(res.theta - THETA).max() < 1e-9
    assert np.abs(res.residuals).max() < 1e-9


def _cov_full(pts, theta, model):
    """Full 2n x 2n cofactor of the points from the reduced pieces."""
    Qpp, Qgg, K, Ninv = ml.covariance(pts[None], theta[None], model)
    n = len(pts)
    full = np.einsum("iap,pq,jbq->iajb", K[0], Qgg[0], K[0]).reshape(2 * n, 2 * n)
    for j in range(n):
        full[2 * j : 2 * j + 2, 2 * j : 2 * j + 2] += Ninv[0, j]
    return full


@pytest.mark.parametrize("model", list(ml.MODELS))
def test_reduced_normals_equal_dense_inverse(model):
    """Schur-complement covariance equals the inverse of the dense normal matrix."""
    P = PTS[None]
    lin = ml._model(None).linearize(P, THETA[None], True)
    Jp, Jg = lin.Jp, lin.Jg[..., : ml.MODELS[model]]
    n = len(PTS)
    A = np.zeros((4 * n, 2 * n + ml.MODELS[model]))
    for j in range(n):
        A[4 * j : 4 * j + 4, 2 * j : 2 * j + 2] = Jp[0, j]
        if Jg is not None:
            A[4 * j : 4 * j + 4, 2 * n :] = Jg[0, j]
    dense = np.linalg.inv(A.T @ A)[: 2 * n, : 2 * n]
    assert np.allclose(_cov_full(PTS, THETA, model), dense, rtol=1e-8, atol=1e-10)


THETA0 = ml.design_theta(H, 0.5, 0.0)  # beta = 0: ranges are plain distances


def _known_cov(pts, S):
    return ml.covariance(pts[None], THETA0[None], "known", station_xy=S[None])[0][0]


def test_translation_leaves_sigmas_unchanged():
    S = ml.stations(THETA0[None])[0]
    shift = np.array([13.7, -41.2])
    assert np.allclose(_known_cov(PTS, S), _known_cov(PTS + shift, S + shift), atol=1e-13)
    assert not np.allclose(_known_cov(PTS, S), _known_cov(PTS + shift, S), atol=1e-3)


@pytest.mark.parametrize("deg", [17.0, 90.0, 233.0])
def test_rotation_rotates_each_point_covariance(deg):
    ang = np.deg2rad(deg)
    R = np.array([[np.cos(ang), -np.sin(ang)], [np.sin(ang), np.cos(ang)]])
    S = ml.stations(THETA0[None])[0]
    Q1 = _known_cov(PTS, S)
    Q2 = _known_cov(PTS @ R.T, S @ R.T)
    assert np.allclose(np.einsum("ij,njk,lk->nil", R, Q1, R), Q2, atol=1e-12)
    assert np.allclose(np.trace(Q1, axis1=1, axis2=2), np.trace(Q2, axis1=1, axis2=2))


@pytest.mark.parametrize("model", ["known", "stations", "pivot"])
def test_monte_carlo_matches_analytic(model):
    T = 3000
    rng = np.random.default_rng(20261122)
    P = batch(PTS, T)
    TH = batch(THETA, T)
    r = ml.simulate_ranges(P, TH, rng, setting_sigma_um=1.0, settings=1)
    t0 = THETA.copy()
    t0[5 : ml.MODELS[model]] = 0.0
    res = ml.adjust(r, model, t0)
    assert res.converged.all()
    mc = (res.points - P).std(axis=0, ddof=1) * 1e3
    an = sigmas(PTS, THETA, model)
    ratio = mc / an
    # each of the 50 ratios within 4.5 standard errors of a sample std (no false alarm at
    # this seed; a 10 % covariance error would fail many of them)
    se = std_rel_se(T)
    assert np.all(np.abs(ratio - 1) < 4.5 * se)
    # the pooled ratio is much tighter
    assert abs(np.sqrt(np.mean(ratio**2)) - 1) < 4 * se / np.sqrt(10)
    # a-posteriori sigma0 is unbiased for the range sigma (dof = 4n - unknowns)
    s0 = res.sigma0 * 1e3
    assert abs(np.mean(s0**2) - 1) < 4 * np.sqrt(2 / res.dof / T)


def test_constant_bias_is_absorbed_by_alpha():
    T = 50
    rng = np.random.default_rng(7)
    P = batch(PTS, T)
    r = ml.simulate_ranges(P, batch(THETA, T), rng, setting_sigma_um=1.0, settings=1)
    t0 = THETA.copy()
    t0[5:] = 0.0
    a = ml.adjust(r, "pivot", t0, tol_mm=1e-12)
    c = 0.0374  # mm
    b = ml.adjust(r + c, "pivot", t0, tol_mm=1e-12)
    assert np.abs(a.points - b.points).max() < 1e-9
    assert np.allclose(b.theta[:, 5] - a.theta[:, 5], -c, atol=1e-9)
    assert np.allclose(a.sigma0, b.sigma0, rtol=1e-6)
    # without alpha, the same constant biases the coordinates
    k = ml.adjust(r, "stations", THETA)
    kb = ml.adjust(r + c, "stations", THETA)
    assert np.abs(k.points - kb.points).max() > 1e-3


def test_beta_near_zero_is_estimable_as_beta_squared():
    T = 200
    th = ml.design_theta(H, 0.5, 0.0)  # beta = 0: d r / d beta would vanish
    rng = np.random.default_rng(11)
    P = batch(PTS, T)
    r = ml.simulate_ranges(P, batch(th, T), rng, setting_sigma_um=1.0, settings=1)
    t0 = th.copy()
    t0[5:] = 0.0
    res = ml.adjust(r, "pivot", t0)
    assert res.converged.all()
    # b = beta^2 scatters around zero (both signs): an unbiased estimate, no singularity
    b = res.theta[:, 6]
    assert (b < 0).any() and (b > 0).any()
    Qgg = ml.covariance(P[:1], batch(th, 1), "pivot")[1][0]
    assert abs(b.mean()) < 4 * np.sqrt(Qgg[6, 6]) * 1e-3 / np.sqrt(T)


def test_singular_geometry_is_flagged_not_raised():
    T = 3
    pts = np.stack([np.linspace(-50, 50, 6), np.zeros(6)], 1)  # collinear points
    P = batch(pts, T)
    r = ml.ranges(P, batch(THETA, T))
    res = ml.adjust(r, "pivot", THETA)
    assert not res.converged.any()
    assert set(res.status.tolist()) <= {2, 3}


def test_bad_arguments_rejected():
    with pytest.raises(ValueError, match="model"):
        ml.adjust(np.zeros((1, 5, 4)), "bogus", THETA)
    with pytest.raises(ValueError, match="shape"):
        ml.adjust(np.zeros((1, 5, 3)), "known", THETA)
    with pytest.raises(ValueError, match="unknowns"):
        ml.adjust(np.ones((1, 3, 4)) * 150, "pivot", THETA)


@pytest.mark.skipif(not ml.jit.available(), reason="numba not installed")
def test_compiled_engine_flags_singular_geometry():
    pts = np.stack([np.linspace(-50, 50, 6), np.zeros(6)], 1)
    r = ml.ranges(batch(pts, 3), batch(THETA, 3))
    res = ml.adjust(r, "pivot", THETA, engine="numba")
    assert not res.converged.any() and set(res.status.tolist()) <= {2, 3}


@pytest.mark.skipif(not ml.jit.available(), reason="numba not installed")
def test_simd_lanes_are_bit_identical_to_one_trial_at_a_time():
    """The SIMD kernel adjusts blocks of LANES trials in lock-step: every trial's result must
    be bit-identical to adjusting it alone, wherever it sits in a block (full blocks, a
    padded last block), and a trial that fails (NaN, absurd range) must not disturb the
    other lanes of its block."""
    T = 2 * ml.jit.LANES + 7
    assert ml.jit.use_lanes(T, len(PTS)) and not ml.jit.use_lanes(1, len(PTS))
    rng = np.random.default_rng(9)
    r = ml.simulate_ranges(batch(PTS, T), batch(THETA, T), rng, setting_sigma_um=2.0, settings=1)
    r[3, 2, 1] = np.nan
    r[T - 2, 0, 0] = 1e300
    t0 = THETA.copy()
    t0[5:] = 0.0
    block = ml.adjust(r, "pivot", t0, engine="numba")
    assert block.status[3] != 0 and block.status[T - 2] != 0
    ok = np.ones(T, bool)
    ok[[3, T - 2]] = False
    assert block.converged[ok].all()
    for t in (0, 3, ml.jit.LANES - 1, ml.jit.LANES, T - 2, T - 1):
        one = ml.adjust(r[t : t + 1], "pivot", t0, engine="numba")
        for f in ("points", "theta", "residuals", "sigma0", "iterations", "status"):
            assert np.array_equal(getattr(one, f)[0], getattr(block, f)[t], equal_nan=True), (t, f)
