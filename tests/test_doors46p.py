"""Key combinations on the big and the two-plate studies (brief P46: network_gridplate_2500,
agnard_block_104, gridplate_two_plates, brown_table1, network_testfield), each key within its
bounds, tried as pairs and triples through ``sim check`` and small runs. One case each; each
failed on the code before its fix.

* ``brown_table1`` and ``brown_dilution``: range errors large against what the plate
  determines. The paper's plate with ``errors.setting_sigma_um = 1e4`` and
  ``errors.comparator_sigma_um = 1e4`` (12 mm a range, each key within its 0-10,000 um)
  passed ``sim check``; the run's stations and pivot adjustments converged in 93 of 400
  trials and its statistics, the Monte-Carlo self-check against the analytic covariance
  included (``self-check``, 1.05), were taken over that selection. A 4 mm plate
  (``plate.spacing_mm = 1``) with 0.3 mm errors passed ``sim check`` and the run computed
  every chunk, then refused, "only 0 trials converged in all models". Sixteen probe plates
  of the run's error model (a fixed stream) are adjusted with each model on load, and a
  configuration where one does not converge is refused, naming the larger error share when
  the paper's errors converge on that plate, else the plate's key
  (:func:`sim.studies.brown.probe.check_noise`). So are solver limits that part of the
  probe plates cannot meet (``solver.max_iter = 3``, ``solver.tol_mm = 1e-15`` on the
  paper's plate: 10 and 9 of 16 do not converge; ``sim check`` passed them as a limit some
  trials meet, tests/test_doors27a.py, and the run's statistics were those of the rest),
  named by the solver's key whose default lets every probe plate converge.
* ``gridplate_two_plates`` and ``agnard_block``: a region over the work limit
  (``region.points = 65536``, ``region.rounds = 6`` with ``region.draws = 1e6``; agnard's
  64 five-point layouts of 1e6 blocks, its Table 1 region of 256 scanner vectors of 10,000
  blocks in 5 rounds) was told to "reduce trials or the lists in the study file": neither
  holds any part of it. The region's keys are named when the region outweighs the rest
  (:mod:`sim.mc.gridplate_size`, :mod:`sim.mc.agnard_size`).
"""

import numpy as np
import pytest

from sim.cli import main
from sim.instruments.ranges import multilateration as ml
from sim.studies.brown.schema import TABLE1, setup
from sim.studies.brown.values import start_theta
from tests.oneline import SIM_ERROR, one_line
from tests.oneline import check_argv as _check


def _converged(sets: dict, trials: int = 48, seed: int = 4601) -> dict:
    """Share of ``trials`` plates of brown_table1 with ``sets`` (a stream apart from the
    probe's) that each model's adjustment brings to convergence at the run's limits."""
    cfg = {**{k: f.default for k, f in TABLE1.items()}, **sets}
    pts, theta = setup(cfg)
    obs = ml.simulate_ranges(
        np.broadcast_to(pts, (trials,) + pts.shape),
        np.broadcast_to(theta, (trials, 7)),
        np.random.default_rng(seed),
        setting_sigma_um=cfg["errors.setting_sigma_um"],
        settings=cfg["errors.settings"],
        comparator_sigma_um=cfg["errors.comparator_sigma_um"],
    )
    out = {}
    for m in ("known", "stations", "pivot"):
        res = ml.adjust(obs, m, start_theta(theta, m), tol_mm=1e-10, max_iter=30, engine="numpy")
        out[m] = float((res.status == 0).mean())
    return out


