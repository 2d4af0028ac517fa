"""The items issue 26's last sessions left open (brief L31).

1. Overflows warned instead of named. agnard's control weights over ``weights.pass`` beyond a
   double (``--set weights.control_xy=1e308 --set weights.control_z=1e308 --set
   weights.pass=1e-7``) printed NumPy's "RuntimeWarning: overflow encountered in divide" and
   then blamed the control for weighing "next to nothing"; now one line naming the heaviest
   control weight and the ratio beyond a 64-bit float. brown's stations 1e200 mm out
   (``--set comparator.station_offset_mm=1e200``) printed the same kind of warning (in
   ``_within_beta``) before the line that names them; now the line alone.
4. A ``run.json`` that cannot be read (EIO) in a results directory a ``Results`` came from was
   taken for none: the check that the directory still holds the run that returned the
   Results was skipped, silently. Now one ``ConfigError`` naming the file.
5. A GNU Gama d-m-s angle whose seconds no double holds (``0-0-1e-400``) read as 0 seconds;
   now refused naming the attribute, in the words of the other numbers no double holds (and
   the Gama readers take such numbers through one helper, :func:`sim.mc.numtext.float_text`).
   And d-m-s seconds written with a negative exponent (``218-39-3.5e-1``) were split at its
   minus: "ValueError: too many values to unpack"; they are read.
6. ``--trials 1e30`` was "an integer of 31 digits is outside TOML's 64-bit range" where
   ``--set trials=1e30`` said "must be <= 1e+08 (got 1e+30)" (so ``--chunk``, ``--seed`` and
   ``make verify``'s ``--trials``): an integer option now checks its value against its key's
   own field (:func:`sim.mc.argv.integer`), in ``--set``'s words.
3. ``sim.load(...).run(out=None)`` killed outright (SIGKILL) left ``$TMPDIR/sim-<study>-XXXX/``
   forever. The name now holds the process id, and a later ``run(out=None)`` of the study
   removes the directories of dead processes it can prove are killed runs' (:mod:`sim.api_tmp`):
   never a live process's, another user's, one holding finished results or chunks a failed
   run named (marked), nor another study's.
"""

from __future__ import annotations

import errno
import json
import os
import subprocess
import sys
import tempfile
import warnings

import pytest
from conftest import ROOT
from oneline import SIM_ERROR, one_line

import sim
import sim.api
from sim import api_paths
from sim.api_tmp import KEPT
from sim.cli import main
from sim.mc import storage
from sim.report.verify.cli import _parser as verify_parser
from sim.report.verify.rules import VerifyError

AGNARD = str(ROOT / "studies" / "agnard_block.toml")
BROWN = str(ROOT / "studies" / "brown_table1.toml")


# ------------------------------------------------------------- 1. overflows named, not warned
def test_agnard_control_weight_ratio_beyond_a_double_is_named(capsys):
    args = ["check", AGNARD, "--set", "weights.control_xy=1e308"]
    args += ["--set", "weights.control_z=1e308", "--set", "weights.pass=1e-7"]
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # NumPy's RuntimeWarning is no answer
        rc = main(args)
    line = one_line(capsys, rc, prefix=SIM_ERROR)
    assert "weights.control_" in line and "beyond a 64-bit float" in line, line
    assert "next to nothing" not in line, line


def test_brown_stations_overflowing_are_named_without_a_warning(capsys):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        rc = main(["check", BROWN, "--set", "comparator.station_offset_mm=1e200"])
    line = one_line(capsys, rc, "comparator.station_offset_mm", prefix=SIM_ERROR)
    assert "ranges overflow" in line, line


# ------------------------------------------------------------- 4. an unreadable run.json named
def test_an_unreadable_run_json_is_named_not_taken_for_none(tmp_path, monkeypatch):
    (tmp_path / "run.json").write_text(json.dumps({"config": {}, "code_hash": "x"}))
    res = sim.Results(tmp_path, "brown_table1", run_sha256="0" * 64)
    real = storage.regular_text

    def eio(p):
        if str(p).endswith("run.json"):
            raise OSError(errno.EIO, "Input/output error")
        return real(p)

    monkeypatch.setattr(storage, "regular_text", eio)
    monkeypatch.setattr(api_paths, "regular_text", eio)
    with pytest.raises(sim.ConfigError) as err:
        res.names()
    assert str(err.value) == f"path: {tmp_path / 'run.json'} cannot be read (Input/output error)"


