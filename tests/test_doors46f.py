"""Doors of session 46, F46: what the fuzzers found with fresh seeds and the FILE SYSTEM kind
(tests/fuzz_fs.py: a file-size limit hit mid-run, too few file descriptors, a file where a
directory is expected and the reverse at every level of the output tree).

* A staging directory whose ``trials/part-0`` is a file (not a directory): ``sim run`` said
  "sim: error: File exists: .../.out.partial/trials/part-0", naming neither the damage nor
  its remedy (a ``trials`` that is a file was named "damaged ... --overwrite" already).
* A sweep's staging directory whose ``cells`` is a file said "Not a directory: .../cells/
  cell0000_r0", one whose cell is a file "File exists: .../cells/cell0001_r0" after "resuming
  ... 20 finished chunks found"; both are named damaged now, ``--overwrite`` the remedy."""

import shutil
from pathlib import Path

import pytest

from sim.cli import main

ROOT = Path(__file__).resolve().parent.parent
NET = ["run", str(ROOT / "studies" / "network_brown.toml"), "--set", "trials=40"]
NET += ["--set", "chunk=2", "--quiet", "--no-figures"]


def test_a_part_of_the_staging_store_that_is_a_file_is_named_damaged(tmp_path, capsys):
    """A FILE WHERE A DIRECTORY IS EXPECTED in a staging directory (its store's ``part-0``):
    it was "File exists" of the part's path; now the staging directory is named damaged with
    the path and the remedy (``--overwrite``), which replaces it."""
    out = tmp_path / "out"
    assert main([*NET, "--out", str(out)]) == 0
    stage = tmp_path / ".out.partial"
    (stage / "trials").mkdir(parents=True)
    shutil.copy(out / "run.json", stage / "run.json")
    (stage / "trials" / "part-0").write_text("not a part\n")
    shutil.rmtree(out)
    capsys.readouterr()
    assert main([*NET, "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "damaged" in err, err
    assert f"{stage / 'trials' / 'part-0'} is not a directory" in err and "--overwrite" in err
    assert main([*NET, "--out", str(out), "--overwrite"]) == 0
    assert (out / "claims.parquet").is_file() and not stage.exists()


GAMA = ROOT / "tests" / "data" / "gama" / "one_fixed.xml"
SWEEP = f'study = "network"\ntrials = 40\nchunk = 2\n[network]\ngama_xml = "{GAMA}"\n'
SWEEP += '[sweep]\n"reliability.power" = [0.8, 0.9]\n'


@pytest.mark.parametrize("where", ["cells", "cells/cell0001_r0"])
def test_a_sweep_cell_of_the_staging_that_is_a_file_is_named_damaged(tmp_path, capsys, where):
    """A FILE WHERE A DIRECTORY IS EXPECTED in a sweep's staging directory: its ``cells`` was
    "Not a directory: .../cells/cell0000_r0", a cell "File exists: .../cells/cell0001_r0"
    (after "resuming ... 20 finished chunks found"); now the staging directory is named
    damaged with the path, and ``--overwrite`` replaces it."""
    (study := tmp_path / "sw.toml").write_text(SWEEP)
    run = ["run", str(study), "--quiet", "--no-figures", "--out", str(tmp_path / "o")]
    assert main(run) == 0
    stage = tmp_path / ".o.partial"
    (tmp_path / "o").rename(stage)
    for f in ("sweep.parquet", "README.md"):
        (stage / f).unlink()
    shutil.rmtree(stage / where)
    (stage / where).write_text("not a cell\n")
    capsys.readouterr()
    assert main(run) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "damaged" in err[0], err
    assert f"{stage / where} is not a directory" in err[0] and "--overwrite" in err[0]
    assert main([*run, "--overwrite"]) == 0
    assert (tmp_path / "o" / "sweep.parquet").is_file() and not stage.exists()
