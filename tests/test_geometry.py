"""sim.geometry: the one rotation convention and the one similarity fit (2-D and 3-D)."""
import numpy as np
import pytest

from sim import geometry as geo
from sim import transforms2d as t2


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
        np.testing.assert_allclose(R[i], _axis(0, o[i]) @ _axis(1, p[i]) @ _axis(2, k[i]),
                                   atol=1e-15)
    np.testing.assert_allclose(R @ np.swapaxes(R, 1, 2), np.broadcast_to(np.eye(3), R.shape),
                               atol=1e-14)
    np.testing.assert_allclose(np.linalg.det(R), 1.0, atol=1e-14)
    np.testing.assert_allclose(np.stack(geo.rotation_angles(R)), np.stack([o, p, k]), atol=1e-12)
    # counter-clockwise about +z: the x axis goes to +y
    np.testing.assert_allclose(geo.rotation(0, 0, np.pi / 2) @ [1, 0, 0], [0, 1, 0], atol=1e-15)


def test_one_rotation_in_the_library():
    from sim import encoders, independent_models
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
        R = np.stack([np.stack([np.cos(a), -np.sin(a)], -1), np.stack([np.sin(a), np.cos(a)], -1)], -2)
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
        dst3[:, 4] += 50.0                                  # an outlier, weighted out
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
    src[1] = src[1, :1]                                    # trial 1: all points coincide
    dst = 1.5 * src + 10.0
    f = geo.similarity_fit(src, dst)
    assert list(f.status) == [0, 2, 0]
    assert np.isnan(f.scale[1]) and np.allclose(f.scale[[0, 2]], 1.5)
