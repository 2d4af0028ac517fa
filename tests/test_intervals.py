"""Every interval method against an exact reference and by its coverage (issue 28).

Exact references: ``scipy.stats`` quantiles and closed forms (Student t, chi-square, Wilson,
order statistics). Coverage: a seeded simulation of ``R`` replications whose coverage ``c`` is
compared with the nominal 0.95 within ``K = 4`` binomial standard errors
``sqrt(0.95 * 0.05 / R)``; ``R`` is chosen so that the same bound excludes 0.90 (a 95 % interval
that is really 90 % fails), i.e. ``0.05 > 2 K se``. A bound of 4 standard errors fails by chance
with probability 6e-5 per test; the seeds are fixed, so a test is either right or wrong.
"""

import math

import numpy as np
import pytest
from scipy import special, stats

from sim.claims import intervals as iv
from sim.claims.book_region import sample_evidence
from sim.mc.config import StudyError
from sim.mc.runner import MIN_CHUNKS, jackknife

K = 4.0  # standard errors of a coverage estimate that the bound allows


def coverage_bound(R: int, k: float = K, nominal: float = 0.95) -> float:
    """Half-width ``k se`` of the accepted coverage band, and a check that it tells 95 % from
    90 % (the band around 0.95 and the one around 0.90 do not meet)."""
    se = math.sqrt(nominal * (1 - nominal) / R)
    assert 2 * k * se < 0.05, "R too small to tell a 95 % interval from a 90 % one"
    return k * se


# --------------------------------------------------------------------------- mean (t)
def test_mean_ci_is_the_student_t_interval():
    x = np.random.default_rng(1).normal(3.0, 2.0, 12)
    m, (lo, hi) = iv.mean_ci(x)
    elo, ehi = stats.t.interval(0.95, x.size - 1, loc=x.mean(), scale=stats.sem(x))
    assert m == pytest.approx(x.mean(), rel=1e-14)
    assert (lo, hi) == pytest.approx((elo, ehi), rel=1e-12)
    _, (lo9, hi9) = iv.mean_ci(x, 0.90)
    assert (lo9, hi9) == pytest.approx(
        stats.t.interval(0.90, x.size - 1, loc=x.mean(), scale=stats.sem(x)), rel=1e-12
    )


def test_mean_ci_coverage_is_95_percent():
    R, n, mu = 4000, 8, 1.5
    x = np.random.default_rng(2).normal(mu, 0.7, (R, n))
    hit = [lo <= mu <= hi for lo, hi in (iv.mean_ci(row)[1] for row in x)]
    assert abs(np.mean(hit) - 0.95) < coverage_bound(R)


def test_mean_ci_needs_two_values_and_a_level_inside_0_1():
    with pytest.raises(ValueError, match="^a mean's interval needs at least 2 values$"):
        iv.mean_ci(np.array([1.0]))
    m, (lo, hi) = iv.mean_ci([1, 3])  # two integers are enough
    assert m == 2.0 and (lo, hi) == pytest.approx((2 - 12.7062047361747, 2 + 12.7062047361747))
    for level in (0.0, 1.0, 1.5):
        with pytest.raises(ValueError, match=rf"^level must lie in \(0, 1\), not {level}$"):
            iv.mean_ci(np.arange(5.0), level)


# --------------------------------------------------------------------------- sd (chi-square)
def test_std_ci_is_the_chi_square_interval():
    x = np.random.default_rng(3).normal(0.0, 5.0, (9, 3))
    s, lo, hi = iv.std_ci(x)
    n = x.shape[0]
    sd = x.std(axis=0, ddof=1)
    assert s == pytest.approx(sd, rel=1e-14)
    assert lo == pytest.approx(sd * np.sqrt((n - 1) / stats.chi2.ppf(0.975, n - 1)), rel=1e-12)
    assert hi == pytest.approx(sd * np.sqrt((n - 1) / stats.chi2.ppf(0.025, n - 1)), rel=1e-12)
    # along another axis, and the scalar form from s and n
    s1, lo1, hi1 = iv.std_ci(x.T, axis=1)
    assert np.allclose([s1, lo1, hi1], [s, lo, hi], rtol=1e-14)
    assert iv.sd_interval(float(sd[0]), n) == pytest.approx((lo[0], hi[0]), rel=1e-14)
    assert iv.sd_interval(2.0, 30, 0.9) == pytest.approx(
        (
            2.0 * math.sqrt(29 / stats.chi2.ppf(0.95, 29)),
            2.0 * math.sqrt(29 / stats.chi2.ppf(0.05, 29)),
        ),
        rel=1e-12,
    )


