"""The compiled paths of the linear case (sim.lsq.linear_kernel, sim.instruments.plotter.polynomial_kernel) against
the NumPy paths they replace: equal to a tolerance derived from each design's condition
number, the same per-trial status (singular, non-finite), and the scaled rule's bound."""

import numpy as np
import pytest

from sim.instruments.plotter import polynomial as pl
from sim.instruments.plotter import polynomial_kernel
from sim.lsq import compile, linear_kernel
from sim.lsq.linear import lstsq
from sim.lsq.normals import RCOND, scaled_rcond

pytestmark = pytest.mark.skipif(not compile.available(), reason="numba not installed")
EPS = np.finfo(float).eps


def _wolf_batch(T=40, seed=11):
    """Wolf's 66-point grid (three sets, mm) measured with a smooth error and 2 um noise."""
    rng = np.random.default_rng(seed)
    xs, ys = np.arange(-100.0, 100.1, 20.0), np.arange(-40.0, 60.1, 20.0)
    yy, xx = np.meshgrid(ys, xs, indexing="ij")
    g = np.tile(np.column_stack([xx.ravel(), yy.ravel()]), (3, 1))
    field = 3e-3 * np.stack([np.sin(g[:, 0] / 80.0), np.cos(g[:, 1] / 70.0)], -1)
    return g, g + field + rng.normal(0.0, 2e-3, (T,) + g.shape)


def test_shared_design_compiled_equals_numpy_path(monkeypatch):
    rng = np.random.default_rng(3)
    T, m, p, k = 50, 40, 3, 2  # the studies' size: no compile of its own on a cold cache
    A = rng.normal(size=(m, p)) * np.array([1.0, 10.0, 0.1])
    b = rng.normal(size=(T, m, k))
    w = rng.uniform(0.2, 3.0, m)
    b[7, 3, 1] = np.nan
    fits = [lstsq(A, b, w)]
    monkeypatch.setenv("SIM_NO_JIT", "1")
    fits.append(lstsq(A, b, w))
    c, n = fits
    cond = np.linalg.cond(A * np.sqrt(w)[:, None])
    tol = 10 * cond * EPS  # backward-stable solves, relative
    np.testing.assert_array_equal(c.status, n.status)
    assert c.status[7] == 3 and np.isnan(c.x[7]).all() and np.isnan(c.vtpv[7]).all()
    ok = c.ok
    scale = np.abs(n.x[ok]).max()
    assert np.abs(c.x[ok] - n.x[ok]).max() <= tol * scale
    np.testing.assert_allclose(c.vtpv[ok], n.vtpv[ok], rtol=tol)
    np.testing.assert_allclose(
        c.residuals[ok], n.residuals[ok], rtol=0, atol=tol * np.abs(b[ok]).max()
    )
    assert np.isnan(c.residuals[7]).all()
    np.testing.assert_allclose(c.cofactor()[ok], n.cofactor()[ok], rtol=1e-13)


def test_polynomial_compiled_equals_numpy_path_within_its_condition():
    g, meas = _wolf_batch()
    meas[5, 10, 0] = np.inf  # a non-finite trial
    meas[9] = np.column_stack([meas[9, :, 0], 0.3 * meas[9, :, 0]])  # points on one line
    # the two term counts Wolf's study fits (10 and 3): no compile of their own on a cold cache
    for terms, corrected in ((pl.WOLF_TERMS, True), (pl.poly_terms(1), False)):
        c = pl.fit_poly(meas, g, terms=terms, corrected=corrected)
        n = pl.fit_poly(meas, g, terms=terms, corrected=corrected, jit=False)
        np.testing.assert_array_equal(c.ok, n.ok)
        assert not c.ok[5] and not c.ok[9] and c.ok.sum() == len(meas) - 2
        assert np.isnan(c.coef[5]).all() and np.isnan(c.coef[9]).all()
        A = pl.design(meas[c.ok], terms)
        cond = np.linalg.cond(A)  # per trial; normal equations square it
        tol = 20 * cond**2 * EPS * np.abs(n.coef[c.ok]).max(axis=(1, 2))
        assert (np.abs(c.coef[c.ok] - n.coef[c.ok]).max(axis=(1, 2)) <= tol).all()
        # |d rms| <= ||A dx|| / sqrt(n) <= sigma_max(A) sqrt(p) |dx|_max / sqrt(n); the
        # corrected points move by |A dx| <= (row sum of |A|) |dx|_max; plus their rounding
        n_pts, p = A.shape[1], A.shape[2]
        smax = np.linalg.norm(A, 2, axis=(1, 2))
        drms = smax * np.sqrt(p) * tol / np.sqrt(n_pts) + 8 * EPS * n.rms_mm[c.ok].max(1)
        assert (np.abs(c.rms_mm[c.ok] - n.rms_mm[c.ok]).max(1) <= drms).all()
        if corrected:
            dcor = np.abs(A).sum(2).max(1) * tol + 4 * EPS * np.abs(meas[c.ok]).max((1, 2))
            assert (np.abs(c.corrected_mm[c.ok] - n.corrected_mm[c.ok]).max((1, 2)) <= dcor).all()


