"""Worked example: a new observation model added to the engine without touching it.

Model: 2-D distances from ``n`` unknown points to ``B`` known beacons, read on an instrument
with an unknown scale ``s`` (one global); ``d_kj = s |x_j - b_k| + e``, ``e ~ N(0, sigma^2)``,
mm. Everything the engine needs is the class below: misclosures and Jacobians over a
leading trial axis and a start for the points. The Monte-Carlo spread of the estimates must
match the engine's analytic covariance ``sigma^2 Q`` within the sampling error.
"""

import numpy as np

from sim import lsq

BEACONS = np.array([[0.0, 0.0], [100.0, 0.0], [100.0, 80.0], [0.0, 80.0]])
POINTS = np.array([[30.0, 20.0], [70.0, 50.0], [45.0, 65.0]])
SCALE = 1.0005
SIGMA = 0.01  # mm


class ScaledDistances:
    """Distances to known beacons with an unknown scale: points (x, y), global ``s``."""

    point_dim = 2
    n_global = 1

    def __init__(self, d_obs, beacons):
        self.d_obs, self.b = d_obs, beacons  # (T, n, B), (B, 2)

    def initial_points(self, theta):  # beacons' centroid
        T, n, _ = self.d_obs.shape
        return np.broadcast_to(self.b.mean(0), (T, n, 2)).copy()

    def linearize(self, points, theta, globals_needed=True):
        diff = points[:, :, None, :] - self.b[None, None]  # (T, n, B, 2)
        rho = np.linalg.norm(diff, axis=-1)
        s = theta[:, None, None, 0]
        r = self.d_obs - s * rho
        Jp = s[..., None] * diff / rho[..., None]
        Jg = rho[..., None] if globals_needed else None
        return lsq.Linearization(r, Jp, Jg)


def test_new_model_monte_carlo_matches_analytic_covariance():
    T = 4000
    rng = np.random.default_rng(2024)
    rho = np.linalg.norm(POINTS[:, None, :] - BEACONS[None], axis=-1)
    d = SCALE * rho[None] + rng.normal(0.0, SIGMA, (T,) + rho.shape)
    res = lsq.gauss_newton(ScaledDistances(d, BEACONS), np.ones((T, 1)))
    assert res.converged.all()
    assert res.dof == 3 * 4 - (2 * 3 + 1)
    # estimates of point 0 (x, y) and the scale, and their analytic covariance at the truth
    est = np.column_stack([res.points[:, 0], res.theta[:, 0]])
    truth = np.r_[POINTS[0], SCALE]
    cof = lsq.cofactors(ScaledDistances(d[:1], BEACONS), POINTS[None], np.array([[SCALE]]))
    full = np.zeros((3, 3))
    full[:2, :2] = cof.points[0, 0]
    full[:2, 2] = full[2, :2] = cof.point_global[0, 0, :, 0]
    full[2, 2] = cof.Qgg[0, 0, 0]
    C = SIGMA**2 * full
    se = np.sqrt(np.diag(C) / T)
    assert np.all(np.abs(est.mean(0) - truth) < 4 * se)  # no bias beyond MC error
    emp = np.cov(est.T)
    # variances: relative standard error sqrt(2 / (T - 1)) of a sample variance
    assert np.all(np.abs(np.diag(emp) / np.diag(C) - 1) < 4 * np.sqrt(2 / (T - 1)))
    # correlations: standard error (1 - rho^2) / sqrt(T)
    sd_e, sd_a = np.sqrt(np.diag(emp)), np.sqrt(np.diag(C))
    r_e, r_a = emp / np.outer(sd_e, sd_e), C / np.outer(sd_a, sd_a)
    assert np.all(np.abs(r_e - r_a) < 4 * (1 - r_a**2) / np.sqrt(T) + 1e-12)
    # sigma0^2 estimates sigma^2 (linearised model: E[s0^2] = sigma^2)
    assert abs((res.sigma0**2).mean() / SIGMA**2 - 1) < 4 * np.sqrt(2 / (res.dof * T))