@pytest.mark.parametrize("study", ["brown_table1", "brown_dilution"])
def test_brown_errors_too_large_for_the_plate_are_refused_on_load(capsys, study):
    """Errors no adjustment of the plate holds: the run's statistics were those of the
    trials that happened to converge (93 of 400), or every chunk ran before a refusal."""
    big = ("errors.setting_sigma_um=1e4", "errors.comparator_sigma_um=1e4")
    line = one_line(capsys, main(_check(study, *big)), prefix=SIM_ERROR)
    key = "comparator" if study == "brown_table1" else "setting"  # the larger share (a tie:
    assert line.startswith(SIM_ERROR + f"errors.{key}_sigma_um: "), line  # dilution's 1 setting)
    assert "probe plates of the run's error model" in line and "do not converge" in line, line
    small = ("errors.setting_sigma_um=300", "errors.comparator_sigma_um=300", "plate.spacing_mm=1")
    line = one_line(capsys, main(_check(study, *small)), prefix=SIM_ERROR + "plate.spacing_mm: ")
    assert "changed from their paper or nominal values: plate.spacing_mm" in line, line
    # the paper's setup, and errors a thousand times the paper's on its plate, still run
    assert main(_check(study)) == 0
    assert main(_check(study, "errors.comparator_sigma_um=1800")) == 0
    capsys.readouterr()


@pytest.mark.parametrize(
    "study, limit, default",
    [
        ("brown_table1", "solver.max_iter=3", 30),
        ("brown_dilution", "solver.max_iter=3", 30),
        ("brown_table1", "solver.tol_mm=1e-15", 1e-10),
    ],
)
def test_brown_solver_limits_part_of_the_trials_miss_are_refused(capsys, study, limit, default):
    """A limit some trials meet and the rest do not: the run's statistics were taken over
    the trials that met it (a selection of them); the key is named, not the errors."""
    key = limit.split("=")[0]
    line = one_line(capsys, main(_check(study, limit)), prefix=SIM_ERROR + f"{key}: ")
    assert "probe plates of the run's error model" in line, line
    assert line.endswith(
        f"(they do at its default {default:g}): the run's statistics would be those of the trials that happened to converge"
    ), line
    assert main(_check(study, "solver.max_iter=4")) == 0
    capsys.readouterr()


def test_the_refused_errors_fail_trials_of_the_run_and_the_accepted_do_not():
    """The property the refusal stands on, on trials of another stream than the probe's:
    the refused configurations leave many trials unconverged, the accepted none."""
    big = _converged({"errors.setting_sigma_um": 1e4, "errors.comparator_sigma_um": 1e4})
    assert big["known"] > 0.5 and big["stations"] < 0.9 and big["pivot"] < 0.5, big
    small = {"errors.setting_sigma_um": 300.0, "errors.comparator_sigma_um": 300.0}
    assert _converged({**small, "plate.spacing_mm": 1.0})["stations"] < 0.9
    ok = _converged({"errors.comparator_sigma_um": 1800.0})
    assert ok == {"known": 1.0, "stations": 1.0, "pivot": 1.0}, ok


@pytest.mark.parametrize(
    "study, sets, keys",
    [
        (
            "gridplate_two_plates",
            ("region.points=65536", "region.rounds=6", "region.draws=1e6"),
            "region.points, region.rounds or region.draws",
        ),
        (
            "gridplate_two_plates",
            ("region.points=65536", "region.rounds=6", "region.iter_calibrations=64"),
            "region.points, region.rounds or region.iter_calibrations",
        ),
        (
            "agnard_block_104",
            ("region.points=64", "region.trials=1e6"),
            "region.points or region.trials",
        ),
        (
            "agnard_block_104",
            ("table1.points=256", "table1.trials=1e4", "table1.rounds=5"),
            "table1.points, table1.rounds or table1.trials",
        ),
    ],
)
def test_a_region_over_the_work_limit_names_its_keys(capsys, study, sets, keys):
    """A region's work over the limit: the refusal named no key of it."""
    argv = _check(study, *sets) + ["--max-adjustments", "4e8"]
    line = one_line(capsys, main(argv), "over the limit of 4e+08 adjustments", prefix=SIM_ERROR)
    assert f"SIM_MAX_ADJUSTMENTS); change {keys}, which hold most of it, or reduce" in line, line
    # the trials' work over the limit names no key of the region
    argv = _check(study, "trials=1e6", "chunk=10") + ["--max-adjustments", "1e5"]
    line = one_line(capsys, main(argv), "over the limit of 1e+05 adjustments", prefix=SIM_ERROR)
    assert "region." not in line and "table1." not in line, line
