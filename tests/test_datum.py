"""P-position multilateration and the datum: S-transformations are datum-invariant."""

import numpy as np
import pytest

from sim import lsq
from sim.claims.intervals import std_rel_se
from sim.instruments.plates import grid_points
from sim.instruments.ranges import multilateration as ml
from sim.instruments.ranges import positions as po
from sim.lsq import datum as dm

H = 122.5 + 45.0
PTS = grid_points(5, 55.0)


def batch(a, T):
    return np.broadcast_to(a, (T,) + a.shape).copy()


@pytest.mark.parametrize("model", ["known", "stations", "pivot"])
def test_four_positions_in_browns_datum_equal_multilateration(model):
    th7 = ml.design_theta(H, 0.5, 1.0)
    th = po.from_brown_theta(th7)
    assert np.allclose(th, po.design_theta(4, H, 0.5, 1.0), atol=1e-12)
    Q1 = ml.covariance(PTS[None], th7[None], model)[0]
    Q2 = po.covariance(PTS[None], th[None], model, "brown")[0]
    assert np.allclose(Q1, Q2, rtol=1e-9, atol=1e-13)
    rng = np.random.default_rng(3)
    r = ml.ranges(batch(PTS, 20), batch(th7, 20)) + rng.normal(0, 1e-3, (20, 25, 4))
    t7 = th7.copy()
    t7[5 : ml.MODELS[model]] = 0.0
    a = ml.adjust(r, model, t7)
    b = po.adjust(r, model, po.from_brown_theta(t7), "brown")
    assert a.converged.all() and b.converged.all()
    assert np.abs(a.points - b.points).max() < 1e-8
    assert a.dof == b.dof


@pytest.mark.parametrize("model", ["stations", "pivot"])
@pytest.mark.parametrize("target", ["inner", "corners"])
def test_s_transformed_covariance_is_the_same_from_any_datum(model, target):
    th = po.design_theta(4, H, 0.5, 1.0)[None]
    Fb = po.full_point_covariance(PTS[None], th, model, "brown")[0]
    Fi = po.full_point_covariance(PTS[None], th, model, "inner")[0]
    assert np.abs(Fb - Fi).max() > 1e-2  # the datums really differ ...
    S = dm.inner(PTS) if target == "inner" else dm.similarity_onto(PTS, dm.corner_indices(PTS))
    assert np.allclose(S @ Fb @ S.T, S @ Fi @ S.T, atol=1e-12)  # ... the S-transform does not
    # minimum trace of the inner-constraint datum
    Si = dm.inner(PTS)
    assert np.trace(Si @ Fb @ Si.T) < np.trace(Fb)
    assert np.trace(Si @ Fi @ Si.T) <= np.trace(Fi) + 1e-12


def test_s_transformed_errors_are_identical_per_trial_whatever_the_datum():
    th = po.design_theta(4, H, 0.5, 1.0)
    T = 30
    rng = np.random.default_rng(5)
    r = po.ranges(batch(PTS, T), batch(th, T)) + rng.normal(0, 1e-3, (T, 25, 4))
    t0 = th.copy()
    t0[-2:] = 0.0
    a = po.adjust(r, "pivot", t0, "brown")
    b = po.adjust(r, "pivot", t0, "inner")
    assert a.converged.all() and b.converged.all()
    S = dm.inner(PTS)
    ea = (a.points - PTS).reshape(T, -1) @ S.T
    eb = (b.points - PTS).reshape(T, -1) @ S.T
    assert np.abs(a.points - b.points).max() > 1e-4
    # equal to first order: the datums differ by a finite rotation of ~1e-5 rad, whose
    # second-order effect (angle^2 x 100 mm) is ~1e-8 mm against errors of ~1e-3 mm
    assert np.abs(ea - eb).max() < 1e-7
    assert np.allclose(a.sigma0, b.sigma0, rtol=1e-8)


def test_s_matrix_projects_out_the_similarity():
    Hs = dm.null_basis(PTS, scale=True)
    S = dm.similarity_onto(PTS, dm.corner_indices(PTS))
    assert np.allclose(S @ Hs, 0, atol=1e-12)
    assert np.allclose(S @ S, S, atol=1e-12)
    assert sorted(dm.corner_indices(PTS).tolist()) == [0, 4, 20, 24]


@pytest.mark.parametrize("P", [3, 6, 8])
def test_p_positions_noise_free_recovery(P):
    th = po.design_theta(P, 190.0, 0.3, 2.0)
    T = 4
    r = po.ranges(batch(PTS, T), batch(th, T))
    t0 = th.copy()
    t0[-2:] = 0.0
    t0[: 2 * P] += np.tile([0.8, -0.5], P)  # a poor start (in the inner datum's frame)
    res = po.adjust(r, "pivot", t0, "inner")
    assert res.converged.all()
    assert np.abs(res.residuals).max() < 1e-9
    # the recovered network equals the truth up to a rigid motion: the S-transform removes it
    S = dm.inner(PTS)
    e = (res.points - PTS).reshape(T, -1) @ S.T
    assert np.abs(e).max() < 1e-8


