"""The classes of the sweep doors24d (issue 26: the seven paper studies' numbers checked three
ways on designs a user would try with --set and [sweep]), one case each; each failed on the
code before its fix. The harness that found them (an independent numpy recomputation of
Brown's point cofactors for every model and layout, the Monte-Carlo spread against the
analytic sigmas within chi-square bounds, every sigma times k, a sweep cell against the single
run, and every claim row's outcome recomputed from its interval and zone by
docs/verdict-rules.md) lives outside the project.

* a claim about a resolution left out of ``tradeoff.dpis`` was scored as an exact 0 % gain:
  ``agnard_block`` with ``--set "tradeoff.dpis=[600.0]"`` wrote
  ``agnard.scanner.gain_300dpi_pct`` = 0 with the interval [0, 0], and the report read
  "Calibration gains 0 % at 300 DPI and 5.6 % at 600 DPI ... (the 600 DPI gain's interval
  lies above the 300 DPI one)": a comparison with a number nothing simulated. The row is now
  absent (a declared claim this run does not produce) and the report says which resolution
  the list lacks.
* ``brown_design``'s coverage and false-alarm rates took the interval v +- 1.96 sqrt(v(1-v)/N)
  (docs/verdict-rules.md: a proportion gets the Wilson interval, never a normal one):
  ``--set coverage.trials=10`` gave ``coverage.affine.false_alarm`` = 0 with the interval
  [-6e-7, 6e-7], outcome "fails" against the zone [0.04, 0.06] (0 false alarms in 10 trials
  cannot exclude 5 %: Wilson [0, 0.28], inconclusive), and coverages of 0.93 with intervals
  up to 1.09. They now take the Wilson interval over the trials.
* ``wolf_polynomial``'s ``wolf.degree.cubic_excess_pct`` ("the cubic's excess over the best
  degree tried") compared the cubic with itself when the other degrees could not be
  estimated on the grid: ``--set plate.spacing_mm=25.0 --set "trade.spacings_mm=[25.0]"
  --set "trade.degrees=[3,4,5]"`` gave 0 % with the interval [0, 0] ("mean rms by degree: 3:
  5.29 um"). Such a run now has no row (nothing was compared), as a trade-off without another
  degree has none.
* ``gridplate_two_plates`` left the calibrations without a positive re-weighting fixed point
  out of the comparator sigma's spread and the grid share without a word (``--set
  plate.grid=3``: 31 of 200), and said "both plates" of one plate or four. The notes now say
  how many were left out, and which plates are pooled.
* ``wolf_polynomial`` run off the paper's calibration (``--set calib.degree=1``: a linear
  correction, not the paper's ten-term cubic; or one reading, one set) still decided the
  paper's predictions ("fails or undecided" on "after correction 5 um rms"), against the rule
  that a prediction tests the paper only on a run whose printed inputs are the paper's: the
  printed inputs were listed as not reproduced, with no exact input row to fail. They are now
  exact input rows (``wolf.input.*``), and such a run's predictions are findings.
"""

from __future__ import annotations

import numpy as np
from scipy import stats

from sim.claims.rules import off_paper
from sim.claims.table import claim_rows, exact
from sim.studies import load_study
from sim.studies.agnard.claims import scanner_rows
from sim.studies.agnard.report import _table1_line
from sim.studies.design.claims import _coverage
from sim.studies.gridplate import claims as gridplate_claims
from sim.studies.wolf import claims as wolf_claims
from sim.studies.wolf.claims import _cubic_excess

GAIN = "agnard.scanner.gain_{}dpi_pct"
CFG = {"scan.max_x_um": 20.0, "scan.max_y_um": 40.0}


def _scan(dpis):
    n = len(dpis)
    return {
        "dpi": np.repeat(np.asarray(dpis, float), 2),
        "calibration": np.array(["raw", "corrected"] * n),
        "gain_xy_pct": np.tile([0.0, 5.5], n),
        "gain_xy_pct_se": np.tile([0.0, 0.5], n),
        "trials": np.full(2 * n, 40),
    }


def test_a_resolution_not_simulated_has_no_gain_row():
    rows = scanner_rows(_scan([600.0]), 21)
    assert rows[GAIN.format(300)] is None
    assert rows[GAIN.format(600)].value == 5.5
    both = scanner_rows(_scan([300.0, 600.0]), 21)
    assert both[GAIN.format(300)].value == 5.5 and both[GAIN.format(300)].ci[0] < 5.5


def test_the_report_does_not_compare_a_gain_nothing_simulated():
    g6 = {"value": 5.6, "ci_low": 4.5, "ci_high": 6.6}
    line = _table1_line({GAIN.format(600): g6}, CFG)
    assert "lacks 300 DPI" in line and "0 % at 300" not in line and "lies above" not in line
    g3 = {"value": 1.0, "ci_low": 0.5, "ci_high": 1.5}
    line = _table1_line({GAIN.format(300): g3, GAIN.format(600): g6}, CFG)
    assert "1.0 % at 300 DPI and 5.6 % at 600 DPI" in line and "lies above" in line


