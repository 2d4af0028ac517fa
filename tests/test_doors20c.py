"""The classes of the sweep doors20c (issue 26: the readers given results this version did not
write -- results/ of older commits, tables rewritten by other tools, run records edited, two
results directories merged by hand), one case each; each failed on the code before its fix.

* a ``run.json`` of bytes that are not UTF-8 (another tool's file where the suite keeps its run
  record) ended ``--stale-only`` (``make reproduce``) in a UnicodeDecodeError traceback;
* two results directories merged by hand (a table of another config, of older code, copied
  beside a run's ``run.json``): ``sim show``, ``sim report`` and ``Results.table`` read its
  verdicts as this run's (an old "holds" where the run says "depends"), ``--stale-only`` called
  the directory current, so ``make reproduce`` never mended it, and ``make verify`` listed
  deviations without saying why. Every table carries its run's config and code hash: a table
  whose provenance is not the run record's is named (:func:`sim.report.read.mixed_run`);
* a claims table with a claim listed twice (two tables concatenated) or with no row was read
  as it was: every count doubled, a headline claim listed twice, or "0 claims";
* the claims table of an older version (results/ of an old clone: no `verdict` column) was
  "not a claims table written by sim": the line says it is an older version's;
* an unfinished run of another code version (an older clone's staging directory) was refused
  with "run that command again to finish it", which this version cannot: the line says so;
* ``--stale-only`` called a sweep's results out of date whatever they were ("made with another
  config: sweep"): the record of a sweep holds the ``[sweep]`` table beside the config.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pyarrow as pa
import pyarrow.parquet as pq
import pytest
from conftest import tiny_overrides
from oneline import one_line

import sim
from sim.batch_checks import why_stale
from sim.cli import DOC, main
from sim.cli_args import parser
from sim.cli_run import load_run
from sim.mc.codehash import study_code_hash
from sim.mc.config import ConfigError
from sim.mc.sweep import read_sweep
from sim.report.verify.rerun import verify

ROOT = Path(__file__).resolve().parent.parent
BROWN = ROOT / "studies" / "brown_table1.toml"


def test_stale_only_names_a_run_record_that_is_not_text(tmp_path):
    d = tmp_path / "brown_table1"
    d.mkdir()
    (d / "run.json").write_bytes(b"\xff\xfe{not json")
    assert "run.json is not UTF-8 text" in why_stale(BROWN, d)


def _copy(tiny_run, tmp_path: Path) -> Path:
    d = tmp_path / "results" / "brown_table1"
    shutil.copytree(tiny_run("brown_table1"), d)
    return d


def _rewrite(p: Path, change=None, table=None) -> None:
    """Rewrite the table ``p`` (or ``table``) with its provenance changed by ``change``."""
    t = table if table is not None else pq.read_table(p)
    meta = dict(pq.read_schema(p).metadata)
    prov = json.loads(meta[b"sim.provenance"])
    if change:
        change(prov)
    meta[b"sim.provenance"] = json.dumps(prov).encode()
    pq.write_table(t.replace_schema_metadata(meta), p)


def test_a_table_of_another_run_is_not_read_as_this_runs(tiny_run, tmp_path, capsys):
    d = _copy(tiny_run, tmp_path)
    tiny = tiny_overrides("brown_table1")
    assert main(["show", str(d)]) == 0 and why_stale(BROWN, d, tiny) is None
    capsys.readouterr()

    def other_config(prov):
        prov["config"]["trials"] = 400  # a --trials 400 run's table, copied in

    _rewrite(d / "points.parquet", other_config)
    one_line(capsys, main(["show", str(d)]), "points.parquet", "another config: trials", "two runs")
    report = one_line(capsys, main(["report", "--results", str(d.parent)]), "points.parquet")
    assert "another config: trials" in report and not (d.parent / "REPORT.md").exists()
    with pytest.raises(ConfigError, match="another config: trials"):
        sim.Results(d, "brown_table1").table("points")
    assert sim.Results(d, "brown_table1").table("claims").num_rows > 0  # its own table reads
    assert why_stale(BROWN, d, tiny).startswith("points.parquet is not of the run of run.json")
    scratch = tmp_path / "scratch"
    shutil.copytree(tiny_run("brown_table1"), scratch / "brown_table1")
    [comp] = verify(d.parent, scratch, rerun=False)
    assert not comp.ok and "mixes results of two runs" in comp.failures[0]
    # a claims table of older code beside the run's record (an older clone's results)
    shutil.copy(tiny_run("brown_table1") / "points.parquet", d / "points.parquet")
    assert why_stale(BROWN, d, tiny) is None
    _rewrite(d / "claims.parquet", lambda prov: prov.update(code_hash="0" * 16))
    one_line(capsys, main(["show", str(d)]), "claims.parquet", "made by other code", "two runs")
    # a table rewritten without its provenance (pyarrow without schema metadata) is read by
    # its numbers, but is no longer called current
    shutil.copy(tiny_run("brown_table1") / "claims.parquet", d / "claims.parquet")
    pq.write_table(pq.read_table(d / "points.parquet").replace_schema_metadata(None), d / "p.x")
    (d / "p.x").replace(d / "points.parquet")
    assert main(["show", str(d)]) == 0
    assert "carries no provenance" in why_stale(BROWN, d, tiny)


def test_a_claims_table_with_a_claim_twice_or_none_is_refused(tiny_run, tmp_path, capsys):
    d = _copy(tiny_run, tmp_path)
    claims = pq.read_table(d / "claims.parquet")
    _rewrite(d / "claims.parquet", table=pa.concat_tables([claims, claims]))
    one_line(capsys, main(["show", str(d)]), "claims.parquet", "lists the claim", "twice")
    one_line(capsys, main(["report", "--results", str(d.parent)]), "twice")
    _rewrite(d / "claims.parquet", table=claims.slice(0, 0))
    one_line(capsys, main(["show", str(d)]), "claims.parquet", "holds no claim")


def test_stale_only_reads_the_record_of_a_sweep(tmp_path):
    f = tmp_path / "sweep_plate.toml"
    f.write_text(
        'study = "brown_table1"\ntrials = 200\nchunk = 10\n'
        '[sweep]\n"plate.spacing_mm" = [35.0, 45.0]\n',
        encoding="utf-8",
    )
    study, cfg = load_run(parser(DOC).parse_args(["run", str(f)]))
    sweep = read_sweep(f, study.schema)
    out = tmp_path / "sweep_plate"
    out.mkdir()
    record = {"config": {**cfg, "sweep": sweep}, "code_hash": study_code_hash("brown_table1")}
    (out / "run.json").write_text(json.dumps(record), encoding="utf-8")
    assert why_stale(f, out) is None
    record["config"]["sweep"] = {"plate.spacing_mm": [35.0]}
    (out / "run.json").write_text(json.dumps(record), encoding="utf-8")
    assert why_stale(f, out) == "made with another config: sweep"


def test_an_unfinished_run_of_another_code_version_is_not_said_to_finish(
    tiny_run, tmp_path, capsys
):
    record = json.loads((tiny_run("brown_table1") / "run.json").read_text("utf-8"))
    stage = tmp_path / ".a.partial"  # what an older clone's run, killed, leaves
    stage.mkdir()
    (stage / "run.json").write_text(json.dumps({**record, "code_hash": "0" * 16}), "utf-8")
    chunk = Path("trials", "part-0", "chunk-000000.parquet")  # its finished chunk is kept
    (stage / chunk).parent.mkdir(parents=True)
    shutil.copy(tiny_run("brown_table1") / chunk, stage / chunk)
    tiny = tiny_overrides("brown_table1")
    rc = main(["run", str(BROWN), "--out", str(tmp_path / "a"), "--quiet", *tiny])
    line = one_line(capsys, rc, "a different code version", "cannot finish it", "--overwrite")
    assert "run that command again" not in line and (stage / chunk).is_file()


def test_an_older_versions_claims_table_is_named_as_such(tmp_path, capsys):
    d = tmp_path / "brown_table1"  # results/ of an old clone: a 'holds' column, no 'verdict'
    d.mkdir()
    prov = json.dumps({"study": "brown_table1", "config": {"study": "brown_table1"}}).encode()
    t = pa.table({"claim": ["brown.x"], "value": [1.0], "holds": [True]})
    pq.write_table(t.replace_schema_metadata({b"sim.provenance": prov}), d / "claims.parquet")
    one_line(capsys, main(["show", str(d)]), "an older version's table", "run its study again")
    rc = main(["report", "--results", str(tmp_path)])
    one_line(capsys, rc, "an older version's table", "no 'verdict' column")


def test_results_of_an_older_version_that_the_report_cannot_read_say_so(tiny_run, tmp_path, capsys):
    """Results of an older clone (their config without a key this version reads) ended in
    "a table ... is not as sim wrote it (KeyError: 'region.trials'); run its study again", as
    if edited by hand: the run record's code hash names another version of the code."""
    d = tmp_path / "results" / "salsig_encoders"
    shutil.copytree(tiny_run("salsig_encoders"), d)

    def older(cfg: dict) -> None:
        del cfg["region.trials"]  # salsig's report names it (its region's simulated models)

    def older_prov(prov):
        older(prov["config"])
        prov["code_hash"] = "0" * 16

    for p in d.glob("*.parquet"):
        _rewrite(p, older_prov)
    rec = json.loads((d / "run.json").read_text())
    older(rec["config"])
    rec["code_hash"] = "0" * 16
    (d / "run.json").write_text(json.dumps(rec))
    rc = main(["report", "--results", str(d.parent)])
    err = capsys.readouterr().err
    assert rc == 2 and "made by another version of the suite's code" in err, err
    assert "make reproduce" in err and len(err.splitlines()) == 1, err