def test_std_ci_coverage_is_95_percent():
    R, n, sigma = 4000, 10, 2.5
    x = np.random.default_rng(4).normal(0.0, sigma, (n, R))
    _, lo, hi = iv.std_ci(x)
    assert abs(np.mean((lo <= sigma) & (sigma <= hi)) - 0.95) < coverage_bound(R)


@pytest.mark.filterwarnings("ignore::RuntimeWarning")
def test_std_ci_needs_two_values():
    msg = "^a standard deviation's interval needs at least 2 values$"
    with pytest.raises(ValueError, match=msg):
        iv.std_ci(np.ones((1, 3)))
    with pytest.raises(ValueError, match=msg):
        iv.sd_interval(1.0, 1)
    s, lo, hi = iv.std_ci([0, 2])  # two integers are enough: chi2(1) quantiles
    assert s == pytest.approx(math.sqrt(2))
    assert (lo, hi) == pytest.approx(
        (math.sqrt(2 / stats.chi2.ppf(0.975, 1)), math.sqrt(2 / stats.chi2.ppf(0.025, 1)))
    )
    assert iv.sd_interval(1.0, 2) == pytest.approx((lo / s, hi / s))


def test_std_rel_se_is_the_large_sample_se_of_s():
    # exact: sd(s)/sigma = sqrt(1 - c4^2), c4 = sqrt(2/(n-1)) G(n/2)/G((n-1)/2); the
    # approximation 1/sqrt(2(n-1)) is off by O(1/n)
    for n in (50, 200, 1000):
        c4 = math.sqrt(2 / (n - 1)) * math.exp(
            special.gammaln(n / 2) - special.gammaln((n - 1) / 2)
        )
        assert iv.std_rel_se(n) == pytest.approx(math.sqrt(1 - c4**2), rel=1.0 / n)
    assert iv.std_rel_se(51) == 0.1


# --------------------------------------------------------------------------- proportions
@pytest.mark.parametrize("k,n", [(0, 20), (1, 20), (7, 20), (20, 20), (3, 1000), (500, 1000)])
def test_binomial_ci_is_scipy_wilson(k, n):
    p, lo, hi = iv.binomial_ci(k, n)
    ci = stats.binomtest(k, n).proportion_ci(0.95, "wilson")
    assert p == k / n
    assert (lo, hi) == pytest.approx((ci.low, ci.high), rel=1e-12, abs=1e-15)
    assert 0.0 <= lo <= p <= hi <= 1.0
    ci9 = stats.binomtest(k, n).proportion_ci(0.90, "wilson")
    assert iv.binomial_ci(k, n, 0.90)[1:] == pytest.approx(
        (ci9.low, ci9.high), rel=1e-12, abs=1e-15
    )


def test_binomial_ci_broadcasts_and_stays_inside_0_1():
    k = np.array([0, 5, 10])
    p, lo, hi = iv.binomial_ci(k, 10)
    assert p.shape == lo.shape == hi.shape == (3,)
    assert lo[0] == 0.0 and hi[2] == 1.0 and np.all((lo >= 0) & (hi <= 1))
    assert np.all(lo < p) == False  # noqa: E712 - k = 0 has lo = p = 0
    for bad in ((-1, 5), (6, 5), (0, 0)):
        with pytest.raises(ValueError, match="^a proportion needs counts 0 <= k <= n and n >= 1$"):
            iv.binomial_ci(*bad)
    assert iv.binomial_ci(1, 1)[1:] == pytest.approx((1 / (1 + 1.959963984540054**2), 1.0))
    # rounding carries Wilson's upper bound at k = n = 16 to 1 + 2e-16: clipped to 1
    assert iv.binomial_ci(16, 16)[2] == 1.0 and iv.binomial_ci([0, 16], 16)[2][1] == 1.0


@pytest.mark.parametrize("n,p", [(100, 0.05), (200, 0.5), (400, 0.95), (1000, 0.05)])
def test_binomial_ci_exact_coverage_is_near_95_percent(n, p):
    # exact coverage: sum of the binomial pmf over the k whose interval holds p
    k = np.arange(n + 1)
    _, lo, hi = iv.binomial_ci(k, n)
    cover = stats.binom.pmf(k, n, p)[(lo <= p) & (p <= hi)].sum()
    # Wilson's coverage oscillates around the nominal value; at these n it stays within
    # 2 points of 95 % (Brown, Cai & DasGupta 2001, Fig. 4), and a 90 % interval would not
    assert 0.93 < cover < 0.97
    _, lo9, hi9 = iv.binomial_ci(k, n, 0.90)
    assert stats.binom.pmf(k, n, p)[(lo9 <= p) & (p <= hi9)].sum() < 0.93


