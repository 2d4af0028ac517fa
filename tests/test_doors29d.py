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
"""

import shutil
from pathlib import Path

import pyarrow as pa
import pyarrow.parquet as pq
from oneline import SIM_ERROR, one_line

from sim.cli import main
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
        line = one_line(capsys, rc, str(rec), why, "make verify writes it again", prefix=SIM_ERROR)
        assert "claims.parquet" not in line and "run its study again" not in line, line
