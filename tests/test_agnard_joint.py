"""Agnard's last rows over all their unprinted inputs (issue 21): the count of pass points
data snooping removes, over the scanner's vectors (``sim.studies.agnard.paired_count``), and
the 5-control rows over the lost layout and the scanner together (``sim.studies.agnard.
joint``). No simulation of blocks: the estimators on synthetic samples whose answer is known,
decided by the claim book's own statements."""

from __future__ import annotations

import numpy as np
import pytest

from sim.claims.book_region import load_declaration, region_rows
from sim.claims.inference import FAILS, HOLDS, UNDECIDED, Region, status
from sim.claims.region import outcomes, statement_of
from sim.studies.agnard.claims import WITHOUT_CENTRES, load_book
from sim.studies.agnard.joint import joint_region, layout_points, pairs_of, with_option
from sim.studies.agnard.paired import z_box
from sim.studies.agnard.paired_count import cdf_shift, count_evidence, mean_shift
from sim.studies.agnard.region import CENTRES, CONFIGURED, DECLARATION, REJECTED, SCANNER

CHECK_Z = "agnard.control_5.check_z_cm"  # printed 29 cm, tol 5.8: zone 22.7-35.3 cm


def _pairs(rng, a: float, b0: float, b1: float, k: int, m: int = 500):
    """Counts with a common part (the same block's luck): ``c = Z + B0``, ``v = Z + B1``,
    ``Z ~ Poisson(a)``, ``B ~ Poisson(b)``; ``m`` base blocks like ``c``, ``k`` pairs."""
    base = rng.poisson(a, m) + rng.poisson(b0, m)
    z = rng.poisson(a, k)
    return base, z + rng.poisson(b0, k), z + rng.poisson(b1, k)


def _decide(base, c, v):
    book = load_book()
    spec = book.spec(REJECTED)
    ev = count_evidence(base, c, v, float(spec["ref"]), 0.5)
    return status(statement_of(book, REJECTED), ev, np.atleast_2d(v).shape[0]), ev


def test_the_count_estimators_variance_is_its_derived_one():
    """The share of blocks losing none at a vector, estimated with the configured scanner as a
    control variate: unbiased, its variance over 3000 replicates equal to the derived
    ``var(I_v) (1 - rho^2) / k + beta^2 F_B (1 - F_B) / M`` within four standard errors of
    a sample variance (from the replicates' own fourth moment) and the regression's O(1/k)
    (``1 / (k - 3)``); below the paired difference's, the vector's own blocks' and the
    unpaired variance, by more than that tolerance; and its reported (smoothed) standard
    error not below the truth."""
    a, b0, b1, k, m, R = 0.8, 0.05, 0.5, 48, 500, 3000  # loses none: 43 % configured, 27 %
    pc, pv, p11 = np.exp(-a - b0), np.exp(-a - b1), np.exp(-a - b0 - b1)
    cov, vc, vv = p11 - pc * pv, pc * (1 - pc), pv * (1 - pv)
    beta = cov / vc
    derived = (vv - cov**2 / vc) / k + beta**2 * vc / m
    difference = (vc + vv - 2 * cov) / k + vc / m
    rng = np.random.default_rng(21)
    est, se2 = np.empty(R), np.empty(R)
    for r in range(R):
        s = cdf_shift(*_pairs(rng, a, b0, b1, k, m), tmax=0)
        est[r], se2[r] = s["F"][0, 0], s["se"][0, 0] ** 2
    var = est.var(ddof=1)
    m4 = np.mean((est - est.mean()) ** 4)
    tol = 4 * np.sqrt((m4 - var**2) / R) / var
    assert abs(est.mean() - pv) < 4 * np.sqrt(derived / R)
    assert 1 - tol < var / derived < 1 + tol + 1 / (k - 3)
    assert derived < difference < vc / m + (vc + vv) / k
    # the test tells the control variate from both its special cases (1.5 and 1.6 x)
    assert derived * (1 + tol + 1 / (k - 3)) < min(difference, vv / k)
    assert se2.mean() >= derived * (1 - tol)


