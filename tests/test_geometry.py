"""sim.instruments.geometry: the one rotation convention and the one similarity fit (2-D and 3-D)."""

import numpy as np
import pytest

from sim.instruments import geometry as geo
from sim.instruments import transforms2d as t2


def _axis(axis, a):
    c, s = np.cos(a), np.sin(a)
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    R = np.eye(3)
    R[i, i], R[i, j], R[j, i], R[j, j] = c, -s, s, c
    return R


def test_rotation_convention_is_rx_ry_rz_and_round_trips():
    rng = np.random.default_rng(1)
    o, p, k = rng.uniform(-3, 3, 20), rng.uniform(-1.5, 1.5, 20), rng.uniform(-3, 3, 20)
    R = geo.rotation(o, p, k)
    for i in range(20):
        np.testing.assert_allclose(
            R[i], _axis(0, o[i]) @ _axis(1, p[i]) @ _axis(2, k[i]), atol=1e-15
        )
    np.testing.assert_allclose(
        R @ np.swapaxes(R, 1, 2), np.broadcast_to(np.eye(3), R.shape), atol=1e-14
    )
    np.testing.assert_allclose(np.linalg.det(R), 1.0, atol=1e-14)
    np.testing.assert_allclose(np.stack(geo.rotation_angles(R)), np.stack([o, p, k]), atol=1e-12)
    # counter-clockwise about +z: the x axis goes to +y
    np.testing.assert_allclose(geo.rotation(0, 0, np.pi / 2) @ [1, 0, 0], [0, 1, 0], atol=1e-15)


def test_one_rotation_in_the_library():
    from sim.instruments import encoders
    from sim.instruments.block import independent_models

    assert encoders.rotation_matrix is geo.rotation
    assert getattr(independent_models, "rotation", geo.rotation) is geo.rotation


@pytest.mark.parametrize("d", [2, 3])
def test_similarity_recovers_known_parameters(d):
    rng = np.random.default_rng(2)
    T, n = 7, 9
    src = rng.uniform(-100, 100, (T, n, d))
    s = rng.uniform(0.5, 2.0, T)
    if d == 3:
        R = geo.rotation(rng.normal(0, 0.3, T), rng.normal(0, 0.3, T), rng.uniform(-3, 3, T))
    else:
        a = rng.uniform(-3, 3, T)
        R = np.stack(
            [np.stack([np.cos(a), -np.sin(a)], -1), np.stack([np.sin(a), np.cos(a)], -1)], -2
        )
    t = rng.normal(0, 1e3, (T, d))
    dst = geo.similarity_apply(s, R, t, src)
    f = geo.similarity_fit(src, dst)
    assert f.ok.all() and f.dof == (2 * n - 4 if d == 2 else 3 * n - 7)
    np.testing.assert_allclose(f.scale, s, rtol=1e-12)
    np.testing.assert_allclose(f.R, R, atol=1e-12)
    np.testing.assert_allclose(f.t, t, atol=1e-9)
    assert np.abs(f.residuals).max() < 1e-9
    np.testing.assert_allclose(f.apply(src), dst, atol=1e-9)


def test_similarity_2d_is_the_linear_fit_and_weights_drop_points():
    rng = np.random.default_rng(3)
    src = rng.uniform(-100, 100, (4, 10, 2))
    dst = 1.001 * src[..., ::-1] + rng.normal(0, 0.05, src.shape)
    f = geo.similarity_fit(src, dst)
    g = t2.fit_similarity(src, dst)
    a, b = g.params[:, 0], g.params[:, 1]
    np.testing.assert_allclose(f.scale, np.hypot(a, b), rtol=1e-14)
    np.testing.assert_allclose(f.residuals, g.residuals, atol=1e-12)
    for d in (2, 3):
        src3 = rng.uniform(-100, 100, (4, 10, d))
        dst3 = 2.0 * src3 + rng.normal(0, 0.05, src3.shape)
        dst3[:, 4] += 50.0  # an outlier, weighted out
        w = np.ones(10)
        w[4] = 0.0
        keep = np.arange(10) != 4
        fw, fk = geo.similarity_fit(src3, dst3, w), geo.similarity_fit(src3[:, keep], dst3[:, keep])
        np.testing.assert_allclose(fw.scale, fk.scale, rtol=1e-11)
        np.testing.assert_allclose(fw.R, fk.R, atol=1e-11)
        np.testing.assert_allclose(fw.t, fk.t, atol=1e-9)


@pytest.mark.parametrize("d", [2, 3])
def test_degenerate_similarity_is_flagged_not_raised(d):
    rng = np.random.default_rng(4)
    src = rng.uniform(-100, 100, (3, 6, d))
    src[1] = src[1, :1]  # trial 1: all points coincide
    dst = 1.5 * src + 10.0
    f = geo.similarity_fit(src, dst)
    assert list(f.status) == [0, 2, 0]
    assert np.isnan(f.scale[1]) and np.allclose(f.scale[[0, 2]], 1.5)


@pytest.mark.parametrize("shared", [False, True])
def test_closed_form_similarity_2d_is_the_linear_fit_of_a_b_c(shared):
    """The 2-D closed form equals the engine's linear fit of ``(a, b, c, c')`` on the explicit
    design: solution, residuals, s0, cofactor, and the scaled rule's decisions (a trial of
    coincident points, a nearly coincident one and a NaN observation among good trials)."""
    from sim.lsq.linear import lstsq

    rng = np.random.default_rng(8)
    T, n = 8, 12
    src = (
        rng.uniform(-100, 100, (n, 2)) + 40.0
        if shared
        else rng.uniform(-100, 100, (T, n, 2)) + 40.0
    )
    th = rng.normal(0, 0.01, T)
    R = np.stack(
        [np.stack([np.cos(th), -np.sin(th)], -1), np.stack([np.sin(th), np.cos(th)], -1)], -2
    )
    dst = 1.001 * np.einsum("tij,tnj->tni", R, np.broadcast_to(src, (T, n, 2))) + 3.0
    dst = dst + rng.normal(0, 0.01, dst.shape)
    if not shared:
        src[2] = src[2, :1]  # coincident: singular
        src[5] = src[5, :1] + 1e-7 * rng.normal(size=(n, 2))  # nearly: eigenvalue ratio ~1e-18
    dst[4, 3, 1] = np.nan
    w = rng.uniform(0.5, 2.0, n)
    for ww in (None, w):
        f = geo.similarity_fit(src, dst, ww)
        S = np.broadcast_to(src, (T, n, 2))
        x, y, one, zero = S[..., 0], S[..., 1], np.ones((T, n)), np.zeros((T, n))
        A = np.concatenate([np.stack([x, y, one, zero], -1), np.stack([y, -x, zero, one], -1)], 1)
        ref = lstsq(
            A,
            np.concatenate([dst[..., 0], dst[..., 1]], 1),
            None if ww is None else np.concatenate([ww, ww]),
        )
        assert np.array_equal(f.status, ref.status)
        ok = ref.ok
        assert ok.sum() == (T - 1 if shared else T - 3)
        np.testing.assert_allclose(f.linear.x[ok], ref.x[ok], rtol=1e-11, atol=1e-11)
        np.testing.assert_allclose(f.linear.residuals[ok], ref.residuals[ok], atol=1e-10)
        np.testing.assert_allclose(f.s0[ok], ref.s0[ok], rtol=1e-9)
        np.testing.assert_allclose(
            f.linear.cofactor()[ok], ref.cofactor()[ok], rtol=1e-10, atol=1e-16
        )
        assert np.isnan(f.scale[~ok]).all() and np.isnan(f.linear.cofactor()[~ok]).all()
