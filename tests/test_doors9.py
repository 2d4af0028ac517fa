"""The failure classes of the ninth sweep of bad inputs (issue 26), one case per class; each
failed on the code before its fix.

* Salsig's ``power.sigma_um = [1e300]`` (the detection-power sweep's marking sigmas) passed
  ``sim check`` and ran with exit 0 after a page of NumPy "invalid value" warnings, its power
  table NaN: the bound ``b8.sigma_um`` had (1 % of the mark array) was missing on the swept
  sigmas (the eighth sweep's overflow class, in another study);
* an option that takes one value given twice (``sim run --trials 40 --trials 60``, ``--out A
  --out B``, ``sim report --results A --results B``, ``python -m sim.batch --results A
  --results B``) ran with the last value and dropped the first without a word (the eighth
  sweep's ``--set`` class, in the options themselves).
"""

from pathlib import Path

import sim.batch
from sim.cli import main

ROOT = Path(__file__).resolve().parent.parent


def test_salsig_power_sigmas_at_the_overflow_edge_are_refused_on_load(capsys):
    study = ROOT / "studies" / "salsig_encoders.toml"
    assert main(["check", str(study), "--set", "power.sigma_um=[5.0,1e300]"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("sim: error: power.sigma_um: exceeds 1 %") and "\n" not in err, err


def test_an_option_given_twice_is_refused_not_dropped(capsys):
    # "--trials 40 --trials 60", "--out A --out B", "--results A --results B" (sim and
    # sim.batch, and the run options after sim.batch's --) ran with the last value and
    # dropped the first without a word
    study = str(ROOT / "studies" / "network_brown.toml")
    cases = [
        (main, ["run", study, "--trials", "40", "--trials", "60"], "--trials"),
        (main, ["run", study, "--workers", "1", "--workers", "1"], "--workers"),
        (main, ["report", "--results", "a", "--results", "b"], "--results"),
        (sim.batch.main, ["--results", "a", "--results", "b", study], "--results"),
        (sim.batch.main, [study, "--", "--out", "a", "--ou", "b"], "--out"),
    ]
    for fn, argv, opt in cases:
        assert fn(argv) == 2, argv
        err = capsys.readouterr().err.strip()
        assert f"argument {opt}: given twice" in err and "\n" not in err, (argv, err)
