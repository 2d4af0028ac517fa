"""R33, a fresh reading of the session's change of 2026-11-28/29 (issue 26), through ``sim run``,
``sim check`` and the network's gama-local export: a run of which too few trials converge for
the jackknife over chunks (numpy warnings, then a claim named as the cause); a driver's
variable of a non-ASCII digit (a traceback); and three messages naming a key the study did
not set (a ``network.generate`` bias at ``sim check`` and in the export note, a grid prefix's
double space in the export note). Each test failed on the code before its fix."""

from __future__ import annotations

from pathlib import Path

from sim.cli import main
from tests.test_lead32 import _trilateration  # 300 random points, 8 nearest distances


def test_a_run_whose_jackknife_would_leave_one_converged_trial_names_the_network(tmp_path, capsys):
    # before: the converged trials lay in two chunks, so the estimates were formed; leaving
    # out either chunk left one trial, whose sample sigma divided by zero: three numpy
    # RuntimeWarnings on stderr, then "claim network.mc_agreement.mean_ratio: the simulated
    # value is not finite", a claim named as the cause of a network that does not converge
    f = _trilateration(tmp_path, 7000.0)
    assert main(["run", str(f), "--out", str(tmp_path / "o"), "--no-figures", "--quiet"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1, err
    assert err.startswith("sim: error: network.generate: too few trials (the jackknife"), err
    assert "converged from the true coordinates" in err and "weakest sight" in err, err
    assert not (tmp_path / "o").exists()


def test_a_drivers_variable_of_a_non_ascii_digit_is_no_traceback():
    # before: SIM_STOP_WITH_PARENT=² (a digit to str.isdigit) reached int(), and every `sim`
    # command ended in a ValueError traceback, exit 1; a value that is no pid is ignored, as
    # "yes" was
    import os
    import subprocess
    import sys

    study = Path(__file__).resolve().parents[1] / "studies" / "wolf_polynomial.toml"
    env = {**os.environ, "SIM_STOP_WITH_PARENT": "\u00b2"}
    p = subprocess.run(
        [sys.executable, "-m", "sim", "check", str(study)],
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert p.returncode == 0 and p.stderr == "", p.stderr


def test_a_gross_bias_of_a_generated_set_names_network_generate(tmp_path, capsys):
    # before: `sim check` refused it naming network.observations, a key the study did not set
    p = tmp_path / "bias.toml"
    p.write_text(
        'study = "network"\ntrials = 40\nchunk = 2\n[network]\n'
        'grids = [ { prefix = "G", nx = 4, ny = 4, spacing_mm = 100.0 } ]\n'
        'generate = [ { kind = "distance", from = "G*", to = "G*", nearest = 4, '
        "sigma_mm = 0.01, bias_mm = 40.0 } ]\n"
        '[datum]\nkind = "inner"\n',
        encoding="utf-8",
    )
    assert main(["check", str(p)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1, err
    assert err.startswith("sim: error: network.generate: none of 16 probe trials"), err
    assert "the bias of 40 mm" in err, err


def test_a_grid_prefix_with_two_spaces_is_named_as_the_grids_prefix(tmp_path):
    # before: `sim run` wrote "gama-local XML: not exported: network.points: point 'A  B1'"
    # into the README of a study that sets no network.points (its grid's prefix made the name)
    from sim.studies import load_study
    from sim.studies.network.definition import build
    from sim.studies.network.gama import export, merge_gama

    st = tmp_path / "s.toml"
    st.write_text(
        'study = "network"\ntrials = 40\nchunk = 2\n[network]\n'
        'grids = [ { prefix = "A  B", nx = 3, ny = 3, spacing_mm = 100.0 } ]\n'
        'generate = [ { kind = "distance", from = "A*", to = "A*", nearest = 4, '
        "sigma_mm = 0.01 } ]\n"
        '[datum]\nkind = "inner"\n',
        encoding="utf-8",
    )
    full = merge_gama(load_study(st)[1])
    note = export(build(full), full, tmp_path / "n.xml")
    assert note.startswith("not exported: network.grids[0].prefix: point 'A  B1'"), note
    assert not (tmp_path / "n.xml").exists()


def test_a_bias_of_a_generated_set_is_named_by_network_generate_in_the_export_note(tmp_path):
    # before: "not exported: network.observations: gama-local has no observation bias" of a
    # study that sets no network.observations (the bias was network.generate's)
    from sim.studies import load_study
    from sim.studies.network.definition import build
    from sim.studies.network.gama import export, merge_gama

    st = tmp_path / "s.toml"
    st.write_text(
        'study = "network"\ntrials = 40\nchunk = 2\n[network]\n'
        'grids = [ { prefix = "G", nx = 3, ny = 3, spacing_mm = 100.0 } ]\n'
        'generate = [ { kind = "distance", from = "G*", to = "G*", nearest = 4, '
        "sigma_mm = 0.01, bias_mm = 0.001 } ]\n"
        '[datum]\nkind = "inner"\n',
        encoding="utf-8",
    )
    full = merge_gama(load_study(st)[1])
    note = export(build(full), full, tmp_path / "n.xml")
    assert note.startswith("not exported: network.generate: gama-local has no observation"), note
