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
  (:func:`sim.studies.agnard.strips.check_strip_overlap`).
* ``agnard_block``: a narrow sidelap (0.1 to 0.14 at ``block.usable = 0.92``) where no
  pass-point row lies in two strips: the region's five-point control leaves the block
  singular at any weight, and it was refused naming ``weights.control_z`` at the paper's
  weights, "keep the ratio above about 6.8e+07". The weights are tried at 1000 times the
  paper's first; singular there, the block is refused naming ``block.sidelap``
  (:func:`sim.studies.agnard.datum.check_datum`, :func:`sim.studies.agnard.strips.tie_words`).
"""

from pathlib import Path

import pytest

import sim
from sim.cli import main
from tests.oneline import SIM_ERROR, one_line

ROOT = Path(__file__).resolve().parent.parent
AGNARD = ROOT / "studies" / "agnard_block.toml"


def test_strips_that_do_not_overlap_name_the_sidelap(capsys):
    argv = ["check", str(AGNARD), "--set", "block.sidelap=0.05", "--set", "block.strips=1"]
    line = one_line(capsys, main(argv), "block.sidelap", "block.usable", prefix=SIM_ERROR)
    assert "ValueError" not in line and "relief" not in line, line
    with pytest.raises(sim.ConfigError) as e:
        sim.load(AGNARD, block__sidelap=0.3, block__usable=0.6, block__base_mm=50.0)
    assert str(e.value).startswith("block.sidelap: 0.3 with block.usable 0.6"), e.value


def test_strips_no_pass_point_ties_name_the_sidelap_not_the_weights():
    with pytest.raises(sim.ConfigError) as e:
        sim.load(AGNARD, block__sidelap=0.1)
    assert str(e.value).startswith("block.sidelap: 0.1"), e.value
    assert "lies in two strips" in str(e.value), e.value
    # a weight the engine cannot solve with is still named as the weight
    with pytest.raises(sim.ConfigError) as e:
        sim.load(AGNARD, weights__control_z=1e-12)
    assert str(e.value).startswith("weights.control_z"), e.value
