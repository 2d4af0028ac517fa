"""The one linear least-squares routine (sim.lsq.linear): per-trial status, shared design,
weights, cofactors, against a per-trial SciPy solve."""

import numpy as np
import pytest
from scipy import linalg

from sim.lsq.linear import LINEAR_STATUS, lstsq


def _batch(rng, T=6, m=15, p=4, k=2):
    A = rng.normal(size=(T, m, p))
    b = rng.normal(size=(T, m, k))
    return A, b


def _reference(A, b, w=None):
    """Per-trial SciPy least squares of the weighted system."""
    out = []
    for t in range(A.shape[0]):
        sw = np.ones(A.shape[1]) if w is None else np.sqrt(np.broadcast_to(w, A.shape[:2])[t])
        out.append(linalg.lstsq(A[t] * sw[:, None], b[t] * sw[:, None])[0])
    return np.array(out)


def test_per_trial_equals_scipy_and_cofactor_is_inverse_normals():
    rng = np.random.default_rng(1)
    A, b = _batch(rng)
    f = lstsq(A, b)
    np.testing.assert_allclose(f.x, _reference(A, b), rtol=1e-12, atol=1e-13)
    Q = f.cofactor()
    np.testing.assert_allclose(Q, np.linalg.inv(np.swapaxes(A, 1, 2) @ A), rtol=1e-11)
    np.testing.assert_allclose(f.residuals, b - A @ f.x, atol=1e-13)
    assert f.dof == 11 and f.ok.all() and not f.shared
    np.testing.assert_allclose(f.s0, np.sqrt((f.residuals**2).sum((1, 2)) / (2 * 11)))


def test_singular_trial_is_flagged_not_raised_and_others_are_untouched():
    rng = np.random.default_rng(2)
    A, b = _batch(rng)
    A[2, :, 3] = 2.0 * A[2, :, 1]  # rank deficient: two proportional columns
    b[4, 7, 0] = np.nan  # a non-finite observation
    f = lstsq(A, b)
    assert list(f.status) == [0, 0, 2, 0, 3, 0]
    assert f.message[2] == LINEAR_STATUS[2] and f.message[4] == LINEAR_STATUS[3]
    assert np.isnan(f.x[[2, 4]]).all() and np.isnan(f.cofactor()[[2, 4]]).all()
    good = [0, 1, 3, 5]
    np.testing.assert_allclose(f.x[good], _reference(A[good], b[good]), rtol=1e-12, atol=1e-13)


def test_too_few_observations_and_singular_shared_design_are_flagged():
    rng = np.random.default_rng(3)
    f = lstsq(rng.normal(size=(3, 2, 4)), rng.normal(size=(3, 2)))
    assert (f.status == 2).all() and np.isnan(f.x).all()
    A = rng.normal(size=(10, 3))
    A[:, 2] = A[:, 0]
    g = lstsq(A, rng.normal(size=(5, 10)))
    assert g.shared and (g.status == 2).all() and np.isnan(g.x).all()


def test_shared_design_equals_per_trial_path():
    rng = np.random.default_rng(4)
    A = rng.normal(size=(20, 3))  # the studies' size: no compile of its own on a cold cache
    b = rng.normal(size=(50, 20, 2))
    w = rng.uniform(0.5, 2.0, 20)
    for ww in (None, w):
        s = lstsq(A, b, ww)
        p = lstsq(
            np.broadcast_to(A, (50, 20, 3)).copy(),
            b,
            None if ww is None else np.broadcast_to(ww, (50, 20)).copy(),
        )
        assert s.shared and not p.shared
        np.testing.assert_allclose(s.x, p.x, rtol=1e-12, atol=1e-14)
        np.testing.assert_allclose(s.cofactor(), p.cofactor(), rtol=1e-11, atol=1e-15)
        np.testing.assert_allclose(s.vtpv, p.vtpv, rtol=1e-10)
    np.testing.assert_allclose(
        s.x, _reference(np.broadcast_to(A, (50, 20, 3)), b, w), rtol=1e-12, atol=1e-14
    )