def test_a_table_too_large_for_memory_is_not_blamed_on_loading_the_libraries(
    tiny_run, tmp_path, capsys, monkeypatch
):
    """A claims table of a million rows under ``ulimit -v``: pyarrow's bare MemoryError read
    "not enough memory to load the suite and its libraries", though they had loaded."""
    d = _copy(tiny_run, tmp_path)

    def huge(*a, **k):
        raise MemoryError()

    monkeypatch.setattr("sim.cli_read.terminal_table", huge)
    err = one_line(capsys, main(["show", str(d)]), "not enough memory for this command")
    assert "load the suite" not in err


def test_verify_says_when_the_committed_results_were_made_by_other_code(tiny_run, tmp_path):
    """Only the code differs (an older clone's results): the FAILED line listed deviations
    and did not say the committed results were stale."""
    d = _copy(tiny_run, tmp_path)
    for p in d.glob("*.parquet"):
        _rewrite(p, lambda prov: prov.update(code_hash="0" * 16))
    rec = json.loads((d / "run.json").read_text())
    rec["code_hash"] = "0" * 16
    (d / "run.json").write_text(json.dumps(rec))
    t = pq.read_table(d / "points.parquet")
    col = next(n for n in t.column_names if pa.types.is_floating(t.schema.field(n).type))
    moved = pa.array([x * 1.5 + 1.0 for x in t.column(col).to_pylist()])
    _rewrite(d / "points.parquet", table=t.set_column(t.column_names.index(col), col, moved))
    scratch = tmp_path / "scratch"
    shutil.copytree(tiny_run("brown_table1"), scratch / "brown_table1")
    [comp] = verify(d.parent, scratch, rerun=False)
    assert not comp.ok and "made by other code (code hash 0000000000000000" in comp.failures[0]
    assert len(comp.failures) > 1  # the deviations follow
