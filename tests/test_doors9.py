"""The failure classes of the ninth sweep of bad inputs (issue 26), one case per class; each
failed on the code before its fix.

* Salsig's ``power.sigma_um = [1e300]`` (the detection-power sweep's marking sigmas) passed
  ``sim check`` and ran with exit 0 after a page of NumPy "invalid value" warnings, its power
  table NaN: the bound ``b8.sigma_um`` had (1 % of the mark array) was missing on the swept
  sigmas (the eighth sweep's overflow class, in another study);
* an option that takes one value given twice (``sim run --trials 40 --trials 60``, ``--out A
  --out B``, ``sim report --results A --results B``, ``python -m sim.batch --results A
  --results B``) ran with the last value and dropped the first without a word (the eighth
  sweep's ``--set`` class, in the options themselves);
* ``sim run`` without ``--out`` judged the run against ``results/<study kind>``: every
  network file (kind ``network``) wrote into a new ``results/network/`` beside the committed
  ``results/network_brown/``, and ``agnard_block_104.toml`` was compared with
  ``results/agnard_block/``. It is now ``results/<file name>``, where ``make`` writes it;
* ``SIM_MAX_MEMORY_GB`` of non-ASCII digits (Arabic-Indic ``٨``) was read as 8 (the sixth
  sweep's Gama class, in an environment variable; the option refuses it).
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
        (main, ["run", study, "--seed", "1", "--seed", "1"], "--seed"),
        (main, ["report", "--results", "a", "--results", "b"], "--results"),
        (sim.batch.main, ["--results", "a", "--results", "b", study], "--results"),
        (sim.batch.main, [study, "--", "--out", "a", "--out", "b"], "--out"),
    ]
    for fn, argv, opt in cases:
        assert fn(argv) == 2, argv
        err = capsys.readouterr().err.strip()
        assert f"argument {opt}: given twice" in err and "\n" not in err, (argv, err)


def test_a_run_without_out_is_judged_against_its_own_files_results(tmp_path, monkeypatch, capsys):
    # sim run studies/network_brown.toml (no --out) wrote into a new results/network/ (the
    # study kind's name): the committed results of the file are results/network_brown/
    monkeypatch.chdir(tmp_path)
    study = tmp_path / "network_brown.toml"
    study.write_text((ROOT / "studies" / "network_brown.toml").read_text())
    committed = tmp_path / "results" / "network_brown"
    argv = ["run", str(study), "--quiet", "--no-figures", "--trials", "40"]
    assert main([*argv, "--out", str(committed)]) == 0
    assert main([*argv, "--seed", "5"]) == 0
    assert "writing to scratch/network_brown-" in capsys.readouterr().err
    assert sorted(p.name for p in (tmp_path / "results").iterdir()) == ["network_brown"]


def test_a_limit_of_non_ascii_digits_in_the_environment_is_refused(capsys, monkeypatch):
    monkeypatch.setenv("SIM_MAX_MEMORY_GB", "\u0668")
    assert main(["check", str(ROOT / "studies" / "network_brown.toml")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("sim: error: SIM_MAX_MEMORY_GB: must be a number") and "\n" not in err
