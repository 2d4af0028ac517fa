"""A reading of session 45's merges (brief R45), where two changes meet; each test failed on
the code before its fix.

* V44's reference of brown_dilution's self-check under ``errors.bias_um``
  (:func:`sim.studies.brown.core.spread_sigma`: the derivatives of the adjusted points by each
  of the plate's 4 n ranges, two noise-free adjustments each) met M44's work and memory
  estimate, which did not know it: it adjusted all 8 n perturbed copies of an n-point plate
  in one batch, beside an ``np.eye(4 n)`` of its steps. At 3,600 points (``plate.grid = 60``,
  ``plate.spacing_mm = 3``) with ``errors.bias_um = 10`` the reference took 150 s and 11.6 GB
  after the trials, where ``sim check`` said 59 s and 0.333 GiB for the whole run (exactly
  what it said without the bias); up to 100,000 random points are allowed. The copies now go
  in blocks (:data:`sim.studies.brown.core.SPREAD_BLOCK_RANGES`: 137 MiB traced at 400
  points became 52, the values equal to 1e-14), and the estimate counts the reference's
  adjustments (:data:`sim.mc.brown_size.BROWN_SPREAD_ADJUSTMENTS`); over the limit, the
  refusal names ``errors.bias_um`` and the plate's key.
* V44's autocorrelation time about the ensemble's mean
  (:func:`sim.instruments.ranges.autocorr.ensemble_time`) transformed a chain's every
  parameter at once: 600 to 730 bytes a walker's step (Brown's 7 parameters), where emcee's
  took 5, on top of the 316 to 514 that the estimate's
  :data:`sim.mc.workunits.BAYES_BYTES` (600) had measured with emcee's: a chain's process
  held about twice what ``sim check`` said. One parameter at a time it holds about 100 (the
  times equal to 4e-16).
"""

from __future__ import annotations

import tracemalloc

import numpy as np
import pytest

import sim
from sim.instruments.ranges.autocorr import ensemble_time
from sim.mc.brown_size import BROWN_POINTS_PER_UNIT, BROWN_SPREAD_ADJUSTMENTS
from sim.mc.config import ConfigError
from sim.mc.estimate import check_limits, estimate
from sim.studies.brown.core import spread_sigma
from sim.studies.brown.schema import setup

DILUTION = "studies/brown_dilution.toml"


def _cfg(bias: float, grid: int, spacing: float) -> dict:
    values = {"errors.bias_um": bias, "plate.grid": grid, "plate.spacing_mm": spacing}
    return sim.load(DILUTION, **values).config


def test_the_biased_reference_is_counted_in_the_estimate_and_named_over_the_limit():
    plain, biased = (estimate(_cfg(b, 60, 3.0)) for b in (0.0, 10.0))
    n = 60 * 60  # it was equal: the reference's derivatives, each of n points, are counted
    spread = BROWN_SPREAD_ADJUSTMENTS * n * n / BROWN_POINTS_PER_UNIT
    assert biased.adjustments - plain.adjustments == pytest.approx(spread, rel=1e-12)
    assert biased.adjustments > 3 * plain.adjustments  # the larger part of the run's work
    with pytest.raises(ConfigError) as e:
        check_limits(biased, max_adjustments=2e6)
    assert "errors.bias_um or plate.grid" in str(e.value)
    check_limits(plain, max_adjustments=2e6)  # the same run without the bias passes


def test_the_biased_reference_holds_memory_in_blocks_not_by_the_square_of_the_points():
    cfg = _cfg(10.0, 20, 10.0)  # 400 points
    pts, theta = setup(cfg)
    spread_sigma(pts[:9], theta, "known", 1.0, 10.0)  # compiled, outside the trace
    tracemalloc.start()
    try:
        spread_sigma(pts, theta, "known", 1.0, 10.0)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 96 * 2**20  # 137 MiB before, in one batch


def test_the_ensemble_tau_transforms_one_parameter_at_a_time():
    n, walkers = 5000, 32
    x = np.random.default_rng(45).standard_normal((n, walkers, 7))
    tracemalloc.start()
    try:
        tau = ensemble_time(x)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert tau.shape == (7,) and np.all(np.isfinite(tau))
    assert peak / (n * walkers) < 200  # bytes a walker's step: 607 before