@pytest.mark.parametrize("P", [3, 6])
def test_p_positions_monte_carlo_matches_analytic(P):
    th = po.design_theta(P, 180.0, 0.5, 1.0)
    T = 1500
    rng = np.random.default_rng(100 + P)
    r = po.ranges(batch(PTS, T), batch(th, T)) + rng.normal(0, 1e-3, (T, 25, P))
    t0 = th.copy()
    t0[-2:] = 0.0
    res = po.adjust(r, "pivot", t0, "inner")
    assert res.converged.all()
    S = dm.inner(PTS)
    e = (res.points - PTS).reshape(T, -1) @ S.T * 1e3
    an = np.sqrt(
        np.diag(S @ po.full_point_covariance(PTS[None], th[None], "pivot", "inner")[0] @ S.T)
    )
    ratio = e.std(0, ddof=1) / an
    assert np.all(np.abs(ratio - 1) < 4.5 * std_rel_se(T))
    assert abs(np.mean(res.sigma0**2) * 1e6 - 1) < 4 * np.sqrt(2 / res.dof / T)


def test_brown_datum_needs_four_stations():
    with pytest.raises(ValueError, match="4 stations"):
        po.covariance(PTS[None], po.design_theta(6, H)[None], "stations", "brown")


def test_result_in_datum_and_coverage_use_the_engine_result():
    from sim.instruments.ranges import coverage as cv

    T = 400
    rng = np.random.default_rng(21)
    pts = grid_points(4, 60.0)
    th = po.design_theta(4, 167.5, 0.5, 1.0)
    P = np.broadcast_to(pts, (T,) + pts.shape)
    r = po.ranges(P, np.broadcast_to(th, (T, len(th)))) + rng.normal(0, 1e-3, (T, len(pts), 4))
    res = po.adjust(r, "known", np.broadcast_to(th, (T, len(th))))
    S = dm.inner(pts)
    F = dm.result_in_datum(res, S)
    ref = dm.s_transform(po.full_point_covariance(res.points, res.theta, "known"), S)
    assert np.allclose(F, ref, rtol=1e-12, atol=1e-15)
    inside = cv.result_inside(res, pts, sigma=1e-3).mean()
    assert abs(inside - 0.95) < 4 * np.sqrt(0.95 * 0.05 / (T * len(pts)))  # points independent


@pytest.mark.parametrize("P, brown", [(3, False), (4, False), (6, False), (4, True)])
def test_sparse_reduced_normals_equal_the_dense_jacobians(P, brown):
    """RangeModel's own reduced normals (the sparse NumPy blocks) are the engine's
    reduction of the dense Jacobian to 1e-12 relative, for any free set, with and without
    readings; the adjustment gives the same solution and status."""
    from sim.instruments.ranges import multilateration as ml
    from sim.lsq import normals as nm

    rng = np.random.default_rng(P)
    T = 6
    th = po.design_theta(P, 160.0, 0.5, 1.0)
    TH = np.broadcast_to(th, (T, th.size)).copy()
    pts = PTS[None] + rng.normal(0, 1e-3, (T,) + PTS.shape)
    r = po.ranges(pts, TH) + rng.normal(0, 1e-3, (T, len(PTS), P))
    layout = ml.BROWN_LAYOUT if brown else None
    if brown:
        TH = np.broadcast_to(ml.design_theta(160.0, 0.5, 1.0), (T, 7)).copy()
    for robs in (r, None):
        m = po.RangeModel(robs, layout, P=P)
        q = m.n_global
        for free in (np.arange(q), np.arange(0), np.arange(q - 2), np.array([0, 2, 3])):
            lin = m.linearize(pts, TH, True)
            ref = nm.reduce(lin.r, lin.Jp, lin.Jg[..., free] if len(free) else None)
            for red in (
                m.reduced(pts, TH, free),
                nm.reduce_blocks(*m.normal_blocks(pts, TH, free)),
            ):
                assert np.array_equal(red.ok, ref.ok)
                for f in ("Ninv", "K", "Nbar", "ubar", "dp0"):
                    a, b = getattr(red, f), getattr(ref, f)
                    assert a.shape == b.shape
                    scale = max(np.abs(b).max(initial=0.0), 1e-3 if robs is None else 0.0)
                    assert np.abs(a - b).max(initial=0.0) <= 1e-12 * scale, f
    if not brown:
        t0 = th.copy()
        t0[-2:] = 0.0
        a = po.adjust(r, "pivot", t0, "inner")
        b = lsq.gauss_newton(
            po.RangeModel(r, dense=True),
            np.broadcast_to(t0, TH.shape),
            None,
            po._datum(TH, P, "pivot", "inner"),
            engine="numpy",
        )
        assert np.array_equal(a.status, b.status)
        assert np.abs(a.points - b.points).max() < 1e-11
