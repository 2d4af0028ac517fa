"""The classes of the sweep doors32v (brief V32: ``make verify``'s verdicts of results touched
by hand that still parse), one case each; each failed on the code before its fix.

* A committed table edited after its run wrote it (a claims table's verdict changed from
  ``holds`` to ``fails``, a table's rows reordered or one row duplicated, the provenance
  kept) was reported ``FAILED`` with its deviations, exit 1, as a failure of the code to
  reproduce it. ``run.json`` now records each table's sha256 (``table_sha256``), and verify
  says first that the tables changed after the run that wrote them, the deviations being of
  that change, not of the code.
"""

from __future__ import annotations

import shutil
import subprocess
import sys

import pyarrow as pa
import pyarrow.parquet as pq
import pytest


def _sim(*args, cwd=None):
    return subprocess.run(
        [sys.executable, "-m", *args], capture_output=True, text=True, cwd=cwd, timeout=300
    )


@pytest.mark.long
def test_a_verdict_edited_by_hand_is_said_to_be_an_edit_not_a_failed_reproduction(tmp_path):
    run = _sim(
        "sim",
        "run",
        "studies/brown_table1.toml",
        "--trials",
        "200",
        "--seed",
        "7",
        f"--out={tmp_path / 'R' / 'brown_table1'}",
        "--quiet",
        "--no-figures",
    )
    assert run.returncode == 0, run.stderr
    shutil.copytree(tmp_path / "R", tmp_path / "S")  # the "re-run": the very same tables
    f = tmp_path / "R" / "brown_table1" / "claims.parquet"
    t = pq.read_table(f)
    v = t.column("verdict").to_pylist()
    v[0] = "fails" if v[0] != "fails" else "holds"
    t = t.set_column(t.column_names.index("verdict"), "verdict", pa.array(v))
    pq.write_table(t.replace_schema_metadata(pq.read_schema(f).metadata), f)
    out = _sim(
        "sim.report.verify",
        "--results",
        str(tmp_path / "R"),
        "--scratch",
        str(tmp_path / "S"),
        "--no-rerun",
        "--no-record",
    )
    assert out.returncode == 1, out.stderr
    text = out.stdout + out.stderr  # (doors40v: the claims table's values are not its run's)
    assert "claims.parquet is not the claims table its run wrote" in text
    assert "the values of column 'verdict' are not those its run wrote" in text
    shutil.copy(tmp_path / "S" / "brown_table1" / "claims.parquet", f)  # another table edited:
    f = tmp_path / "R" / "brown_table1" / "table1_trials.parquet"  # compared, and said so
    t = pq.read_table(f)
    t = t.take(list(reversed(range(t.num_rows))))
    pq.write_table(t.replace_schema_metadata(pq.read_schema(f).metadata), f)
    out = _sim(
        "sim.report.verify",
        "--results",
        str(tmp_path / "R"),
        "--scratch",
        str(tmp_path / "S"),
        "--no-rerun",
        "--no-record",
    )
    assert out.returncode == 1, out.stderr
    text = out.stdout + out.stderr
    assert "table1_trials.parquet changed after the run that wrote them" in text
    assert "not of the code" in text
