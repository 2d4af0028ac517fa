"""Review of the session ending 62e2e50b (brief R35: the diff bcd59378..62e2e50b read for
defects); one case each, each failed on the code before its fix.

* A ``run.json`` whose ``overrides`` were edited by hand to hold a lone surrogate in a value
  (``"plate.pattern=\\"\\ud800\\""`` in JSON) passed :func:`sim.mc.overrides.replayable` (it
  reads back as the text a run writes) and ``make verify`` ended in a UnicodeEncodeError
  traceback while building the re-run's command line. Such an override is now refused as
  the other hand-edited ones are: the study fails in one line naming the entry and the
  file, and nothing is re-run.
* ``sim.load(path, trials=np.timedelta64(40, "s"))`` was a TypeError traceback (NumPy counts a
  timedelta64 as an integer, whose ``int()`` fails), and ``np.timedelta64(40, "ns")`` or
  ``np.datetime64(40, "ns")`` (whose ``.item()`` is an int) ran 40 trials without a word; a
  nearby input of last session's dates and times given to the API. Each is now refused naming
  the key, as a date is (:func:`sim.mc.pyvalue.as_config_value`).
* A pyarrow timestamp or duration in nanoseconds that are not whole microseconds (a scalar, an
  array, a column) was a ValueError traceback of ``sim.load`` ("not safely convertible to
  microseconds"): now one line naming the key and the value's type.
* A network record given to the API with a key that is not a string (``{"name": "P", ...,
  1: 2.0}``, which no study file can hold) was a TypeError traceback: last session's guess
  of a misspelt field read the key as text (``normalize() argument 2 must be str``); with a
  string key beside it, sorting the unknown fields failed; in ``datum.constraints`` it was an
  AttributeError. A dict's keys must now be strings, refused naming the config key.
* ``make verify`` of results made with an override the re-run now refuses in one of its
  entries (``network.points``, refused as ``network.points[3].role: must be one of ...``: a
  study file or code changed since the run, or a ``run.json`` edited) said only "the re-run
  exited with 2" (the refusal on standard error, not in the study's lines), and with
  ``--trials`` ended in exit 2 blaming verify's own options ("the re-run refused its
  options"): only a refusal naming the override's key itself was known as the override's.
  An entry or a field of an override's key is now the override's too ("the run's overrides
  no longer apply ..."), as in 33v.
* An option typed with a word processor's dash where argparse takes it for a file (``sim run
  —trials 40 x.toml``: the study file; ``python -m sim.batch —jobs 2 x.toml``: two study
  files) was answered "unrecognized arguments: 40 x.toml" (the study file named as the
  unrecognized one), or "—jobs: no such study file" and "2: no such study file": lead33's
  guess (``did you mean --trials? U+2014 EM DASH is no hyphen``) came only when argparse left
  the word unrecognized. Such a word is now refused in one line with that guess wherever
  it stands (:class:`sim.mc.argv.BoundedParser`).
* (Older than the session, found beside it.) ``make verify --scratch DIR`` over an earlier
  re-run whose ``run.json`` lists its files as no list of paths (``"files": 5``, edited by
  hand) was a TypeError traceback; it is refused in one line naming the ``run.json``,
  nothing replaced.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pyarrow as pa
import pytest

import sim
from sim.cli import main
from sim.report.verify import main as verify_main

ROOT = Path(__file__).resolve().parent.parent
COMMITTED = ROOT / "results" / "brown_table1"
BROWN = ROOT / "studies" / "brown_table1.toml"


def _results(tmp_path: Path, overrides: list[str]) -> Path:
    """A copy of the committed brown_table1 results whose run.json records ``overrides``."""
    d = tmp_path / "R" / "brown_table1"
    shutil.copytree(COMMITTED, d, ignore=shutil.ignore_patterns("*.png", "trials"))
    rec = json.loads((d / "run.json").read_text(encoding="utf-8"))
    (d / "run.json").write_text(json.dumps({**rec, "overrides": overrides}), encoding="utf-8")
    return d.parent


def test_an_override_with_a_lone_surrogate_is_not_passed_on(tmp_path, capsys):
    results = _results(tmp_path, ['plate.pattern="\ud800"', "trials=40"])
    argv = ["--results", str(results), "--scratch", str(tmp_path / "S"), "--no-record"]
    assert verify_main(argv) == 1  # before: UnicodeEncodeError from the re-run's launcher
    out = capsys.readouterr()
    assert out.out.splitlines()[0] == "brown_table1: FAILED; nothing compared", out
    (line,) = out.out.splitlines()[1:]
    assert "its override 'plate.pattern=\"\\ud800\"' is not a value written as a run" in line
    assert "run.json" in line and "(edited by hand?): not re-run" in line
    assert "re-running" not in out.err and not (tmp_path / "S" / "brown_table1").exists()


@pytest.mark.parametrize(
    "value, words",
    [
        (np.timedelta64(40, "s"), "timedelta64(40,'s'))"),
        (np.timedelta64(40, "ns"), "timedelta64(40,'ns'))"),
        (np.datetime64(40, "ns"), "datetime64('1970-01-01T00:00:00.000000040'))"),
        (np.datetime64(40, "D"), "(got 1970-02-10)"),  # (held: a date, as TOML writes it)
    ],
)
def test_a_numpy_date_or_duration_is_no_trial_count(value, words):
    # before: a TypeError traceback (seconds), or 40 trials (nanoseconds)
    with pytest.raises(sim.ConfigError) as e:
        sim.load(BROWN, trials=value)
    line = str(e.value)
    assert line.startswith("trials: must be an integer (got ") and line.endswith(words), line


@pytest.mark.parametrize(
    "value",
    [
        pa.scalar(40, type=pa.duration("ns")),
        pa.scalar(40, type=pa.timestamp("ns")),
        pa.chunked_array([pa.array([40], type=pa.duration("ns"))]),
    ],
    ids=["duration", "timestamp", "column"],
)
def test_a_pyarrow_nanosecond_value_is_refused_in_one_line(value):
    with pytest.raises(sim.ConfigError) as e:  # before: ValueError, "not safely convertible"
        sim.load(BROWN, trials=value)
    assert str(e.value).startswith("trials: is a pyarrow "), str(e.value)
    assert "[ns] value with no Python form: not a config value" in str(e.value)


NET = """study = "network"
trials = 40
chunk = 2
[network]
points = [ { name = "A", x_mm = 0.0, y_mm = 0.0, role = "fixed" },
           { name = "B", x_mm = 400.0, y_mm = 0.0, role = "fixed" },
           { name = "C", x_mm = 400.0, y_mm = 300.0, role = "fixed" },
           { name = "P", x_mm = 150.0, y_mm = 120.0 } ]
