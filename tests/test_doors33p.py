"""Key combinations that make a printed statistic meaningless (brief P33): keys each inside
their own bounds whose combination the suite ran and printed as if it meant something. One
case each, each failed on the code before its fix.

* ``agnard_block``: ``scan.fiducial_mm`` (10 to 250 mm) above half of ``block.format_mm`` (50
  to 500 mm), e.g. the fiducials at +-250 mm on the 230 mm photo, put the four corner
  fiducials of the scanner's affine off the photo: the scanner field was evaluated outside the
  format it models and the fiducial-corrected scan errors and every claim that reads them were
  printed as findings of a scan no photo could have. It is now refused on load, naming
  ``scan.fiducial_mm`` and ``block.format_mm``.
"""

from __future__ import annotations

from pathlib import Path

import pytest

import sim
from sim.cli import main
from tests.oneline import SIM_ERROR, one_line

ROOT = Path(__file__).resolve().parent.parent
AGNARD = ROOT / "studies" / "agnard_block.toml"


def test_fiducials_off_the_photo_are_refused(capsys):
    argv = ["check", str(AGNARD), "--set", "scan.fiducial_mm=250"]
    one_line(capsys, main(argv), "scan.fiducial_mm", "block.format_mm", prefix=SIM_ERROR)
    with pytest.raises(sim.ConfigError) as e:
        sim.load(AGNARD, block__format_mm=200.0, scan__fiducial_mm=101.0)
    assert "scan.fiducial_mm" in str(e.value), e.value
    # at the format's edge the fiducials are on the photo
    assert main(["check", str(AGNARD), "--set", "scan.fiducial_mm=115"]) == 0
    capsys.readouterr()
