"""Key combinations on the five paper studies (brief P39: salsig_encoders,
gridplate_two_plates, wolf_polynomial, agnard_block, brown_design), tried as pairs and triples
of legal keys at extreme or interacting values through ``sim check`` and small runs. One case
each; each failed on the code before its fix.

* ``agnard_block``: ``block.sidelap`` with ``block.usable`` (each inside its bounds) whose sum
  is not above 1: adjacent strips' measured areas do not overlap, and the signalised points
  between them lie in no model. The block builder's ``ValueError`` was named as
  ``block.relief_m`` ("lower the relief", the relief at its default), and reached ``sim check``
  as a bare ``ValueError:`` line, naming no key, from the trade-off's blocks of several strips
  even with ``block.strips = 1``. It is refused naming ``block.sidelap`` and ``block.usable``
  (:func:`sim.studies.agnard.strips.check_strip_overlap`); strips that overlap but that a
  relief of 200 m parts in a compared block (``block.sidelap = 0.1``) name ``block.relief_m``
  and that block (:func:`sim.studies.agnard.centre.check_centre_points`).
* ``agnard_block``: a narrow sidelap (0.1 to 0.14 at ``block.usable = 0.92``) where no
  pass-point row lies in two strips: the region's five-point control leaves the block
  singular at any weight, and it was refused naming ``weights.control_z`` at the paper's
  weights, "keep the ratio above about 6.8e+07". The weights are tried at 1000 times the
  paper's first; singular there, the block is refused naming ``block.sidelap``
  (:func:`sim.studies.agnard.datum.check_datum`, :func:`sim.studies.agnard.strips.tie_words`).
* ``gridplate_two_plates``: ``trials`` (from 2) below what the order-statistic interval of
  the self-check ``twoplate.self_check.affine_sigma_analytic`` needs: its indices were clipped
  to the sample, so at ``trials = 2, chunk = 1`` the median affine sigma of two calibrations
  took [min, max] as its 95 % interval (it covers the median half the time), and the run
  printed "self-check (fails)" on it ([-0.098, -0.024] against the analytic sigma's [-0.02,
  0.02]); at 6 trials the interval [x(2), x(6)] covered it 87.5 % of the time. The median's
  interval is now the one that covers it at 95 % at least
  (:func:`sim.studies.gridplate.claims.median_ci`), and fewer than the 6 trials it needs are
  refused on load, naming ``trials`` and the self-check.
"""

from pathlib import Path

import numpy as np
import pytest

import sim
from sim.cli import main
from sim.studies.gridplate.claims import median_ci
from tests.oneline import SIM_ERROR, one_line

ROOT = Path(__file__).resolve().parent.parent
AGNARD = ROOT / "studies" / "agnard_block.toml"
GRID = ROOT / "studies" / "gridplate_two_plates.toml"


def test_strips_that_do_not_overlap_name_the_sidelap(capsys):
    argv = ["check", str(AGNARD), "--set", "block.sidelap=0.05", "--set", "block.strips=1"]
    line = one_line(capsys, main(argv), "block.sidelap", "block.usable", prefix=SIM_ERROR)
    assert "ValueError" not in line and "relief" not in line, line
    with pytest.raises(sim.ConfigError) as e:
        sim.load(AGNARD, block__sidelap=0.3, block__usable=0.6, block__base_mm=50.0)
    assert str(e.value).startswith("block.sidelap: 0.3 with block.usable 0.6"), e.value
    # overlapping strips that the relief parts: a compared block's builder named its key too
    with pytest.raises(sim.ConfigError) as e:
        sim.load(AGNARD, block__strips=1, block__sidelap=0.1, block__relief_m=200.0)
    assert str(e.value).startswith("block.relief_m: the 6 x 24 block compared"), e.value


def test_strips_no_pass_point_ties_name_the_sidelap_not_the_weights():
    with pytest.raises(sim.ConfigError) as e:
        sim.load(AGNARD, block__sidelap=0.1)
    assert str(e.value).startswith("block.sidelap: 0.1"), e.value
    assert "lies in two strips" in str(e.value), e.value
    # a weight the engine cannot solve with is still named as the weight
    with pytest.raises(sim.ConfigError) as e:
        sim.load(AGNARD, weights__control_z=1e-12)
    assert str(e.value).startswith("weights.control_z"), e.value


def test_a_median_of_too_few_calibrations_is_refused_not_failed(capsys):
    argv = ["check", str(GRID), "--set", "trials=2", "--set", "chunk=1"]
    one_line(capsys, main(argv), "trials", "affine_sigma_analytic", prefix=SIM_ERROR)
    # the interval covers the median at 95 % at least: six values give [x(1), x(6)]
    # (96.9 %; quantile_ci gave [x(2), x(6)], 87.5 %), five none
    assert median_ci(np.arange(6.0))[1] == (0.0, 5.0)
    with pytest.raises(sim.StudyError):
        median_ci(np.arange(5.0))
    assert main(["check", str(GRID), "--set", "trials=6", "--set", "chunk=1"]) == 0
    capsys.readouterr()
