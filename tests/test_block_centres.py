"""Projection centres as model points (``sim.instruments.block.centres``), the option of the
independent-model block that SPACE-M carries: the merged block's structure, the centres'
model coordinates against the models' own frames, and what the tie does to heights."""

from __future__ import annotations

import numpy as np
import pytest

from sim.instruments.block import independent_models as im
from sim.instruments.block.centres import centre_models, with_centres
from sim.instruments.block.layout import make_block, select_control


@pytest.fixture(scope="module")
def small():
    """A 2 x 3 block with 40 signalised points."""
    return make_block(2, 3, n_ground=40, pass_rows=3)


def test_centres_are_points_shared_by_consecutive_models(small):
    cb = with_centres(small)
    b = cb.block
    S, M = small.strips, small.models
    n_photo = S * (M + 1)
    assert b.n_points == small.n_points + n_photo and b.n_ground == small.n_ground
    assert b.obs_model.size == small.obs_model.size + 2 * S * M
    assert np.all(np.diff(b.obs_model) >= 0)  # sorted by model, as the block's own
    seen = np.bincount(
        b.obs_point[b.obs_point >= small.n_points] - small.n_points, minlength=n_photo
    )
    ends = np.zeros((S, M + 1), bool)
    ends[:, [0, -1]] = True
    assert np.array_equal(seen, np.where(ends.ravel(), 1, 2))  # inner photos tie two models
    assert np.allclose(b.points[small.n_points :], small.photos.reshape(-1, 3))
    # the merge keeps the block's own observations in their order
    xm = np.arange(small.obs_model.size * 3, dtype=float).reshape(1, -1, 3)
    xc = -np.ones((1, 2 * S * M, 3))
    merged = cb.merge(xm, xc)
    own = b.obs_point < small.n_points
    assert np.array_equal(merged[0, own], xm[0]) and np.all(merged[0, ~own] == -1)


def test_noise_free_centres_fit_the_models_exactly(small):
    """Error-free models with their error-free centres, adjusted on five control points:
    every residual vanishes and every point and centre comes back (so the centres' model
    coordinates are in the same frames as the model points)."""
    rng = np.random.default_rng(3)
    T = 2
    xm, (s, R, t) = im.noisy_models(small, rng, T)
    cb = with_centres(small)
    x = cb.merge(xm, centre_models(cb, rng, s, R, t))
    b = cb.block
    ctrl = select_control(small, "five")
    st = im.BlockStructure(b.obs_model, b.obs_point, ctrl, b.n_models, b.n_points)
    X0 = b.points + rng.normal(0, 2.0, (T,) + b.points.shape)
    s0, R0, t0 = im.initial_values(st, x, X0)
    res = im.adjust_block(
        st,
        x,
        np.ones(3),
        np.broadcast_to(small.points[ctrl], (T, 5, 3)),
        np.full((5, 3), 10.0),
        s0,
        R0,
        t0,
        X0,
        tol_m=1e-9,
    )
    assert res.converged.all()
    assert np.abs(res.v_obs).max() < 1e-6
    assert np.allclose(res.X, b.points, atol=1e-6)


def test_centres_stiffen_heights_between_sparse_control():
    """A 1 x 6 strip with control at its two ends only: model points with 0.1 m errors. The
    centres (same error, same weight) tie consecutive models, so the height error between the
    controls falls; the error of the planimetry changes far less. Fixed seed, 60 blocks: the
    rms height error without the centres is several times that with them (the ratio's
    sampling error over 60 blocks is a few per cent)."""
    b = make_block(1, 6, n_ground=40, pass_rows=3)
    rng = np.random.default_rng(5)
    T = 60
    xm, (s, R, t) = im.noisy_models(b, rng, T, 0.1)
    cb = with_centres(b)
    xc = centre_models(cb, rng, s, R, t, 0.1)
    ctrl = select_control(b, "corners")
    check = np.setdiff1d(np.arange(b.n_ground), ctrl)
    err = {}
    for name, blk, x in (("without", b, xm), ("with", cb.block, cb.merge(xm, xc))):
        st = im.BlockStructure(blk.obs_model, blk.obs_point, ctrl, blk.n_models, blk.n_points)
        X0 = blk.points + rng.normal(0, 1.0, (T,) + blk.points.shape)
        s0, R0, t0 = im.initial_values(st, x, X0)
        res = im.adjust_block(
            st, x, np.ones(3), np.broadcast_to(b.points[ctrl], (T, 4, 3)),
            np.full((4, 3), 100.0), s0, R0, t0, X0,
        )  # fmt: skip
        assert res.converged.all()
        e = res.X[:, check] - b.points[check]
        err[name] = np.sqrt(np.mean(e**2, axis=(0, 1)))
    assert err["without"][2] > 2.0 * err["with"][2]
    assert (
        err["with"][2] < err["without"][2]
        and err["with"][:2].max() <= 1.2 * err["without"][:2].max()
    )
