"""The classes of the sweep doors20c (issue 26: the readers given results this version did not
write -- results/ of older commits, tables rewritten by other tools, run records edited, two
results directories merged by hand), one case each; each failed on the code before its fix.

* a ``run.json`` of bytes that are not UTF-8 (another tool's file where the suite keeps its run
  record) ended ``--stale-only`` (``make reproduce``) in a UnicodeDecodeError traceback;
"""

from sim.batch_checks import why_stale

BROWN = "studies/brown_table1.toml"


def test_stale_only_names_a_run_record_that_is_not_text(tmp_path):
    d = tmp_path / "brown_table1"
    d.mkdir()
    (d / "run.json").write_bytes(b"\xff\xfe{not json")
    assert "run.json is not UTF-8 text" in why_stale(BROWN, d)
