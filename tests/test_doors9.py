"""The failure classes of the ninth sweep of bad inputs (issue 26), one case per class; each
failed on the code before its fix.

* Salsig's ``power.sigma_um = [1e300]`` (the detection-power sweep's marking sigmas) passed
  ``sim check`` and ran with exit 0 after a page of NumPy "invalid value" warnings, its power
  table NaN: the bound ``b8.sigma_um`` had (1 % of the mark array) was missing on the swept
  sigmas (the eighth sweep's overflow class, in another study).
"""

from pathlib import Path

from sim.cli import main

ROOT = Path(__file__).resolve().parent.parent


def test_salsig_power_sigmas_at_the_overflow_edge_are_refused_on_load(capsys):
    study = ROOT / "studies" / "salsig_encoders.toml"
    assert main(["check", str(study), "--set", "power.sigma_um=[5.0,1e300]"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("sim: error: power.sigma_um: exceeds 1 %") and "\n" not in err, err