def test_the_configured_scanner_with_itself_and_the_count_quantiles():
    """Paired with itself the estimate is the main blocks' own distribution function (the
    shift is zero), so the median and the share that loses none are the book's; a vector
    that removes one point more on every block moves the median by one; the mean shift is
    the paired difference of counts with a zero error when every pair differs alike."""
    rng = np.random.default_rng(4)
    base, c, _ = _pairs(rng, 0.6, 0.5, 0.5, 48)
    ev = count_evidence(base, c, np.stack([c, c + 1]))
    assert ev["share_zero"][0] == pytest.approx(np.mean(base == 0), abs=1e-12)
    assert ev["value"][0] == np.median(base) and ev["value"][1] == np.median(base) + 1
    d, se, un = mean_shift(c, np.stack([c, c + 1]))
    assert list(d) == [0.0, 1.0] and list(se) == [0.0, 0.0] and un[1] > 0
    with pytest.raises(ValueError, match="non-negative integers"):
        cdf_shift(base, c - 0.5, c)


def test_the_count_rule_flips_where_the_zeros_vanish_and_not_where_they_stay():
    """'Not a single pass point had to be removed', decided by the book's one-plate rule
    (fails iff a block losing none is rare, p = 2 P(X = 0) < 0.05). Configured blocks that
    lose none a third of the time (as the run's 34 %) are undecided; a vector that keeps
    them stays undecided, one whose blocks all lose at least one fails with 400 pairs, and
    with 48 pairs cannot fail (its share's interval reaches z / 50: what the module says
    48 pairs cannot show). Blocks that nearly never lose one hold, and fail where every
    block of the vector loses one."""
    rng = np.random.default_rng(7)
    base, c, _ = _pairs(rng, 0.6, 0.5, 0.5, 400)
    st, ev = _decide(base, c, np.stack([c, c + 1 + rng.poisson(2.0, c.size)]))
    assert list(st) == [UNDECIDED, FAILS]
    assert ev["p"][0] > 0.05 > ev["p"][1]
    st48, ev48 = _decide(base, c[:48], (c[:48] + 1)[None])
    assert list(st48) == [UNDECIDED]
    assert ev48["p"][0] >= 2 * z_box(48) * np.sqrt(0.5 / 50 * (1 - 0.5 / 50) / 48) * 0.9
    base, c, _ = _pairs(rng, 0.001, 0.001, 0.0, 400)
    st, _ = _decide(base, c, np.stack([c, c + 1]))
    assert list(st) == [HOLDS, FAILS]


def _layout_region(book, insets, stats_of):
    """A layout region of ``insets`` without and with centres (no statement constrains it)."""
    dec = load_declaration(DECLARATION, book)
    n = 2 * len(insets)
    x = {"five_inset_1": np.tile(insets, 2), CENTRES: np.repeat([0.0, 1.0], len(insets))}
    res = {i.name: (0.1, 0.1) for i in dec.inputs}
    stats = [stats_of(i) for i in range(n)]
    return Region(dec.inputs, [], x, np.zeros((n, 0), np.int8), 0.95, res), stats


def test_the_joint_design_is_balanced():
    """Every layout point gets as many vectors as every other, each vector sees both options
    at two insets half the range apart; the layout points span the explored insets."""
    book = load_book()
    insets = np.linspace(0.0, 0.45, 16)
    layout, _ = _layout_region(book, insets, lambda i: {})
    five = layout_points(layout)
    assert len(five) == 16 and five[0] == (0.0, False) and five[7] == (0.45, False)
    assert [c for _, c in five] == [False] * 8 + [True] * 8
    use = np.zeros(16, int)
    for j in range(16):
        a, b = pairs_of(j, 16)
        assert not five[a][1] and five[b][1] and abs(a - (b - 8)) == 4
        use[[a, b]] += 1
    assert set(use) == {2}


def _two_by_two(book) -> Region:
    """The joint region of two layout points (inset 0.2 without and with centres: configured
    check Z medians 27 and 12 cm) and two scanner vectors (vector 0 makes the blocks 60 %
    larger at the point without centres, vector 1 at the one with)."""
    rng = np.random.default_rng(5)
    med = {0: 27.0, 1: 12.0}
    lay, stats = _layout_region(
        book, [0.2], lambda i: {CHECK_Z: med[i] * np.exp(0.12 * rng.standard_normal(150))}
    )
    five = ((0.2, False), (0.2, True))
    scan_dec = load_declaration(SCANNER, book)
    sx = {i.name: np.array([i.low, i.high]) for i in scan_dec.inputs}
    scanner = Region(scan_dec.inputs, [], sx, np.zeros((2, 0), np.int8), 0.95, {})
    cfg_blocks = {lay_i: med[lay_i] * np.exp(0.12 * rng.standard_normal(48)) for lay_i in (0, 1)}
    grow = {(0, 0): 1.6, (0, 1): 1.0, (1, 0): 1.0, (1, 1): 1.6}  # (vector, layout point)
    sstats = []
    for j in (0, 1):
        p = {}
        for li in (0, 1):
            cb = cfg_blocks[li]
            p[CONFIGURED + f"five{li}:{CHECK_Z}"] = cb
            p[f"five{li}:{CHECK_Z}"] = cb * grow[(j, li)] * np.exp(0.01 * rng.standard_normal(48))
        sstats.append(p)
    joint = joint_region(book, lay, stats, scanner, sstats, five, [CHECK_Z])
    return joint