# ------------------------------------------------------------- 5. d-m-s seconds no double holds
def test_a_gama_dms_angle_whose_seconds_no_double_holds_is_refused(tmp_path, capsys):
    gama = (ROOT / "tests" / "data" / "gama" / "user_dms.xml").read_text()
    old = 'val="218-39-35.3097147244"'
    assert old in gama
    (tmp_path / "net.xml").write_text(gama.replace(old, 'val="0-0-1e-400"'))
    study = tmp_path / "net.toml"
    study.write_text(f'study = "network"\n[network]\ngama_xml = "{tmp_path}/net.xml"\n')
    line = one_line(capsys, main(["check", str(study)]), "network.gama_xml", "attribute 'val'")
    assert "'0-0-1e-400': seconds 1e-400 is too small for a 64-bit float" in line, line


def test_a_gama_dms_angle_with_an_exponent_in_its_seconds_is_read(tmp_path, capsys):
    # "218-39-353097147244e-10" was split at its exponent's minus too: "too many values to unpack"
    gama = (ROOT / "tests" / "data" / "gama" / "user_dms.xml").read_text()
    (tmp_path / "net.xml").write_text(gama.replace("35.3097147244", "353097147244e-10"))
    study = tmp_path / "net.toml"
    study.write_text(f'study = "network"\n[network]\ngama_xml = "{tmp_path}/net.xml"\n')
    assert main(["check", str(study)]) == 0, capsys.readouterr().err


# ------------------------------------------------------------- 6. --trials 1e30 in --set's words
@pytest.mark.parametrize("key", ["trials", "chunk", "seed"])
def test_an_integer_option_beyond_its_bound_is_refused_in_set_words(capsys, key):
    by_set = one_line(capsys, main(["check", BROWN, "--set", f"{key}=1e30"]), prefix=SIM_ERROR)
    by_option = one_line(capsys, main(["run", BROWN, f"--{key}", "1e30"]), prefix=SIM_ERROR)
    words = by_set.removeprefix(f"{SIM_ERROR}{key}: ")
    assert words.startswith("must be <= ") and "(got 1e+30)" in words, by_set
    assert f"argument --{key}: {words} (see sim run --help)" in by_option, by_option
    with pytest.raises(VerifyError) as err:  # make verify's --trials reads its value so too
        verify_parser().parse_args(["--trials", "1e30"])
    assert str(err.value) == "argument --trials: must be <= 1e+08 (got 1e+30)"


# ------------------------------------------------------------- 3. a killed run's temp dir cleared
def test_a_killed_runs_temporary_directory_is_cleared_by_the_next_run(tmp_path, monkeypatch):
    gone = subprocess.run(
        [sys.executable, "-c", "import os; print(os.getpid())"],
        check=True,
        capture_output=True,
        text=True,
    )
    dead, live = int(gone.stdout), os.getpid()
    made = {}
    for tag, pid, study, inside in (
        ("killed", dead, "brown_table1", ".staging/chunk-0.parquet"),
        ("live", live, "brown_table1", ".staging/chunk-0.parquet"),
        ("finished", dead, "brown_table1", "run.json"),
        ("kept", dead, "brown_table1", None),
        ("other", dead, "brown_dilution", ".staging/chunk-0.parquet"),
    ):
        d = tmp_path / f"sim-{study}-{pid}-{tag[:4]:_<8}"
        (d / study / inside if inside else d / study).parent.mkdir(parents=True)
        if inside:
            (d / study / inside).write_text("x")
        else:
            (d / KEPT).write_text("x")
        made[tag] = d
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))

    def killed(*a, **k):
        raise RuntimeError("stopped")

    monkeypatch.setattr(sim.api, "execute", killed)
    with pytest.raises(RuntimeError):
        sim.load(BROWN).run(trials=40, workers=1)
    assert not made["killed"].exists()
    assert all(made[t].exists() for t in ("live", "finished", "kept", "other"))
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(
        made[t].name for t in ("live", "finished", "kept", "other")
    )  # this run's own (empty) directory removed after its failure, as before