def test_share_ci_counts_the_true_values():
    x = np.array([[1, 0, 1], [1, 1, 0]], bool)
    p, (lo, hi) = iv.share_ci(x)
    assert p == 4 / 6 and (lo, hi) == pytest.approx(tuple(iv.binomial_ci(4, 6)[1:]))
    assert iv.share_ci(np.zeros(10))[1][0] == 0.0
    assert iv.share_ci(x, 0.9)[1] == pytest.approx(tuple(iv.binomial_ci(4, 6, 0.9)[1:]))
    for bad in (np.array([]), np.array([0.5, 1.0])):
        with pytest.raises(ValueError, match="^a share needs a non-empty array of 0/1 values$"):
            iv.share_ci(bad)


# --------------------------------------------------------------------------- bootstrap
def test_bootstrap_ci_is_the_2_5_and_97_5_percentiles_of_the_resamples():
    data = np.random.default_rng(5).normal(0.0, 1.0, (40, 2))

    def stat(d):
        return float(d[:, 0].mean() - d[:, 1].mean())

    default = iv.bootstrap_ci(stat, data, np.random.default_rng(6))
    rng = np.random.default_rng(6)
    reps = [stat(data[rng.integers(0, 40, 40)]) for _ in range(400)]  # 400 resamples
    assert default[1] == pytest.approx(tuple(np.percentile(reps, [2.5, 97.5])), rel=1e-12)
    est, (lo, hi) = iv.bootstrap_ci(stat, data, np.random.default_rng(6), n_boot=300)
    rng = np.random.default_rng(6)  # the same resamples, by hand
    reps = np.sort([stat(data[rng.integers(0, 40, 40)]) for _ in range(300)])
    # numpy's default percentile: linear between order statistics at (n-1) q
    assert est == stat(data)
    assert lo == pytest.approx(reps[7] + 0.475 * (reps[8] - reps[7]), rel=1e-12)
    assert hi == pytest.approx(reps[291] + 0.525 * (reps[292] - reps[291]), rel=1e-12)


def test_bootstrap_ci_coverage_is_near_95_percent():
    # 160,000 resamples (a Python loop): R = 800 and a band of 3 se (0.023), which still
    # tells 95 % from 90 %; a by-chance failure has probability 0.3 % for an untried seed
    R, n, mu = 800, 100, 0.3
    rng = np.random.default_rng(7)
    x = rng.normal(mu, 1.0, (R, n))
    hit = [lo <= mu <= hi for lo, hi in (iv.bootstrap_ci(np.mean, row, rng, 200)[1] for row in x)]
    # the percentile bootstrap of a mean is the normal interval with s of ddof 0: its coverage
    # at n = 100 is P(|t_99| < 1.96 sqrt(99/100)) = 0.946
    nominal = 2 * stats.t.cdf(1.96 * math.sqrt((n - 1) / n), n - 1) - 1
    assert abs(np.mean(hit) - nominal) < coverage_bound(R, 3.0)


# --------------------------------------------------------------------------- one plate
def test_spread_is_the_median_and_the_2_5_97_5_percent_order_statistics():
    x = np.random.default_rng(8).permutation(np.arange(201.0))  # (n-1) q is a whole number
    med, (lo, hi) = iv.spread(x)
    assert (med, lo, hi) == pytest.approx((100.0, 5.0, 195.0), rel=1e-14)
    med, (lo, hi) = iv.spread(x, 0.90)
    assert (lo, hi) == pytest.approx((10.0, 190.0), rel=1e-14)
    with pytest.raises(ValueError, match="^a spread needs at least one value$"):
        iv.spread(np.array([]))
    assert iv.spread([3, 1, 2]) == (2.0, (1.05, 2.95))  # integers, linear interpolation


def test_spread_rows_is_the_spread_of_every_row_with_nan_left_out():
    x = np.random.default_rng(9).permutation(np.arange(201.0))
    rows = np.stack([x, 2 * x, np.append(x[:-1], np.nan)])  # the last: 200 values, NaN out
    med, lo, hi = iv.spread_rows(rows)
    assert med.shape == lo.shape == hi.shape == (3,)
    assert (med[:2], lo[:2], hi[:2]) == (
        pytest.approx([100.0, 200.0]),
        pytest.approx([5.0, 10.0]),
        pytest.approx([195.0, 390.0]),
    )
    ref = np.percentile(x[:-1], [2.5, 50, 97.5])  # linear interpolation between ranks
    assert (lo[2], med[2], hi[2]) == pytest.approx(tuple(ref), rel=1e-14)
    med, lo, hi = iv.spread_rows(rows[:1], 0.90)
    assert (lo[0], hi[0]) == pytest.approx((10.0, 190.0), rel=1e-14)