def test_polynomial_trials_do_not_depend_on_their_neighbours():
    """A trial's fit is the same alone as in a batch with a singular and a non-finite trial
    (the lanes of the compiled solve are independent)."""
    g, meas = _wolf_batch(T=11)
    meas[2, :, 1] = 5.0  # all Y equal: singular
    meas[4, 0, 1] = np.nan
    batch = pl.fit_wolf(meas, g)
    for t in (0, 3, 10):
        alone = pl.fit_wolf(meas[t : t + 1], g)
        np.testing.assert_array_equal(alone.coef[0], batch.coef[t])
        np.testing.assert_array_equal(alone.rms_mm[0], batch.rms_mm[t])
    assert list(np.flatnonzero(~batch.ok)) == [2, 4]


def test_normal_solve_proves_regular_or_leaves_to_the_exact_rule():
    rng = np.random.default_rng(5)
    p, T = 7, 12
    Q = np.linalg.qr(rng.normal(size=(T, p, p)))[0]
    ev = np.tile(np.geomspace(1.0, 1e-3, p), (T, 1))
    ev[3, -1] = 1e-12  # below rcond: singular by the rule
    d = rng.uniform(0.1, 100.0, (T, p))  # the rule is invariant to this scaling
    C = np.einsum("tij,tj,tkj->tik", Q, ev, Q)
    N = C * d[:, :, None] * d[:, None, :]
    u = rng.normal(size=(T, p, 2))
    x, st = linear_kernel.normal_solve(N, u, RCOND)
    solved = st == linear_kernel.SOLVED
    rc = scaled_rcond(N)
    assert (rc[solved] > RCOND).all()  # the bound never passes a singular trial
    assert not solved[3] and solved.sum() == T - 1  # the rest are proved regular
    assert np.isnan(x[~solved]).all()
    ref = np.linalg.solve(N[solved], u[solved])
    cond = 1.0 / rc[solved]
    err = np.abs(x[solved] - ref).max(axis=(1, 2)) / np.abs(ref).max(axis=(1, 2))
    assert (err <= 10 * cond * EPS).all()


def test_polynomial_undecided_trials_get_the_exact_rule(monkeypatch):
    """A trial the kernel's bound cannot prove regular is left undecided by the kernel and
    fitted by lstsq (the exact rule): a nearly collinear set of points, regular by the rule
    but beyond the bound, gets the NumPy path's status and coefficients."""
    g, meas = _wolf_batch(T=9)
    meas[6, :, 1] = 0.3 * meas[6, :, 0] + 1e-3 * np.sin(meas[6, :, 0])  # nearly one line
    _, st, _, _ = polynomial_kernel.fit(meas, g, pl.WOLF_TERMS, 100.0, False, RCOND)
    assert st[6] == polynomial_kernel.UNDECIDED and (np.delete(st, 6) == 0).all()
    c = pl.fit_wolf(meas, g)
    monkeypatch.setenv("SIM_NO_JIT", "1")
    n = pl.fit_wolf(meas, g)
    np.testing.assert_array_equal(c.ok, n.ok)
    np.testing.assert_array_equal(c.coef[6], n.coef[6])
    np.testing.assert_array_equal(c.rms_mm[6], n.rms_mm[6])
