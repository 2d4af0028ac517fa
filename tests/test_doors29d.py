"""The classes of the sweep doors29d (brief D29d: what an upgrade leaves behind -- a user who
pulls a newer version of the suite and keeps what the older one made), one case each; each
failed on the code before its fix.

* the reproducibility record of an older version (before ``tables_sha256``, 9d90f3a7) read
  "within tolerance: yes" for every study in the report, whatever tables are there now (results
  re-run at any commit since): its rows now read "not checked now: checked by an older
  version, which did not record the tables (it said yes)"; and a record that is not one (a
  truncated file, another table in its place) was blamed on the last study table the report
  had read ("wolf_polynomial/claims.parquet ... is not as sim wrote it (column 'kind':
  KeyError: 'study'); run its study again"): now one line naming the record
  (:func:`sim.report.verify.record.markdown`).
* a run killed under older code, the code pulled, then ``make reproduce`` (``sim.batch``, whose
  runs are ``--overwrite``) or ``sim run --overwrite``: the older version's chunks were dropped
  and the run started over without a word (a long agnard_block run lost, the user not told
  why). Its chunks are still never mixed with this version's (their identity holds the code
  hash), and a run without --overwrite still refuses, naming the code version; with it, one
  line says what is replaced: "sim: starting agnard_block over: its unfinished run of a
  different code version (48 chunks) is replaced, not resumed"
  (:func:`sim.mc.outputs.prepare_stage`).
* results of an older version kept after a pull, which lack a table this version reads
  (``brown_dilution`` of e48edaac~1: no ``region_inputs.parquet``): ``sim report`` and ``sim show
  --markdown`` said only "No such file or directory: .../region_inputs.parquet"; now the
  directory is named as made by another version of the code, and make reproduce as the remedy
  (:func:`sim.cli_tables.older_lacks`); a table removed by hand from this version's run is
  still the plain line.
* ``make verify`` over such results (brown_table1 of e48edaac~1, whose run wrote a table named
  ``sweep.parquet`` beside its claims) said "not verified: brown_table1 (sweeps: verify re-runs
  single studies ...)" and then compared it all the same: a study's results are not a sweep's
  (:func:`sim.report.verify.rerun.verify`, as ``sim report`` already told them apart).
"""

import json
import shutil
import subprocess
from pathlib import Path

import pyarrow as pa
import pyarrow.parquet as pq
import pytest
from conftest import tiny_command
from oneline import SIM_ERROR, one_line, one_line_of

import sim.stale as stale
from sim.cli import main
from sim.mc.outputs import stage_dir
from sim.mc.storage import read_provenance, read_record
from sim.report.verify import main as verify_main
from sim.report.verify import markdown


def _verified(tmp_path: Path, tiny_run) -> Path:
    """``results/network_plate`` of the tiny run and the record of its check by make verify."""
    results, scratch = tmp_path / "results", tmp_path / "scratch"
    for d in (results, scratch):
        shutil.copytree(tiny_run("network_plate"), d / "network_plate")
    args = ["--results", str(results), "--scratch", str(scratch), "--no-rerun"]
    assert verify_main(args) == 0
    return results


def _row(text: str, study: str) -> str:
    return next(ln for ln in text.splitlines() if ln.startswith(f"| {study} |"))


def test_an_older_versions_record_vouches_for_no_tables_there_now(tiny_run, tmp_path, capsys):
    results = _verified(tmp_path, tiny_run)
    capsys.readouterr()
    rec = results / "reproducibility.parquet"
    assert _row(markdown(results), "network_plate").endswith("| yes |  |")
    t = pq.read_table(rec)  # as the versions before 9d90f3a7 wrote it: no tables_sha256
    pq.write_table(t.drop_columns(["tables_sha256"]), rec)
    text = markdown(results)
    row = _row(text, "network_plate")
    assert "| yes |" not in row and "not checked now" in row and "older version" in row, row
    assert "(it said yes)" in row and "run make verify again" in text
    t = pq.read_table(rec)  # and one whose check failed then
    failed = t.set_column(t.column_names.index("ok"), "ok", pa.array([False]))
    failed = failed.set_column(
        failed.column_names.index("first_failure"), "first_failure", pa.array(["x: 1 != 2"])
    )
    pq.write_table(failed, rec)
    assert "not checked now" in (row := _row(markdown(results), "network_plate")), row
    assert "(it said no: x: 1 != 2)" in row


