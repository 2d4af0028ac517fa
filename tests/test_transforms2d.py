"""2-D transformations: published decompositions, exact recovery, covariance vs Monte Carlo."""

import numpy as np
import pytest

from sim.instruments import transforms2d as t2
from sim.instruments.plates import grid_points

FIG2 = np.array(
    [0.999929623, 0.011191034, -117.846539270, -0.011258985, 0.999916040, -116.507525374]
)
FIG3 = np.array(
    [12.700044103, 0.027714040, -2625.077266139, -0.031355021, 12.701997895, -5081.092972783]
)
# each of A, B, D, E is rounded to 9 decimals: the scales can move by ~|A|+|D| times 0.5e-9
RND = 0.5e-9 * 1.02


def test_salsig_fig3_to_printed_digits():
    d = t2.decompose_columns(FIG3)
    assert abs(d["SX"] - 12.700082809) <= 0.5e-9 + RND
    assert abs(d["SY"] - 12.702028129) <= 0.5e-9 + RND
    assert abs(d["E"] / t2.ARCSEC - (-59.2)) <= 0.05


def test_salsig_fig2_to_printed_digits():
    d = t2.decompose_columns(FIG2)
    assert abs(d["SX"] - 0.999993007) <= 0.5e-9 + RND
    assert abs(d["E"] / t2.ARCSEC - (-14.0)) <= 0.05
    # SY agrees to 8 decimals only: the printed B and E give .999978663, not .999978669
    assert abs(d["SY"] - 0.999978669) < 1e-8
    assert 5e-9 < abs(d["SY"] - 0.999978669) < 7e-9


def test_sign_of_D_is_negative():
    flipped = FIG3 * np.array([1, 1, 1, -1, 1, 1])
    assert abs(t2.decompose_columns(flipped)["E"] / t2.ARCSEC) > 900


@pytest.mark.parametrize("fit, n_par", [(t2.fit_affine, 6), (t2.fit_similarity, 4)])
def test_noise_free_recovered_exactly(fit, n_par):
    rng = np.random.default_rng(3)
    G = grid_points(5, 40.0)
    if n_par == 6:
        p = np.column_stack(
            [
                1 + rng.normal(0, 1e-3, 7),
                rng.normal(0, 0.01, 7),
                rng.normal(0, 50, 7),
                rng.normal(0, 0.01, 7),
                1 + rng.normal(0, 1e-3, 7),
                rng.normal(0, 50, 7),
            ]
        )
        dst = t2.apply_affine(p, G)
    else:
        p = np.column_stack(
            [
                1 + rng.normal(0, 1e-3, 7),
                rng.normal(0, 0.01, 7),
                rng.normal(0, 50, 7),
                rng.normal(0, 50, 7),
            ]
        )
        dst = t2.apply_similarity(p, G)
    f = fit(G, dst)
    np.testing.assert_allclose(f.params, p, rtol=0, atol=1e-10)
    assert np.all(f.s0 < 1e-10)


def test_decompositions_round_trip():
    e = np.array([-59.2, 3.0, 120.0]) * t2.ARCSEC
    p = t2.affine_from_columns([12.7, 1.0, 0.5], [12.702, 1.00002, 0.4999], e, [0.1, -0.3, 2.0])
    d = t2.decompose_columns(p)
    np.testing.assert_allclose(d["SX"], [12.7, 1.0, 0.5], rtol=1e-14)
    np.testing.assert_allclose(d["E"], e, atol=1e-14)
    q = t2.affine_from_rows([1.0, 0.99998], [1.00001, 1.0], e[:2], [0.01, -1.0])
    r = t2.decompose_rows(q)
    np.testing.assert_allclose(r["S2"], [1.00001, 1.0], rtol=1e-14)
    np.testing.assert_allclose(r["eps"], e[:2], atol=1e-14)


def test_row_and_column_conventions_agree_up_to_sign():
    """eps (rows, grid -> instrument) = -E (columns, instrument -> grid); S = SX cos E."""
    inv = t2.invert_affine(FIG3)
    r, c = t2.decompose_rows(inv), t2.decompose_columns(FIG3)
    assert abs(r["eps"] + c["E"]) < 1e-12
    assert abs(r["S"] - c["SX"] * np.cos(c["E"])) < 1e-12
    assert abs(r["S2"] - c["SY"] * np.cos(c["E"])) < 1e-12


def test_affine_covariance_matches_monte_carlo():
    """MC sd of SX, SY, E against the propagated a-posteriori covariance (rms), within
    4 / sqrt(2 (N - 1)) of the sampling error of an sd."""
    rng = np.random.default_rng(11)
    T = 3000
    G = grid_points(5, 50.0)
    p = t2.affine_from_columns(12.7, 12.702, -59.2 * t2.ARCSEC, 0.01)
    sig = 0.002
    dst = t2.apply_affine(np.broadcast_to(p, (T, 6)), G) + rng.normal(0, sig, (T, 25, 2))
    f = t2.fit_affine(G, dst)
    d = t2.decompose_columns(f.params, f.cov)
    tol = 4 / np.sqrt(2 * (T - 1))
    for i, k in enumerate(("SX", "SY", "E")):
        mc = np.std(d[k], ddof=1)
        stated = np.sqrt(np.mean(d["cov"][:, i, i]))
        assert abs(mc / stated - 1) < tol, k
    # s0 unbiased for sigma^2
    assert abs(np.mean(f.s0**2) / sig**2 - 1) < 4 * np.sqrt(2 / f.dof / T)


def test_inverse_decomposition_matches_direct():
    rng = np.random.default_rng(5)
    G = grid_points(5, 50.0)
    p = t2.affine_from_columns(12.7, 12.702, -59.2 * t2.ARCSEC, 0.01)
    x2 = t2.apply_affine(t2.invert_affine(p), G[None] + rng.normal(0, 0.02, (400, 25, 2)))
    f = t2.fit_affine(G, x2)  # residuals on X2, as Salsig's program
    d = t2.inverse_decomposition(f.params, f.cov)
    g = t2.fit_affine(x2, np.broadcast_to(G, x2.shape))  # residuals on X1
    e = t2.decompose_columns(g.params, g.cov)
    # the two directions agree to second order: their stated sds differ by the relative noise
    # (0.02 mm on a 100 mm grid, 2e-4) times a factor of order one; 5x that is the bound
    assert np.max(np.abs(d["E"] - e["E"])) < 0.05 * np.sqrt(np.mean(e["cov"][:, 2, 2]))
    rel = 0.02 / 100.0
    np.testing.assert_allclose(np.sqrt(d["cov"][:, 2, 2]), np.sqrt(e["cov"][:, 2, 2]), rtol=5 * rel)