def test_spread_of_many_plates_matches_the_normal_quantiles():
    n = 40000
    x = np.random.default_rng(9).normal(10.0, 2.0, n)
    med, (lo, hi) = iv.spread(x)
    # standard error of the q-quantile: sqrt(q (1-q) / n) / pdf(z_q)
    for q, got in ((0.025, lo), (0.5, med), (0.975, hi)):
        z = stats.norm.ppf(q)
        se = 2.0 * math.sqrt(q * (1 - q) / n) / stats.norm.pdf(z)
        assert abs(got - (10.0 + 2.0 * z)) < K * se, q


def test_spread_holds_95_percent_of_new_plates():
    R = 4000
    rng = np.random.default_rng(10)
    _, (lo, hi) = iv.spread(rng.gamma(3.0, 1.0, 100000))
    new = rng.gamma(3.0, 1.0, R)
    assert abs(np.mean((lo <= new) & (new <= hi)) - 0.95) < coverage_bound(R)


def test_plate_p_is_the_two_sided_tail_share_with_ties_half():
    x = np.arange(1.0, 101.0)  # 1..100
    assert iv.plate_p(x, 50.5) == 1.0
    assert iv.plate_p(x, 3.5) == pytest.approx(2 * 3 / 100)
    assert iv.plate_p(x, 97.5) == pytest.approx(2 * 3 / 100)
    assert iv.plate_p(x, 3.0) == pytest.approx(2 * 2.5 / 100)  # the tie counts half
    assert iv.plate_p(x, 0.0) == 0.0 and iv.plate_p(x, 1000.0) == 0.0
    assert iv.plate_p(x, 50.0) == pytest.approx(2 * 49.5 / 100)
    with pytest.raises(ValueError, match="^a one-plate p needs at least one plate$"):
        iv.plate_p(np.array([]), 1.0)
    assert iv.plate_p([1, 2, 3], 2) == 1.0  # integers: the middle plate, q = 1/2


@pytest.mark.parametrize(
    "ref, h, p",
    [
        (3.0, 0.0, 2 * 2.5 / 100),  # h = 0 is the old rule: the tie at 3 counts half
        (3.0, 0.25, 2 * 3 / 100),  # 3 plates below 3.25 (none on an edge)
        (3.0, 0.5, 2 * 3 / 100),  # below 3.5: 3 plates; above 2.5: 98
        (3.0, 1.0, 2 * 3.5 / 100),  # the plate on the edge 4 counts half
        (2.5, 1.5, 2 * 3.5 / 100),  # lower share 1, 2, 3 and half of the plate on 4
        (97.0, 1.0, 2 * 4.5 / 100),  # upper tail: 97..100 above 96, and half the plate on 96
        (97.0, 0.5, 2 * 4 / 100),  # above 96.5: 97..100
        (0.0, 0.5, 0.0),  # nothing prints as 0 (-0.5 to 0.5): p = 0
        (0.0, 1.0, 2 * 0.5 / 100),  # the first plate lies on the edge 0 + 1: it counts half
        (50.0, 10.0, 1.0),  # 2 min(59.5, 60.5) / 100 = 1.19: capped at 1
        (50.5, 0.25, 1.0),  # exactly the middle: 2 min(50, 50) / 100
    ],
)
def test_plate_p_counts_every_value_that_prints_as_ref(ref, h, p):
    """p = min(1, 2 min(P(X < ref + h), P(X > ref - h))), plates on an edge counted half."""
    x = np.arange(1.0, 101.0)  # 1..100: every share is exact
    assert iv.plate_p(x, ref, h) == pytest.approx(p, abs=1e-15)
    assert iv.plate_p(x, ref, h) == iv.plate_p(-x, -ref, h)  # symmetric in the two tails