def test_the_predictions_use_the_centres_the_finding_the_rest():
    """The paper's program carries the projection centres: a prediction decided over the
    joint points with them (check Z fails at both: inconclusive, two points being too few for
    a region verdict, sim.claims.region.REGION_MIN_POINTS), the finding over those without
    (fails at one, undecided at the other: fails or undecided), each region holding only
    its option's points and their evidence."""
    book = load_book()
    joint = _two_by_two(book)
    with_c, without = with_option(joint, True), with_option(joint, False)
    assert with_c.n == without.n == 2
    assert set(with_c.x[CENTRES]) == {1.0} and set(without.x[CENTRES]) == {0.0}
    for r, v in ((with_c, 1.0), (without, 0.0)):
        keep = np.asarray(joint.x[CENTRES]) == v
        for q, a in joint.outputs[CHECK_Z].items():
            assert np.array_equal(r.outputs[CHECK_Z][q], np.asarray(a)[keep])
    finding = WITHOUT_CENTRES[CHECK_Z]
    without.outputs[finding] = without.outputs[CHECK_Z]
    (pred,) = region_rows(book, with_c, [CHECK_Z])
    (found,) = region_rows(book, without, [finding])
    assert pred["outcome"] == "inconclusive" and pred["verdict"] == "inconclusive"
    assert "region sampled at 2 points, fails at all of them" in pred["note"]
    assert found["outcome"] == "fails or undecided" and found["verdict"] == "finding"
    assert book.spec(finding)["kind"] == "finding"
    assert book.spec(finding)["ref"] == book.spec(CHECK_Z)["ref"]


def test_a_joint_point_is_decided_by_its_vectors_shift_at_its_layout():
    """Check Z of one layout point, configured median 27 cm (95 % of blocks inside the
    22.7-35.3 zone's neighbourhood: undecided). Vector 0 makes every paired block 60 %
    larger at that layout: the joint point fails; vector 1 leaves it: undecided. At the
    other layout point (with centres, blocks far below the zone) vector 1's +60 % still
    leaves p < 0.05 below it (fails), vector 0's nothing (fails too): the shift is read at
    the point's own layout, not at another."""
    book = load_book()
    joint = _two_by_two(book)
    assert joint.n == 4 and joint.accepted.all()
    o = outcomes(joint, statement_of(book, CHECK_Z))
    at = {
        (int(j), int(c)): int(s)
        for j, c, s in zip(joint.x["wavelength_mm"] > 100, joint.x[CENTRES], o)
    }
    assert at[(0, 0)] == FAILS and at[(1, 0)] == UNDECIDED
    assert at[(0, 1)] == FAILS and at[(1, 1)] == FAILS
    assert set(np.asarray(joint.x["five_inset_1"])) == {0.2}


def test_the_joint_points_map_is_always_stretched_so_never_narrower():
    """At a joint point the spread's scale ranges over its interval even where the pairs do
    not show it changed: the evidence is never narrower (lower low, higher high, larger p)
    than the shift-only map's, and strictly wider where the shift-only map applies (pairs
    consistent with an unchanged spread)."""
    from sim.studies.agnard.paired import paired_evidence, paired_shift

    rng = np.random.default_rng(9)
    base = 27.0 * np.exp(0.2 * rng.standard_normal(150))
    c = 27.0 * np.exp(0.2 * rng.standard_normal(48))
    v = c[None] * np.exp(0.3 + 0.02 * rng.standard_normal((1, 48)))  # spread unchanged
    assert not paired_shift(c, v).stretched[0]
    plain = paired_evidence(base, c, v, 29.0, 0.5)
    wide = paired_evidence(base, c, v, 29.0, 0.5, stretch=True)
    assert wide["low"][0] < plain["low"][0] and wide["high"][0] > plain["high"][0]
    assert wide["p"][0] >= plain["p"][0]
    assert wide["value"][0] == pytest.approx(plain["value"][0], rel=0.01)  # beta near 1
