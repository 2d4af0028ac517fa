"""The paired shift (common random numbers) that decides Agnard's 21-control rows over the
scanner's unprinted inputs (``sim.studies.agnard.paired``). No simulation of blocks: the
estimator on synthetic log-normal samples whose answer is known, and the book's one-plate
rule on the mapped blocks, with the claim book's own check-Z statement."""

from __future__ import annotations

import numpy as np
import pytest

from sim.claims.book_region import plate_ref, sample_evidence
from sim.claims.inference import FAILS, HOLDS, UNDECIDED, status
from sim.claims.region import statement_of
from sim.studies.agnard.claims import load_book
from sim.studies.agnard.paired import (
    GRID,
    MIN_TEST_PAIRS,
    mapped,
    paired_evidence,
    paired_shift,
    variance_ratio,
    z_box,
)

CID = "agnard.control_21.check_z_cm"  # printed 24 cm, tol 4.8: zone 18.7-29.3 cm


def _status(base, c, v):
    book = load_book()
    ev = paired_evidence(base, c, v, *plate_ref(book.spec(CID)))
    return status(statement_of(book, CID), ev, len(v)), ev


def _samples(median, log_sd, k_base=500, k=48, seed=3):
    """500 configured blocks and k paired ones (log-normal, like an rms over one block)."""
    rng = np.random.default_rng(seed)
    base = median * np.exp(log_sd * rng.standard_normal(k_base))
    c = median * np.exp(log_sd * rng.standard_normal(k))
    return base, c, rng


def test_the_configured_scanner_itself_gets_the_books_evidence_on_its_blocks():
    """Paired with itself, the shift and its error are zero: the row's evidence is exactly
    the book's over the configured blocks (no lattice widening)."""
    base, c, _ = _samples(27.2, 0.11)
    book = load_book()
    ref, h = plate_ref(book.spec(CID))
    ev = paired_evidence(base, c, c[None], ref, h)
    want = sample_evidence(base[None], ref, h)
    for q in ("value", "low", "high", "p"):
        assert ev[q][0] == pytest.approx(want[q][0], rel=1e-12), q


def test_a_shift_that_moves_the_blocks_flips_the_decision_and_a_small_one_does_not():
    """The configured check Z (median 27.2 cm, 95 % of blocks 22.6-34.9, like the run) is
    undecided against 24 cm. A vector whose blocks are 35 % larger block by block (paired
    noise 2 %) fails (p < 0.05 over the whole interval of its shift); one 2 % larger and
    the configured scanner itself stay undecided. Configured blocks narrow enough to hold
    (median 24 cm, log sd 0.04) hold at their own vector and fail 50 % larger."""
    base, c, rng = _samples(27.2, 0.11)
    noise = 0.02 * rng.standard_normal((3, c.size))
    v = c * np.exp(np.log([1.35, 1.02, 1.0])[:, None] + noise)
    st, ev = _status(base, c, v)
    assert list(st) == [FAILS, UNDECIDED, UNDECIDED]
    assert ev["p"][0] < 0.05 <= ev["p"][1]
    # the same configured blocks with a narrow spread: inside the zone, holds; shifted, fails
    base, c, rng = _samples(24.0, 0.04)
    v = c * np.exp(np.log([1.0, 1.5])[:, None] + 0.01 * rng.standard_normal((2, c.size)))
    st, _ = _status(base, c, v)
    assert list(st) == [HOLDS, FAILS]


def test_the_shifts_uncertainty_keeps_a_straddling_vector_undecided():
    """A shift whose point estimate fails but whose interval reaches back to where blocks
    print as 24 cm is undecided: the decision is taken at every point of the interval."""
    base, c, rng = _samples(27.2, 0.11)
    for sd, want in ((0.005, FAILS), (0.30, UNDECIDED)):
        v = c * np.exp(np.log(1.25) + sd * rng.standard_normal((1, c.size)))
        sh = paired_shift(c, v)
        at_estimate = sample_evidence(base[None] * np.exp(sh.delta[0]), 24.0, 0.5)
        assert at_estimate["p"][0] < 0.05  # decided on the estimate alone: fails
        st, _ = _status(base, c, v)
        assert st[0] == want, sd