def test_plate_p_at_h_0_is_the_old_rule_and_h_is_not_negative():
    rng = np.random.default_rng(21)
    x = np.round(rng.normal(0.0, 1.0, 500), 1)  # many ties
    for ref in (-2.0, -0.3, 0.0, 0.1, 1.7, 2.5):
        q = (np.count_nonzero(x < ref) + 0.5 * np.count_nonzero(x == ref)) / x.size
        assert iv.plate_p(x, ref, 0.0) == pytest.approx(2 * min(q, 1 - q), abs=1e-15)
        assert iv.plate_p(x, ref) == iv.plate_p(x, ref, 0.0)
        # a wider rounding can only make the paper's number less rare
        assert iv.plate_p(x, ref, 0.05) >= iv.plate_p(x, ref, 0.0)
    with pytest.raises(ValueError, match=r"^the rounding half-unit h must be >= 0, not -0\.1$"):
        iv.plate_p(x, 0.0, -0.1)
    with pytest.raises(ValueError, match="^the rounding half-unit h must be >= 0, not nan$"):
        iv.plate_p(x, 0.0, math.nan)


def test_plate_p_of_a_true_plate_is_uniform():
    # the paper's plate drawn from the simulated distribution: P(p < 0.05) = 0.05
    R = 4000
    rng = np.random.default_rng(11)
    plates = rng.normal(0.0, 1.0, 2000)
    p = np.array([iv.plate_p(plates, r) for r in rng.normal(0.0, 1.0, R)])
    se = math.sqrt(0.05 * 0.95 / R)
    assert abs(np.mean(p < 0.05) - 0.05) < K * se
    assert abs(np.mean(p < 0.01) - 0.01) < K * math.sqrt(0.01 * 0.99 / R)


# --------------------------------------------------------------------------- jackknife
def test_jackknife_of_a_mean_is_the_t_interval_of_the_chunk_means():
    rng = np.random.default_rng(12)
    x = rng.normal(2.0, 3.0, size=(40, 50))  # 40 chunks of 50 draws
    sums = np.stack([x.sum(1), np.full(40, 50.0)], 1)
    est, lo, hi = jackknife(lambda t: t[0] / t[1], sums)
    # over equal chunks the jackknife se of a mean is the between-chunk se of the mean (exact)
    elo, ehi = stats.t.interval(0.95, 39, loc=x.mean(), scale=stats.sem(x.mean(1)))
    assert est == pytest.approx(x.mean(), rel=1e-13)
    assert (lo, hi) == pytest.approx((elo, ehi), rel=1e-12)


def test_jackknife_coverage_of_a_ratio_is_95_percent():
    R, C, m = 2000, MIN_CHUNKS, 25
    rng = np.random.default_rng(13)
    x = rng.normal(0.0, 2.0, (R, C, m))
    hit = 0
    for r in range(R):  # the sd, a smooth non-linear function of the sums
        sums = np.stack([np.full(C, m), x[r].sum(1), (x[r] ** 2).sum(1)], 1)
        _, lo, hi = jackknife(lambda t: np.sqrt(t[2] / t[0] - (t[1] / t[0]) ** 2), sums)
        hit += lo <= 2.0 <= hi
    assert abs(hit / R - 0.95) < coverage_bound(R)


def test_jackknife_refuses_fewer_than_the_minimum_of_chunks():
    sums = np.ones((MIN_CHUNKS - 1, 2))
    with pytest.raises(StudyError, match=f"at least {MIN_CHUNKS} chunks, the run has 19"):
        jackknife(lambda t: t[0], sums)
    assert MIN_CHUNKS == 20
    jackknife(lambda t: t[0], np.ones((MIN_CHUNKS, 2)))  # the minimum itself is enough
    with pytest.raises(StudyError, match="at least 2 chunks"):
        jackknife(lambda t: t[0], np.ones((1, 2)), min_chunks=0)
    est, lo, hi = jackknife(lambda t: t[0], np.arange(6.0)[:, None], min_chunks=2)
    assert est == 15.0 and lo < est < hi


def test_the_provenance_names_every_method():
    assert set(iv.METHODS) == {"mean", "sd", "share", "bootstrap", "jackknife", "spread", "exact"}
    assert str(MIN_CHUNKS) in iv.METHODS["jackknife"] and "Wilson" in iv.METHODS["share"]


def test_sample_evidence_p_is_plate_p_row_by_row():
    """The region's vectorised one-plate p (sim.claims.book_region) equals plate_p per point,
    with the rounding's h, on plates with values on the edges."""
    x = np.stack([np.arange(1.0, 101.0), np.arange(1.0, 101.0) / 2, -np.arange(1.0, 101.0)])
    for ref, h in ((3.0, 0.0), (3.0, 1.0), (2.5, 0.5), (97.0, 1.0), (-3.0, 0.5), (50.0, 10.0)):
        ev = sample_evidence(x, ref, h)
        assert list(ev["p"]) == [iv.plate_p(r, ref, h) for r in x]
