"""sim.lsq.distributions equals scipy.stats (which it replaces to save a second of import per
process), and sim.claims.intervals keeps the coverage of its intervals."""

import numpy as np
import pytest
from scipy import stats

from sim.claims.intervals import sd_interval, std_ci
from sim.lsq import distributions as D


@pytest.mark.parametrize("df", [1, 2, 3, 7.5, 49, 400])
def test_quantiles_and_tails_equal_scipy_stats(df):
    q = np.linspace(0.0005, 0.9995, 401)
    np.testing.assert_allclose(D.chi2_ppf(q, df), stats.chi2.ppf(q, df), rtol=1e-13)
    np.testing.assert_allclose(D.t_ppf(q, df), stats.t.ppf(q, df), rtol=1e-13, atol=1e-15)
    np.testing.assert_allclose(D.f_ppf(q, 2, df), stats.f.ppf(q, 2, df), rtol=1e-13)
    x = np.linspace(0, 4 * df, 97)
    np.testing.assert_allclose(D.chi2_cdf(x, df), stats.chi2.cdf(x, df), rtol=1e-13, atol=1e-300)
    np.testing.assert_allclose(D.chi2_sf(x, df), stats.chi2.sf(x, df), rtol=1e-13, atol=1e-300)
    np.testing.assert_allclose(D.norm_ppf(q), stats.norm.ppf(q), rtol=1e-13)
    z = np.linspace(-6, 6, 121)
    np.testing.assert_allclose(D.norm_pdf(z), stats.norm.pdf(z), rtol=1e-13)
    np.testing.assert_allclose(D.norm_cdf(z), stats.norm.cdf(z), rtol=1e-13)


def test_probabilities_outside_the_unit_interval_are_nan():
    assert np.isnan(D.chi2_ppf(1.5, 3)) and np.isnan(D.norm_ppf(-0.1)) and np.isnan(D.t_ppf(2, 4))


@pytest.mark.parametrize("n", [1, 7, 60, 1000])
@pytest.mark.parametrize("p", [0.01, 0.05, 0.5, 0.95])
def test_binomial_quantile_and_wilson_interval_equal_scipy_stats(n, p):
    for q in (0.001, 0.025, 0.5, 0.975, 0.999):
        assert D.binom_ppf(q, n, p) == int(stats.binom.ppf(q, n, p))
    k = int(round(p * n))
    ref = stats.binomtest(k, n).proportion_ci(0.95, "wilson")
    np.testing.assert_allclose(D.wilson_ci(k, n), (ref.low, ref.high), rtol=1e-12, atol=1e-15)


def test_standard_deviation_interval_covers_at_its_level():
    """Of 4000 Gaussian samples of 12, the 95 % chi-square interval of sigma misses the true
    sigma about 200 times: within 4.5 binomial standard errors."""
    rng = np.random.default_rng(11)
    x = 2.0 * rng.standard_normal((12, 4000))
    s, lo, hi = std_ci(x, 0.95, axis=0)
    miss = np.count_nonzero((lo > 2.0) | (hi < 2.0))
    assert abs(miss - 200) < 4.5 * np.sqrt(4000 * 0.05 * 0.95), miss
    np.testing.assert_allclose(sd_interval(float(s[0]), 12), (lo[0], hi[0]), rtol=1e-14)