def test_a_record_that_is_not_one_is_named_not_a_study_table(tiny_run, tmp_path, capsys):
    results = _verified(tmp_path, tiny_run)
    capsys.readouterr()
    rec = results / "reproducibility.parquet"
    whole = rec.read_bytes()
    for bad, why in (
        (whole[:500], "ArrowInvalid"),  # truncated (a copy that stopped)
        (None, "it has no column 'study'"),  # another table in its place
    ):
        if bad is None:
            pq.write_table(pa.table({"a": [1]}), rec)
        else:
            rec.write_bytes(bad)
        rc = main(["report", "--results", str(results)])
        line = one_line(capsys, rc, str(rec), why, "move it away", prefix=SIM_ERROR)
        assert "claims.parquet" not in line and "run its study again" not in line, line


@pytest.mark.long
def test_an_older_versions_unfinished_run_is_not_resumed_and_says_so(tiny_run, tmp_path):
    src, out = tiny_run("brown_table1"), tmp_path / "brown_table1"
    stage = stage_dir(out)  # its run killed under older code: the same config, its chunks
    shutil.copytree(src / "trials", stage / "trials")
    rec = json.loads((src / "run.json").read_text(encoding="utf-8"))
    (stage / "run.json").write_text(json.dumps({**rec, "code_hash": "0123456789abcdef"}))
    n = sum(1 for _ in (stage / "trials").rglob("chunk-*.parquet"))
    cmd = tiny_command("brown_table1", out)
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
    one_line_of(
        p, "unfinished run of a different code version", "cannot finish it", prefix=SIM_ERROR
    )
    assert not out.exists() and (stage / "trials").is_dir()
    p = subprocess.run(cmd + ["--overwrite"], capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr
    said = f"starting brown_table1 over: its unfinished run of a different code version ({n} "
    assert said in p.stderr and "not resumed" in p.stderr and "resuming" not in p.stderr, p.stderr
    code = read_record(out)["code_hash"]
    chunks = sorted((out / "trials").rglob("chunk-*.parquet"))
    assert chunks and all(read_provenance(c)["code_hash"] == code for c in chunks)


def test_results_of_an_older_version_without_a_table_this_one_reads(
    tiny_run, tmp_path, capsys, monkeypatch
):
    results = tmp_path / "results"
    d = results / "brown_dilution"  # as a version before region_inputs.parquet wrote it
    shutil.copytree(tiny_run("brown_dilution"), d)
    (d / "region_inputs.parquet").unlink()
    rc = main(["report", "--results", str(results)])  # this version's run, removed by hand
    line = one_line(capsys, rc, "No such file or directory", "region_inputs.parquet")
    assert "another version" not in line, line
    monkeypatch.setattr(stale, "study_code_hash", lambda study: "0123456789abcdef")
    said = ("brown_dilution was made by another version", "has no region_inputs.parquet")
    rc = main(["report", "--results", str(results)])  # the code pulled since
    one_line(capsys, rc, *said, "--overwrite makes them current", prefix=SIM_ERROR)
    rc = main(["show", "--markdown", str(d)])
    one_line(capsys, rc, *said, prefix=SIM_ERROR)


def test_verify_does_not_call_a_study_with_an_older_sweep_table_a_sweep(tiny_run, tmp_path, capsys):
    results, scratch = tmp_path / "results", tmp_path / "scratch"
    for d in (results, scratch):
        shutil.copytree(tiny_run("network_plate"), d / "network_plate")
    shutil.copy(
        results / "network_plate" / "claims.parquet", results / "network_plate" / "sweep.parquet"
    )
    rc = verify_main(["--results", str(results), "--scratch", str(scratch), "--no-rerun"])
    out, err = capsys.readouterr()
    # a table run.json does not list is no table of the run's (H46): not compared, kept
    assert rc == 0 and "network_plate: ok" in out, (out, err)
    assert "not verified" not in err and "sweeps" not in err, err
    assert (results / "network_plate" / "sweep.parquet").exists()