generate = [ { kind = "distance", from = ["A", "B", "C"], to = "P", sigma_mm = 0.002 } ]
"""


@pytest.mark.parametrize(
    "key, value",
    [
        ("network.points", [{"name": "P", "x_mm": 150.0, "y_mm": 120.0, 1: 2.0}]),
        ("network.points", [{"name": "P", "x_mm": 150.0, "y_mm": 120.0, 1: 2.0, "zz": 1}]),
        ("datum.constraints", [{1: 1.0}]),
    ],
    ids=["int", "int-and-str", "constraint"],
)
def test_a_record_key_that_is_no_string_is_refused(tmp_path, key, value):
    f = tmp_path / "net.toml"
    f.write_text(NET, encoding="utf-8")
    if key == "network.points":  # the file's three fixed pillars, then the record
        value = [*sim.load(f).config["network.points"][:3], *value]
    more = {"datum.kind": "constraints"} if key.startswith("datum") else {}
    with pytest.raises(sim.ConfigError) as e:  # before: TypeError, AttributeError tracebacks
        sim.load(f, **{key: value}, **more)
    assert str(e.value) == f"{key}: a table's key must be a string (got 1)"


@pytest.mark.long
def test_an_override_refused_in_one_of_its_entries_is_named(tmp_path, capsys):
    studies, results = tmp_path / "studies", tmp_path / "R"
    studies.mkdir()
    (studies / "net.toml").write_text(NET, encoding="utf-8")
    points = (
        'network.points=[{ name = "A", x_mm = 0.0, y_mm = 0.0, role = "fixed" }, '
        '{ name = "B", x_mm = 400.0, y_mm = 0.0, role = "fixed" }, '
        '{ name = "C", x_mm = 400.0, y_mm = 300.0, role = "fixed" }, '
        '{ name = "P", x_mm = 160.0, y_mm = 120.0 }]'
    )
    run = ["run", str(studies / "net.toml"), "--set", points, "--out", str(results / "net")]
    assert main([*run, "--no-figures", "--quiet"]) == 0
    rec = json.loads((results / "net" / "run.json").read_text(encoding="utf-8"))
    assert rec["overrides"] == [points]
    # an entry the code (or the file) refuses now: a role it no longer takes
    bad = points.replace("y_mm = 120.0 }", 'y_mm = 120.0, role = "fixd" }')
    (results / "net" / "run.json").write_text(json.dumps({**rec, "overrides": [bad]}))
    capsys.readouterr()
    base = ["--results", str(results), "--studies", str(studies), "--no-record"]
    for more in ([], ["--trials", "400"]):  # before: "exited with 2"; exit 2 with --trials
        argv = [*base, "--scratch", str(tmp_path / f"S{len(more)}"), *more]
        assert verify_main(argv) == 1
        out = capsys.readouterr().out.splitlines()
        assert out[0] == "net: FAILED; nothing compared", out
        assert out[1].startswith("  the run's overrides no longer apply: the re-run of "), out
        assert "(sim: error: network.points[3].role: must be one of free, fixed" in out[1], out


@pytest.mark.parametrize(
    "argv, words",
    [
        (["run", "—trials", "40", str(BROWN)], "sim run: —trials: not an option (did you mean"),
        (["check", "–set", "trials=40", str(BROWN)], "sim check: –set: not an option (did you"),
        (["run", "—trials"], "sim run: —trials: not an option (did you mean --trials?"),
    ],
)
def test_an_option_with_a_typographic_dash_taken_for_a_file_is_named(capsys, argv, words):
    assert main(argv) == 2  # before: "unrecognized arguments: 40 ...", "no such study file"
    (line,) = capsys.readouterr().err.splitlines()
    assert line.startswith(f"sim: error: {words}") and "DASH is no hyphen: type -)" in line, line


def test_a_dashed_word_given_as_an_options_value_is_left_to_it(capsys):
    # held: a --set value is its key's ("—trials: unknown key"), not an option's
    assert main(["check", str(BROWN), "--set", "—trials=40"]) == 2
    (line,) = capsys.readouterr().err.splitlines()
    assert line == "sim: error: —trials: unknown key (did you mean trials?)", line


def test_a_batch_option_with_a_typographic_dash_is_named(tmp_path, capsys):
    from sim.batch import main as batch_main

    argv = ["—jobs", "2", str(BROWN), "--results", str(tmp_path / "r")]
    assert batch_main(argv) == 2  # before: two lines, "—jobs: no such study file", "2: ..."
    (line,) = capsys.readouterr().err.splitlines()
    assert line.startswith("sim.batch: —jobs: not an option (did you mean --jobs? U+2014"), line
    assert not (tmp_path / "r").exists()


@pytest.mark.parametrize("files", [5, [1, "claims.parquet"]], ids=["int", "int-entry"])
def test_a_scratch_rerun_whose_file_list_is_no_list_is_refused(tmp_path, capsys, files):
    results = _results(tmp_path, [])
    old = tmp_path / "S" / "brown_table1"  # an earlier re-run under --scratch, edited
    shutil.copytree(results / "brown_table1", old)
    rec = json.loads((old / "run.json").read_text(encoding="utf-8"))
    (old / "run.json").write_text(json.dumps({**rec, "files": files}), encoding="utf-8")
    argv = ["--results", str(results), "--scratch", str(tmp_path / "S"), "--no-record"]
    assert verify_main(argv) == 2  # before: TypeError / AttributeError traceback
    (line,) = capsys.readouterr().err.splitlines()
    assert line.startswith(f"sim verify: error: --scratch: {old / 'run.json'} lists no files")
    assert sorted(p.name for p in old.iterdir()) == sorted(p.name for p in results.glob("*/*"))