def _cov_table(false_alarm, coverage, trials=10):
    two = lambda v: [v, v]  # noqa: E731
    return {
        "coverage": {
            "model": ["pivot", "affine"],
            "scenario": two("nominal"),
            "trials": two(trials),
            "nonconverged": two(0),
            "grid": two(5),
            "dof": two(43),
            "coverage_known": two(coverage),
            "coverage_f": two(coverage),
            "false_alarm": two(false_alarm),
            "s0_ratio": two(1.0),
            "s0_ratio_se": two(0.01),
            "s0_expected": two(0.99),
            "s0sq_ratio": two(1.0),
        }
    }


def test_brown_design_rates_take_the_wilson_interval():
    t = _coverage(_cov_table(0.0, 0.932))
    fa, cov = t["coverage.affine.false_alarm"], t["coverage.pivot.coverage_known"]
    wilson = stats.binomtest(0, 10).proportion_ci(0.95, "wilson")
    assert fa.value == 0.0 and fa.ci[0] == 0.0
    assert np.isclose(fa.ci[1], wilson.high, rtol=1e-9)  # 0.28: 0 of 10 cannot exclude 5 %
    assert 0.0 <= cov.ci[0] < 0.932 < cov.ci[1] <= 1.0
    w = stats.binomtest(3, 20).proportion_ci(0.95, "wilson")
    fa = _coverage(_cov_table(0.15, 1.0, trials=20))["coverage.pivot.false_alarm"]
    assert np.allclose(fa.ci, (w.low, w.high), rtol=1e-9)
    assert _coverage(_cov_table(0.15, 1.0, trials=20))["coverage.pivot.coverage_f"].ci[1] == 1.0


def _degt(rms4):
    t = 20
    return {
        "spacing_mm": np.full(2 * t, 25.0),
        "n_sets": np.full(2 * t, 3),
        "degree": np.repeat([3, 4], t),
        "check_rms_um": np.concatenate([np.linspace(5.0, 6.0, t), np.full(t, rms4)]),
    }


def test_wolf_cubic_is_not_compared_with_itself():
    cfg = {"plate.spacing_mm": 25.0, "calib.n_sets": 3, "seed": 1, "trade.trials": 20}
    assert _cubic_excess(cfg, _degt(np.nan)) is None  # degree 4 not estimable: cubic alone
    both = _cubic_excess(cfg, _degt(5.0))
    assert both.value > 0 and both.ci[1] > both.ci[0]  # 5.5 against 5.0: a real comparison


def test_gridplate_notes_say_what_was_left_out_and_which_plates():
    rng = np.random.default_rng(5)
    comp = rng.normal(1.2, 0.1, 40)
    comp[:6] = np.nan
    res = {"gn_iterations": np.full(40, 2), "comp_sigma_um": comp, "aff_sigma_um": comp + 0.2}
    res["sim_sigma_um"] = comp + 0.3
    cfg = {
        "comparator.coord_sigma_um": 1.2,
        "readings.count": 4,
        "readings.sigma_um": 1.5,
        "analysis.iter_tol_um": 0.001,
        "plate.count": 1,
    }
    rows = gridplate_claims._comparator(gridplate_claims.load_book(), cfg, res)
    note = rows["twoplate.comparator_sigma.sigma_um"].note
    assert "6 of 40 calibrations had no positive fixed point" in note and "both" not in note
    assert "on the plate pooled" in note
    share = gridplate_claims._shares(res)["twoplate.similarity_vs_affine.grid_share_linear_um"]
    assert "6 of 40" in share.note


def test_wolf_off_the_papers_calibration_is_not_a_test_of_it():
    book = wolf_claims.load_book()
    cfg = load_study("studies/wolf_polynomial.toml")[1]
    ids = [f"wolf.input.{k}" for k in wolf_claims.PRINTED_INPUTS]
    assert {"wolf.input.calib.degree", "wolf.input.reading.n", "wolf.input.calib.n_sets"} <= set(
        ids
    )
    shipped = claim_rows(book, {i: exact(float(cfg[i[len("wolf.input.") :]])) for i in ids})
    assert [r["outcome"] for r in shipped] == ["holds"] * len(ids)  # the study file is the paper's
    pred = {"claim": "p", "kind": "prediction", "verdict": "holds", "outcome": "holds", "note": ""}
    assert off_paper([*shipped, pred])[-1]["verdict"] == "holds"
    linear = claim_rows(wolf_claims.load_book(), {"wolf.input.calib.degree": exact(1.0)})
    assert linear[0]["outcome"] == "fails"
    assert off_paper([*linear, pred])[-1]["verdict"] == "finding"
