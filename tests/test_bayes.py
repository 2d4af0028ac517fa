"""emcee cross-check: a linear-Gaussian posterior, and Brown's marginal posterior."""

import numpy as np

from sim.instruments.plates import grid_points
from sim.instruments.ranges import bayes
from sim.instruments.ranges import multilateration as ml


def test_emcee_posterior_of_a_linear_gaussian_model_matches_the_analytic_one():
    rng = np.random.default_rng(42)
    A = np.column_stack([np.ones(12), np.linspace(-1, 1, 12), np.linspace(-1, 1, 12) ** 2])
    x_true = np.array([0.3, -1.2, 0.7])
    sigma = 0.2
    y = A @ x_true + rng.normal(0, sigma, 12)
    cov = sigma**2 * np.linalg.inv(A.T @ A)
    mean = np.linalg.solve(A.T @ A, A.T @ y)
    p0 = rng.multivariate_normal(mean, cov, size=24)
    ch = bayes.run_emcee(
        bayes.linear_log_posterior(A, y, sigma), p0, 4000, np.random.SeedSequence(7)
    )
    assert ch.n_eff > 1000
    sd = np.sqrt(np.diag(cov))
    # mean within 5 standard errors (N_eff independent samples)
    assert np.all(np.abs(ch.samples.mean(0) - mean) < 5 * sd / np.sqrt(ch.n_eff))
    # standard deviations within 5 standard errors of a sample std
    ratio = ch.samples.std(0, ddof=1) / sd
    assert np.all(np.abs(ratio - 1) < 5 / np.sqrt(2 * ch.n_eff))
    corr = cov / np.outer(sd, sd)
    assert np.abs(np.corrcoef(ch.samples.T) - corr).max() < 5 / np.sqrt(ch.n_eff)
    # the same seed gives the same chain
    ch2 = bayes.run_emcee(
        bayes.linear_log_posterior(A, y, sigma), p0, 200, np.random.SeedSequence(7)
    )
    ch3 = bayes.run_emcee(
        bayes.linear_log_posterior(A, y, sigma), p0, 200, np.random.SeedSequence(7)
    )
    assert np.array_equal(ch2.samples, ch3.samples)


def test_brown_marginal_posterior_is_the_least_squares_gaussian():
    """Near the LS estimate the Laplace-marginal log posterior is the quadratic form of the
    least-squares covariance of the globals (the points profiled out exactly)."""
    pts = grid_points(5, 45.0)
    th = ml.design_theta(152.5, 0.5, 1.0)
    rng = np.random.default_rng(9)
    sig = 1.5e-3
    r = ml.ranges(pts[None], th[None])[0] + rng.normal(0, sig, (25, 4))
    t0 = th.copy()
    t0[5:] = 0.0
    ls = ml.adjust(r[None], "pivot", t0, tol_mm=1e-12)
    Q = ml.covariance(ls.points, ls.theta, "pivot")[1][0] * sig**2
    lp = bayes.brown_log_posterior(r, sig, tol_mm=1e-12)
    d = rng.multivariate_normal(np.zeros(7), Q, size=40)
    vals = lp(ls.theta + d) - lp(ls.theta)[0]
    quad = -0.5 * np.einsum("wi,ij,wj->w", d, np.linalg.inv(Q), d)
    assert np.all(np.abs(vals - quad) < 0.05 + 0.02 * np.abs(quad))


def test_vectorised_sampler_is_emcee_step_for_step():
    """sim.instruments.ranges.ensemble runs emcee's stretch move: the same seed gives emcee's chain, acceptance
    and autocorrelation times exactly (a posterior with -inf regions and a skewed one)."""
    rng = np.random.default_rng(3)
    A = np.column_stack([np.ones(10), np.linspace(-1, 1, 10)])
    y = A @ np.array([0.5, 2.0]) + rng.normal(0, 0.1, 10)
    base = bayes.linear_log_posterior(A, y, 0.1)

    def lp(x):
        out = base(x) - 3.0 * x[:, 1] ** 4
        return np.where(x[:, 0] > 0.45, out, -np.inf)

    p0 = np.array([0.5, 2.0]) + rng.normal(0, 0.02, (10, 2))
    p0[:, 0] = np.abs(p0[:, 0] - 0.5) + 0.46
    seed = np.random.SeedSequence(11)
    a = bayes.run_emcee(lp, p0, 300, seed)
    b = bayes.run_emcee(lp, p0, 300, seed, engine="emcee")
    assert np.array_equal(a.samples, b.samples)
    assert np.array_equal(a.tau, b.tau) and a.acceptance == b.acceptance
    assert 0.05 < a.acceptance < 0.95