def test_weights_scale_the_observations_and_zero_weight_drops_one():
    rng = np.random.default_rng(5)
    A, b = _batch(rng, T=4, m=12, p=3, k=1)
    w = rng.uniform(0.2, 5.0, (4, 12))
    f = lstsq(A, b, w)
    np.testing.assert_allclose(f.x, _reference(A, b, w), rtol=1e-12, atol=1e-13)
    np.testing.assert_allclose(
        f.cofactor(), np.linalg.inv(np.einsum("tmi,tm,tmj->tij", A, w, A)), rtol=1e-11
    )
    np.testing.assert_allclose(f.vtpv[:, 0], (w * f.residuals[..., 0] ** 2).sum(1), rtol=1e-12)
    w0 = np.ones((4, 12))
    w0[:, 5] = 0.0
    keep = np.arange(12) != 5
    np.testing.assert_allclose(lstsq(A, b, w0).x, lstsq(A[:, keep], b[:, keep]).x, rtol=1e-11)


@pytest.mark.parametrize("spread", [1e-6, 0.3, 3.0])
def test_designs_far_from_the_trial_mean_stay_exact(spread):
    """The preconditioner is the trial-mean design: trials that differ from it a lot fall
    back to column equilibration and are still the least-squares solution."""
    rng = np.random.default_rng(6)
    A0 = rng.normal(size=(30, 6))
    A = A0 + spread * rng.normal(size=(8, 30, 6))
    A[3] *= 1e3  # a badly scaled trial
    b = rng.normal(size=(8, 30))
    f = lstsq(A, b)
    np.testing.assert_allclose(f.x, _reference(A, b[..., None]), rtol=1e-10, atol=1e-13)


def test_bad_shapes_raise_value_error():
    with pytest.raises(ValueError):
        lstsq(np.ones((4, 3)), np.ones((2, 5)))
    with pytest.raises(ValueError):
        lstsq(np.ones((4, 2)), np.ones((2, 4)), w=np.ones(3))


def test_screened_rule_decides_like_the_eigenvalue_ratio():
    """Per-trial designs from well conditioned to rank deficient: the screened rule of the
    per-trial path decides like ``scaled_rcond(A'A) > rcond`` and solves like a plain inverse."""
    from sim.lsq.normals import scaled_rcond

    rng = np.random.default_rng(11)
    T, m = 300, 12
    x = rng.uniform(-1, 1, (T, m))
    eps = 10.0 ** rng.uniform(-13, 0, T)  # near-collinear third column
    A = np.stack([np.ones((T, m)), x, x + eps[:, None] * rng.normal(size=(T, m))], -1)
    b = rng.normal(size=(T, m))
    for rc in (1e-10, 1e-6):
        f = lstsq(A, b, rcond=rc)
        ref = scaled_rcond(np.swapaxes(A, 1, 2) @ A) > rc
        assert np.array_equal(f.ok, ref) and 0 < ref.sum() < T
        good = ref & (eps > 1e-3)
        xr = np.linalg.lstsq(A[good][0], b[good][0], rcond=None)[0]
        np.testing.assert_allclose(f.x[good][0, :, 0], xr, rtol=1e-9, atol=1e-12)


def test_inputs_are_left_unchanged():
    """The residuals never overwrite the caller's observations (one trial of a shared design,
    whose transposed right-hand sides are a view of ``b``)."""
    rng = np.random.default_rng(7)
    for A, b in (
        (rng.normal(size=(9, 3)), rng.normal(size=(1, 9, 2))),
        (rng.normal(size=(9, 3)), rng.normal(size=(4, 9, 2))),
        (rng.normal(size=(4, 9, 3)), rng.normal(size=(4, 9, 1))),
    ):
        A0, b0 = A.copy(), b.copy()
        f = lstsq(A, b)
        assert np.array_equal(A, A0) and np.array_equal(b, b0)
        np.testing.assert_allclose(f.residuals, b - np.matmul(A, f.x), atol=1e-13)
