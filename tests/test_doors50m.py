"""Helper m50: unit slips and values a real instrument cannot have.

Every numeric key of every study file was set at 1e-9, 1e-3, 1e3 and 1e6 times its committed
value (and 0 and its negative) through ``sim.load``, and the accepted ones were run small
(``--trials 400``) where a claim could be scored on them; one case per class found, each
failing on the code before its fix.

* brown_dilution's range sigma a thousand times its file's (``errors.setting_sigma_um =
  1000``, a sigma in nm read as um; not printed: the study's tables are ratios to it) made
  the paper's exact prediction "a common additive constant on all ranges gives precisely the
  same x_j, y_j" **fail** (5e-8 mm against the zone of 1e-9 mm, "zero to rounding"; 2e-8 mm
  at 100 um, 1.5e-8 mm at 3 mm): the engine stops an adjustment when the remaining error it
  estimates from the contraction of the last two corrections is below ``solver.tol_mm``, and at
  range errors of 0.1-3 mm that estimate is 100 times short, so the two pivot adjustments the
  check compares stopped 1e-8 mm from their (equal) solutions. Each is now restarted twice
  from its own solution (a fresh first step, no contraction estimate): 1e-11 mm at 3 mm.
* Brown's comparator in brown_table1 and brown_dilution took a micrometer travel, a scale and
  a plate of any length (``comparator.micrometer_mm = 1000``, a travel in um read as mm: a
  metre of micrometer on the 261 mm scale, so every range-on-the-scale check passed), where
  brown_design bounds the same instrument's keys (micrometer at most 100 mm, scale 5,000 mm,
  format 2,000 mm; a 245 m format under an idealised scale was refused as "plate.grid: the
  pivot model ... cannot be solved"). The same bounds now hold in all three studies.
* brown_dilution's bias-invariance check took a constant of 0 (or 1e-7 um): it compared an
  adjustment with itself and scored the paper's prediction "holds", a claim that could not
  fail. The constant is now at least 1 um (a million times the claims' zone).
* gridplate_two_plates with its sigmas in metres (1.2e-06 for 1.2 um): its iterations stopped
  at ``analysis.iter_tol_um`` (0.001 um), a thousand times the errors, and its closed-form
  self-check failed. A sigma under ten times the tolerance is refused now, naming it.
"""

from __future__ import annotations

from pathlib import Path

import pytest

import sim
from sim.mc.runner import chunk_rng
from sim.studies.brown.core import SIM_KEYS, chunk
from sim.studies.brown.schema import DILUTION, setup

ROOT = Path(__file__).resolve().parent.parent
STUDIES = ROOT / "studies"


def test_brown_bias_invariance_holds_at_a_range_sigma_a_thousand_times_the_file_s():
    """A range sigma 1000x brown_dilution's (a unit slip, an allowed value): the bias
    check's two pivot adjustments stopped 5e-8 mm apart on the engine's contraction estimate,
    and the paper's exact "precisely the same x_j, y_j" was scored as failing."""
    cfg = {k: f.default for k, f in DILUTION.items()}
    cfg["errors.setting_sigma_um"] = 1000.0
    pts, theta = setup(cfg)
    out = chunk(
        chunk_rng(1968, 0, 5),  # a chunk with such a trial (2.9e-8 mm before)
        8,
        sim={k: cfg[k] for k in SIM_KEYS},
        pts=pts,
        theta=theta,
        shift_um=cfg["checks.bias_shift_um"],
    )
    assert out["bias.n"][0] == 8
    # the claims' zone: 1e-9 mm
    assert out["bias.max_point_shift_mm"][0] < 1e-9, out["bias.max_point_shift_mm"]
    assert out["bias.alpha_err_mm"][0] < 1e-9, out["bias.alpha_err_mm"]


@pytest.mark.parametrize(
    "study, key, value, bound, more",
    [
        ("brown_table1", "comparator.micrometer_mm", 1000.0, "100", {}),
        ("brown_dilution", "comparator.scale_length_mm", 261000.0, "5000", {}),
        # an idealised comparator (scale 0) with a 245 m plate: it blamed plate.grid's geometry
        ("brown_dilution", "plate.format_mm", 245000.0, "2000", {"comparator.scale_length_mm": 0}),
    ],
)
def test_brown_comparator_lengths_beyond_the_instrument_are_refused(study, key, value, bound, more):
    """A length of Brown's comparator a thousand times the paper's (a unit slip: the
    micrometer, the scale or the format in um): accepted by brown_table1 and brown_dilution (a
    1 m micrometer let every range fit the scale), refused by brown_design."""
    with pytest.raises(sim.ConfigError) as e:
        sim.load(STUDIES / f"{study}.toml", **{key: value}, **more)
    msg = str(e.value)
    assert msg.startswith(f"{key}: must be <= {bound}"), msg
    assert "\n" not in msg


@pytest.mark.parametrize("value", [0.0, 1e-7])
def test_brown_bias_check_with_no_constant_is_refused(value):
    """``checks.bias_shift_um = 0`` (or 1e-7 um, a constant in mm read as um at 1e-9x): the
    check compared the pivot adjustment with itself (or moved it by less than its claims'
    zone of 1e-9 mm), so the paper's "precisely the same x_j, y_j" held whatever the model:
    a claim that could not fail, scored "holds"."""
    with pytest.raises(sim.ConfigError) as e:
        sim.load(STUDIES / "brown_dilution.toml", checks__bias_shift_um=value)
    assert str(e.value).startswith("checks.bias_shift_um: must be >= 1"), str(e.value)


def test_gridplate_sigmas_in_metres_are_refused():
    """gridplate's printed sigmas written in metres (``1.2e-06`` for 1.2 um; every sigma a
    millionth): accepted, its re-weighting iterations stopped at analysis.iter_tol_um =
    0.001 um, a thousand times the errors, and the self-check twoplate.self_check.closed_form
    failed (3.5e-5 against 1e-6) on a run whose README called the affine sigma "0.0000 um"."""
    sigmas = {
        "readings.sigma_um": 1.5e-6,
        "comparator.coord_sigma_um": 1.2e-6,
        "grid.sigma_true_um": 7e-7,
        "grid.sigma_stated_um": 7e-7,
    }
    with pytest.raises(sim.ConfigError) as e:
        sim.load(STUDIES / "gridplate_two_plates.toml", **sigmas)
    msg = str(e.value)
    assert msg.startswith("grid.sigma_stated_um: grid.sigma_stated_um = 7e-07 um is under ten"), msg
    assert "analysis.iter_tol_um = 0.001 um" in msg and "\n" not in msg