def test_paired_variance_is_smaller_than_unpaired_by_the_derived_ratio():
    """Synthetic pairs u ~ N(0, s^2), w = u + 0.1 + e, e ~ N(0, t^2): the variance of the paired
    shift over many replicates is variance_ratio(s_u, s_w, rho) times that of the shift from
    independent blocks (t^2 / (2 s^2 + t^2) here: 0.111 at t = s / 2), within 4 standard errors of
    the variance ratio's own Monte-Carlo estimate; the formula's standard error matches the
    replicates' spread."""
    rng = np.random.default_rng(11)
    k, reps, s, t = 24, 3000, 0.1, 0.05
    paired, unpaired, se = [], [], []
    for _ in range(reps):
        u = s * rng.standard_normal(k)
        w = u + 0.1 + t * rng.standard_normal(k)
        w_other = s * rng.standard_normal(k) + 0.1 + t * rng.standard_normal(k)
        sh = paired_shift(np.exp(u), np.exp(w)[None])
        paired.append(sh.delta[0])
        se.append(sh.delta_se[0])
        unpaired.append(w_other.mean() - u.mean())
    s_w = np.hypot(s, t)
    want = variance_ratio(s, s_w, s / s_w)
    assert want == pytest.approx(t**2 / (2 * s**2 + t**2))
    got = np.var(paired, ddof=1) / np.var(unpaired, ddof=1)
    rel_se = np.sqrt(2 / (reps - 1) * 2)  # two independent variance estimates
    assert abs(got / want - 1) < 4 * rel_se
    assert np.mean(se) == pytest.approx(np.std(paired, ddof=1), rel=0.05)
    assert variance_ratio(1.0, 1.0, 0.8) == pytest.approx(0.2)  # 1 - rho at equal sds


def test_the_map_stretches_only_where_the_pairs_show_the_spread_changed():
    """log v = 1.6 log c (spread 60 % wider): stretched, log beta ~ log 1.6; v = 1.1 c (the
    same relative spread): not stretched, and the map is a pure shift; on fewer pairs than
    the test needs, stretched whatever they show."""
    rng = np.random.default_rng(5)
    c = 20 * np.exp(0.1 * rng.standard_normal(48))
    m = np.log(c).mean()
    v = np.stack([np.exp(m + 1.6 * (np.log(c) - m) + 0.01 * rng.standard_normal(48)), 1.1 * c])
    sh = paired_shift(c, v)
    assert list(sh.stretched) == [True, False]
    assert sh.log_beta[0] == pytest.approx(np.log(1.6), abs=3 * sh.log_beta_se[0] + 0.01)
    used = sh.map_of()
    assert used.log_beta[1] == 0 and used.log_beta_se[1] == 0
    # the same 10 % shift seen on 8 pairs only: too few to test the map, so it stretches
    few = paired_shift(c[:8], 1.1 * c[None, :8] * np.exp(0.02 * rng.standard_normal(8)))
    assert few.k == 8 < MIN_TEST_PAIRS and few.stretched[0]
    assert few.map_of().log_beta_se[0] == few.log_beta_se[0] > 0
    base = 20 * np.exp(0.1 * rng.standard_normal(200))
    x = mapped(base, used)
    assert x.shape == (2, GRID * GRID, 200)
    mid = GRID * GRID // 2
    assert np.allclose(x[1, mid], base * np.exp(used.delta[1]))
    # the lattice reaches the interval's ends, +-z standard errors (Student, 47 dof)
    assert used.z == z_box(48) == pytest.approx(2.3155, abs=1e-3)
    ends = np.log(x[1, :, 0] / base[0])
    assert ends.min() == pytest.approx(used.delta[1] - used.z * used.delta_se[1])
    assert ends.max() == pytest.approx(used.delta[1] + used.z * used.delta_se[1])


def test_bad_blocks_decide_nothing():
    """A vector with a non-positive or NaN block is undecided (NaN evidence); too few or
    mismatched blocks are refused."""
    base, c, _ = _samples(27.2, 0.11, k=8)
    v = np.stack([c * 1.3, c * 1.3])
    v[1, 3] = np.nan
    st, ev = _status(base, c, v)
    assert st[0] == FAILS and st[1] == UNDECIDED and np.isnan(ev["p"][1])
    with pytest.raises(ValueError, match="same k"):
        paired_shift(c, v[:, :5])
    with pytest.raises(ValueError, match="same k"):
        paired_shift(c[:1], v[:, :1])


def test_a_grid_stream_of_its_own_keeps_blocks_of_two_grid_spacings_paired():
    """The grid's node count depends on its spacing; with its noise from ``grid_rng`` every
    other draw of two scanners' blocks is the same (model frames, control, pointing), without
    it the main stream shifts and the blocks are no longer paired."""
    from sim.studies import load_study
    from sim.studies.agnard.schema import block_of
    from sim.studies.agnard.simulate import Simulated

    _, cfg = load_study("studies/agnard_block.toml")
    b = block_of(cfg)

    def sim(grid_mm, paired):
        g = np.random.default_rng(2) if paired else None
        c = {**cfg, "scan.grid_mm": grid_mm}
        return Simulated(c, b, np.random.default_rng(1), 2, cfg["scan.dpi"], grid_rng=g)

    for paired in (True, False):
        a, z = sim(5.0, paired), sim(20.0, paired)
        same = np.array_equal(a.ctrl_obs, z.ctrl_obs) and np.array_equal(a.R, z.R)
        assert same == paired
