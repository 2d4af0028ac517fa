"""Doors of session 46, F46: what the fuzzers found with fresh seeds and the FILE SYSTEM kind
(tests/fuzz_fs.py: a file-size limit hit mid-run, too few file descriptors, a file where a
directory is expected and the reverse at every level of the output tree).

* A staging directory whose ``trials/part-0`` is a file (not a directory): ``sim run`` said
  "sim: error: File exists: .../.out.partial/trials/part-0", naming neither the damage nor
  its remedy (a ``trials`` that is a file was named "damaged ... --overwrite" already)."""

import shutil
from pathlib import Path

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
