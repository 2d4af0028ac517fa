"""Fuzz, seeds 3701.. and the doors fuzzer's 37001126/7 and 37011126/7 (brief F37), and a new
mutation kind, BYTES (tests/fuzz_bytes.py): the raw bytes of study files, GNU Gama XML files,
Wolf's reading tables, ``run.json`` and Parquet metadata changed as editors and cut copies
change them. The seeds' cases of the earlier kinds found no new class; every class below was
found by BYTES (the fuzzer's, or the same mutations by hand on run.json, Parquet metadata and
the reports). One case each, each failed on the code before its fix.

* A row of a Wolf reading table whose plate or photo is not one of the paper's (``003`` with
  a zero-width space or a right-to-left mark in it, or any other plate) was read and left out
  of every claim without a word: plate 003's summaries were over 9 of its 10 points. It is
  now refused naming its row, line and the plate with its escapes (``plate "0\\u200b03" is
  not 003 or 005``).
* A form feed, a vertical tab, NEL (U+0085) or a line separator (U+2028) in a comment of a
  reading table split the line there (``str.splitlines``), and the rest of the comment became
  the header: "missing column(s)" of every column. A CSV line now ends at CR, LF or CRLF
  only, and such a comment is read as the same table.
* A reading table cut short was read as far as it went: cut in a quoted note, every row after
  it was dropped without a word; cut in a row, it was Python's ``float() argument must be a
  string or a real number, not 'NoneType'``. The first is now ``not a CSV table at line N
  (unexpected end of data) (a quoted cell is not closed: is the file cut short?)``, the second
  ``data row 4 (line 11) has 5 cells for the header's 9: no y_pg2_mm``. A file of over
  2,000,000 bytes, read cut there before (the rows after it dropped), is refused.
* A reading table that is not UTF-8 text was "not a text file (not UTF-8)" (no byte, no line),
  UTF-16 without its signature "a binary file"; it is now named as a study file is (``not
  UTF-8 text (byte 0xe9 at line 24: saved as Latin-1 ...)``, ``it is UTF-16``), by one helper
  (:mod:`sim.mc.text_bytes`).
* A ``run.json`` config key with a zero-width space or a right-to-left mark (edited in, or a
  table's provenance so written) was shown raw in ``--out``'s "holds results of a different
  config: plate.grid: not in that config (this run 5), plate.gr<ZWSP>id = 5" and ``sim
  show``'s "made with another config": two keys that look the same. Such a key is now named
  with its escapes (``"plate.gr\\u200bid"``).
* An ``--out`` whose ``run.json`` was there but damaged (saved in Latin-1 or UTF-16, cut
  short) was refused as holding "no sim run record (run.json)": the user looked for a file
  that is there. What the file is is now named (``a run.json that is no sim run record (it is
  not UTF-8 text ...)``). One saved with a UTF-8 signature is read as the record since H46.
* A table whose provenance (its Parquet metadata ``sim.provenance``) was edited into bytes
  that are not UTF-8 was refused in the codec's words (``'utf-8' codec can't decode byte 0xe9
  in position 2232: invalid continuation byte``), into no JSON in json's alone; the metadata
  is now named (``its metadata sim.provenance is not as sim writes it (byte 0xe9 is not
  UTF-8)``).
* A ``REPORT.md`` or a results directory's ``README.md`` the suite wrote, saved again by an
  editor that puts a UTF-8 signature before its mark (Windows Notepad), was taken for the
  user's: ``sim report`` refused (``REPORT.md was not written by sim report``) and left such a
  README.md stale without a word. The mark behind a signature is the mark (REPORT.md is
  rebuilt; since J50 a README.md whose bytes are not the ones its run recorded is the
  user's edit: kept, and named in a note, no longer stale without a word). So saved, a
  ``python -m sim.batch --timings`` file was "not a timings file of sim.batch".
* A study file whose TOML error falls on a form feed or a vertical tab (``trials =\\f40``) was
  ``Invalid value (at line 2, column 9)``, pointing at nothing visible; the character is now
  named (``the character there is '\\x0c', U+000C FORM FEED``).
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest

import sim
from sim.batch_checks import _timings_problem
from sim.cli import main
from sim.mc.config import ConfigError
from sim.studies.wolf import tables
from tests.oneline import SIM_ERROR, one_line

ROOT = Path(__file__).resolve().parent.parent
T1 = ROOT / "studies" / "data" / "wolf_table1.csv"
T3 = ROOT / "studies" / "data" / "wolf_table3.csv"
WOLF = str(ROOT / "studies" / "wolf_polynomial.toml")
TABLE1 = ROOT / "studies" / "brown_table1.toml"


def _wolf_check(capsys, which: str, path: Path, *needles: str) -> str:
    rc = main(["check", WOLF, "--set", f'{which}.file="{path}"'])
    return one_line(capsys, rc, f"{which}.file: {path}", *needles, prefix=SIM_ERROR)


@pytest.mark.parametrize("mark", ["\u200b", "\u200f"])
def test_a_reading_table_row_of_another_plate_is_refused(tmp_path, capsys, mark):
    f = tmp_path / "t1.csv"
    f.write_text(T1.read_text().replace("\n003,7,", f"\n0{mark}03,7,", 1))
    shown = f'plate "0\\u{ord(mark):04x}03" is not 003 or 005'
    _wolf_check(capsys, "table1", f, "(line ", shown)
    with pytest.raises(ConfigError, match="data row 7 "):
        tables.load_table1(f)


@pytest.mark.parametrize("ch", ["\f", "\v", "\x85", "\u2028"])
def test_a_form_feed_or_line_separator_in_a_comment_keeps_the_table(tmp_path, ch):
    f = tmp_path / "t3.csv"
    text = T3.read_text()
    assert text.startswith("# Wolf & Pearsall (1976), ")
    f.write_text(text.replace("# Wolf & Pearsall (1976), ", f"# Wolf & Pearsall{ch}(1976), ", 1))
    got, want = tables.load_table3(f), tables.load_table3(T3)
    assert all(np.array_equal(got[k], want[k]) for k in want)


def test_a_reading_table_cut_short_is_named(tmp_path, capsys):
    text = T1.read_text()
    f = tmp_path / "t1.csv"
    f.write_bytes(text[: text.index("\n005,6,") + 60].encode())  # in row 005,6's note
    assert tables.load_table1(T1)["point"].size == 20
    _wolf_check(capsys, "table1", f, "not a CSV table at line ", "a quoted cell is not closed")
    f.write_bytes(text[: text.index("\n005,6,") + 20].encode())  # in its numbers
    _wolf_check(capsys, "table1", f, "has 5 cells for the header's 9: no y_set2_mm (is the")
    f.write_bytes(text.encode() + b"#" * 2_000_000 + b"\n" + text.splitlines()[-1].encode())
    _wolf_check(capsys, "table1", f, "has over 2,000,000 bytes: not the CSV transcription")


@pytest.mark.parametrize(
    "data, needle",
    [
        (lambda t: t.replace("OCR'd", "OCR\u00e9", 1).encode("latin-1"), "byte 0xe9 at line "),
        (lambda t: t.encode("utf-16"), "not UTF-8 text (it is UTF-16, as Windows saves"),
        (lambda t: t.encode("utf-16-le"), "not UTF-8 text (it holds NUL bytes: UTF-16 or"),
    ],
)
def test_a_reading_table_not_utf8_is_named_as_a_study_file_is(tmp_path, capsys, data, needle):
    f = tmp_path / "t3.csv"
    f.write_bytes(data(T3.read_text()))
    _wolf_check(capsys, "table3", f, needle, "expected the CSV transcription")


@pytest.fixture(scope="module")
def done(tmp_path_factory) -> Path:
    """A finished tiny run of brown_table1 (about a second)."""
    out = tmp_path_factory.mktemp("f37") / "run"
    st = sim.load(TABLE1, trials=40, chunk=2, region__points=256, region__rounds=1)
    st.run(out=out, quiet=True, figures=False)
    return out


def test_a_run_json_key_with_an_invisible_character_is_escaped(done, tmp_path, capsys):
    d = tmp_path / "run"
    shutil.copytree(done, d)
    text = (d / "run.json").read_text()
    assert '"plate.grid": 5' in text
    (d / "run.json").write_text(text.replace('"plate.grid"', '"plate.gr\u200bid"'))
    rc = main(["show", str(d)])
    line = one_line(capsys, rc, 'made with another config: plate.grid, "plate.gr\\u200bid"')
    assert "\u200b" not in line
    argv = ["run", str(TABLE1), "--set", "region.points=256", "--set", "region.rounds=1"]
    rc = main([*argv, "--trials", "40", "--chunk", "2", "--out", str(d), "--no-figures"])
    line = one_line(capsys, rc, '"plate.gr\\u200bid" = 5 (no such key in this run', "--overwrite")
    assert "\u200b" not in line


@pytest.mark.parametrize(
    "edit, needle",
    [
        (lambda b: b.replace(b'"seed"', b'"s\xe9ed"'), "(byte 0xe9 is not UTF-8)"),
        (lambda b: b.replace(b'"seed"', b'"s\x00ed"'), "(Invalid control character at: "),
        (lambda b: b[: len(b) // 2], "(Unterminated string starting at: "),
    ],
)
def test_a_damaged_provenance_is_named(done, tmp_path, capsys, edit, needle):
    d = tmp_path / "run"
    shutil.copytree(done, d)
    t = pq.read_table(d / "claims.parquet")
    meta = dict(t.schema.metadata)
    meta[b"sim.provenance"] = edit(meta[b"sim.provenance"])
    pq.write_table(t.replace_schema_metadata(meta), d / "claims.parquet")
    line = one_line(capsys, main(["show", str(d)]), "claims.parquet cannot be read: its metadata")
    assert "sim.provenance is not as sim writes it " + needle in line, line
    assert "codec" not in line


def test_a_report_saved_with_a_signature_is_still_the_suites(done, tmp_path, capsys):
    top = tmp_path / "results"
    shutil.copytree(done, top / "brown_table1")
    assert main(["report", "--results", str(top)]) == 0
    for f in (top / "REPORT.md", top / "brown_table1" / "README.md"):  # Notepad's save
        f.write_bytes(b"\xef\xbb\xbf" + f.read_bytes().replace(b"\n", b"\r\n") + b"edited\r\n")
    capsys.readouterr()
    assert main(["report", "--results", str(top)]) == 0
    readme = top / "brown_table1" / "README.md"
    assert f"{readme} was changed after the run" in capsys.readouterr().err  # kept, named
    assert b"edited" in readme.read_bytes()
    f = top / "REPORT.md"
    assert f.read_bytes().startswith(b"<!-- written by ") and b"edited" not in f.read_bytes()
    timings = tmp_path / "t.json"  # a batch's --timings file so saved: "not a timings file"
    timings.write_bytes(b'\xef\xbb\xbf{"brown_table1.toml": [0, 1.5, 0.0]}\r\n')
    assert _timings_problem(str(timings)) is None


@pytest.mark.parametrize(
    "damage, needle",
    [
        (lambda b: b.replace(b'"seed"', b'"s\xe9ed"'), "(it is not UTF-8 text (byte 0xe9 at line"),
        (lambda b: b.decode().encode("utf-16"), "(it is not UTF-8 text (it is UTF-16"),
        (lambda b: b[: len(b) // 2], "(it is not JSON: "),
    ],
)
def test_a_damaged_run_json_is_named(tmp_path, capsys, damage, needle):
    d = tmp_path / "out"
    d.mkdir()
    rec = {"config": {"study": "brown_table1"}, "code_hash": "0" * 16, "seed": 1}
    (d / "run.json").write_bytes(damage(json.dumps(rec, indent=1).encode()))
    (d / "claims.parquet").write_bytes(b"x")
    rc = main(["run", str(TABLE1), "--trials", "40", "--chunk", "2", "--out", str(d)])
    line = one_line(capsys, rc, "holds files but a run.json that is no sim run record", needle)
    assert "no sim run record (run.json)" not in line
    assert (d / "claims.parquet").read_bytes() == b"x"


def test_a_run_json_saved_with_a_utf8_signature_is_read_as_the_record(tmp_path, capsys):
    # 37f named the signature as damage; since H46 the record behind it is read (an editor's
    # save), so this one is refused for what it holds: another config, the table kept
    d = tmp_path / "out"
    d.mkdir()
    rec = {"config": {"study": "brown_table1"}, "code_hash": "0" * 16, "seed": 1}
    (d / "run.json").write_bytes(b"\xef\xbb\xbf" + json.dumps(rec, indent=1).encode())
    (d / "claims.parquet").write_bytes(b"x")
    rc = main(["run", str(TABLE1), "--trials", "40", "--chunk", "2", "--out", str(d)])
    line = one_line(capsys, rc, "holds results of a different config", "--overwrite")
    assert "no sim run record" not in line, line
    assert (d / "claims.parquet").read_bytes() == b"x"


@pytest.mark.parametrize(
    "text, needle",
    [
        ("trials =\f40\n", "(the character there is '\\x0c', U+000C FORM FEED)"),
        ("trials =\v40\n", "(the character there is '\\x0b', U+000B LINE TABULATION)"),
    ],
)
def test_a_control_character_at_a_toml_error_is_named(tmp_path, capsys, text, needle):
    f = tmp_path / "s.toml"
    f.write_text('study = "brown_table1"\n' + text)
    one_line(capsys, main(["check", str(f)]), "malformed TOML: Invalid value (at line 2", needle)
