"""Helper j51 (session 52's J52): the last session's left items, each a bad (or wrongly
refused) input through one door, each test failing on the code before its fix.

* brown_dilution's bias-invariance constant of either sign: ``checks.bias_shift_um = -100``
  (ranges read short, as valid an additive constant as +100) was refused ("must be >= 1");
  a negative constant that reads the shortest range below 0 (-100 mm) was then run and the
  paper's "precisely the same x_j, y_j" scored "holds" over 0 Monte-Carlo plates (no shifted
  adjustment converged). Now |shift| >= 1 um, and a negative one keeps every reading >= 0.
* A note (``sim.standard_error.say``: "resuming", "note: ...") naming a path with a non-ASCII
  character to a strict-ASCII standard error (``PYTHONIOENCODING=ascii:strict``) raised
  ``UnicodeEncodeError``, a traceback in place of the note; a path's terminal control codes
  reached the terminal raw (one-line errors escaped them). Both are escaped now
  (:func:`sim.escapes.printable`, moved below every layer that prints).
* A quoted pattern whose directory cannot be read (``chmod 000 d; sim check 'd/*.toml'``)
  read "a pattern that matched no file", of a directory that may hold the files; a pattern in
  a directory that does not exist read the same. Each names its directory now.
* A GNU Gama file whose DOCTYPE declares a harmless attribute default (``<!ATTLIST gama-local
  xmlns CDATA #FIXED "...gama-local">``, which gama-local 2.03 reads; or a default no element
  lacks) was refused as every default was. It is read now; a default that gives an element a
  value it does not write (another namespace, a stdev) is still refused.
* A run.json of this code whose ``files`` list was emptied (or made null) by hand was read as
  the run's, and ``sim report`` re-filled it with README.md alone: the run's own tables and
  export then read as the user's (a re-run refused its own ``network.xml``). The readers
  (show, report, ``sim.Results``) refuse it now, as a record with its sha256s removed is
  (J50's forged-record rule), naming run.json and the table the list does not name.
* ``output.inner_over`` over one point beside a fixed point (one fixed point, an inner datum
  over the others) was refused, "cannot fix the network's 3 datum defects", though the point
  holds the one defect the fixed point leaves (the rotation about it), and ``compare.fix``
  over the same point was accepted (N51). The two agree now: the inner datum removes the
  defects the fixed points leave when its points cannot hold every free-network defect
  (named "... (about the fixed points)"); points that hold neither are still refused.
* A claim note edited into ``claims.parquet`` with terminal control codes (its record forged to
  match) was escaped by ``sim show`` only: ``sim report`` wrote it raw into the results'
  README.md (``cat`` cleared the screen). REPORT.md and every README.md are escaped now.
* sim/places.py printed its notes itself ("... is not the project's studies/x.toml: writing
  to scratch/..."): a study file named ``réseau.toml`` under a strict-ASCII standard error
  ended the run in ``UnicodeEncodeError``, a closed one in ``ValueError``. Through ``say`` now.
"""

from __future__ import annotations

import io
from pathlib import Path

import pytest

import sim

ROOT = Path(__file__).resolve().parents[1]
STUDIES = ROOT / "studies"


def test_a_negative_bias_constant_is_accepted_and_one_below_the_shortest_range_refused():
    """A wrongly refused value (a negative additive constant) and a meaningless one (readings
    below 0): -100 um was refused "must be >= 1"; -100 mm then ran, and scored "holds" over
    no plate. Now -100 um loads, -100 mm and -0.5 um are refused naming the key."""
    cfg = sim.load(STUDIES / "brown_dilution.toml", checks__bias_shift_um=-100.0).config
    assert cfg["checks.bias_shift_um"] == -100.0
    with pytest.raises(sim.ConfigError) as e:
        sim.load(STUDIES / "brown_dilution.toml", checks__bias_shift_um=-1e5)
    msg = str(e.value)
    assert msg.startswith("checks.bias_shift_um: -100000 um reads the shortest range"), msg
    assert "no negative range" in msg and "\n" not in msg
    with pytest.raises(sim.ConfigError) as e:
        sim.load(STUDIES / "brown_dilution.toml", checks__bias_shift_um=-0.5)
    assert str(e.value).startswith("checks.bias_shift_um: must be >= 1 or <= -1 um"), str(e.value)


def test_a_note_to_a_strict_ascii_stderr_is_escaped_not_raised(monkeypatch):
    """An environment (stderr's encoding strict ASCII) and a hostile path (an escape
    sequence): ``say`` raised UnicodeEncodeError on ``é`` and wrote ``\\x1b[2J`` raw. Now
    both are backslash escapes, the line written whole."""
    from sim.standard_error import say

    raw = io.BytesIO()
    err = io.TextIOWrapper(raw, encoding="ascii", errors="strict")
    monkeypatch.setattr("sys.stderr", err)
    say("sim: note: /tmp/r\u00e9sultats\x1b[2J/run.json")
    err.flush()
    assert raw.getvalue() == b"sim: note: /tmp/r\\xe9sultats\\x1b[2J/run.json\n"


def test_a_pattern_in_an_unreadable_directory_names_the_directory(tmp_path, monkeypatch, capsys):
    """A path (a pattern) whose directory cannot be listed (root reads a chmod 000 directory,
    so its listing is made to fail): "a pattern that matched no file". Now the directory and
    the reason, exit 2."""
    import os

    from sim.cli import main

    d = tmp_path / "studies"
    d.mkdir()
    real = os.scandir

    def scandir(path="."):
        if Path(path) == d:
            raise PermissionError(13, "Permission denied", str(path))
        return real(path)

    monkeypatch.setattr(os, "scandir", scandir)
    assert main(["check", str(d / "*.toml")]) == 2
    err = capsys.readouterr().err
    assert f"a pattern whose directory {d} could not be read (Permission denied)" in err, err
    assert "matched no file" not in err and len(err.splitlines()) == 1


def test_a_doctype_default_that_changes_nothing_is_read(tmp_path):
    """A GNU Gama file (a harmless DOCTYPE): ``#FIXED`` xmlns of gama-local's own namespace on a
    root without one (gama-local 2.03 adjusts it) and a distance stdev default every distance
    overrides were refused "attribute defaults are not read". Now read; a default namespace
    of another URI (gama-local: "bad namespace") is still refused, naming it."""
    from gama_triangle import triangle

    from sim.studies.network.gama_read import read_gama

    ns = '<gama-local xmlns="http://www.gnu.org/software/gama/gama-local">'
    fixed = '<!ATTLIST gama-local xmlns CDATA #FIXED "http://www.gnu.org/software/gama/gama-local">'
    for decl in (fixed, '<!ATTLIST distance stdev CDATA "5">'):
        text = triangle().replace(ns, "<gama-local>" if "xmlns" in decl else ns)
        p = tmp_path / "net.xml"
        p.write_text(text.replace("?>\n", f"?>\n<!DOCTYPE gama-local [{decl}]>\n", 1))
        assert [q["name"] for q in read_gama(p)["network.points"]] == ["A", "B", "C"]
    other = fixed.replace("software/gama/gama-local", "x")
    p.write_text(
        triangle()
        .replace(ns, "<gama-local>")
        .replace("?>\n", f"?>\n<!DOCTYPE gama-local [{other}]>\n", 1)
    )
    with pytest.raises(sim.ConfigError, match="gives <gama-local> attribute 'xmlns' the default"):
        read_gama(p)


def test_a_run_record_whose_files_list_was_emptied_is_refused(tmp_path, tiny_run, capsys):
    """A results directory touched by hand (run.json's ``files`` emptied): ``sim show`` read
    it as the run's and ``sim report`` wrote ``files = ["README.md"]`` into it. Now each
    refuses naming run.json and claims.parquet, exit 2, and run.json is left as it was."""
    import json
    import shutil

    from sim.cli import main

    out = tmp_path / "results" / "network_plate"
    shutil.copytree(tiny_run("network_plate"), out)
    rec = out / "run.json"
    rec.write_text(json.dumps({**json.loads(rec.read_text()), "files": []}))
    before = rec.read_bytes()
    for argv in (["show", str(out)], ["report", "--results", str(out.parent)]):
        assert main(argv) == 2, argv
        err = capsys.readouterr().err
        assert f"{rec} is not a run record (its files list does not name claims.parquet" in err
        assert len(err.splitlines()) == 1, err
    assert rec.read_bytes() == before


ONE_FIXED = """study = "network"
trials = 40
chunk = 2
[network]
points = [ { name = "A", x_mm = 0.0, y_mm = 0.0, role = "fixed" },
           { name = "B", x_mm = 1000.0, y_mm = 0.0 },
           { name = "C", x_mm = 400.0, y_mm = 700.0 },
           { name = "D", x_mm = 900.0, y_mm = 800.0 } ]
generate = [ { kind = "distance", from = "*", to = "*", sigma_mm = 0.01 } ]
[datum]
kind = "inner"
[output]
inner_over = ["C"]
"""


def test_inner_over_one_point_beside_a_fixed_point_holds_the_rotation_about_it(tmp_path):
    """Network keys in combination (``output.inner_over`` over one point with one fixed point):
    refused, though ``compare.fix = ["C"]`` was accepted. Now it runs, and its datum is the
    one the mathematics gives: A held, C's motion about A (tangential) removed, so C's
    covariance is along the line A-C alone (its ellipse's small axis 0)."""
    import numpy as np
    import pyarrow.parquet as pq

    study = tmp_path / "one.toml"
    study.write_text(ONE_FIXED)
    sim.load(study).run(tmp_path / "r", figures=False)
    d = pq.read_table(tmp_path / "r" / "datums.parquet").to_pydict()
    assert set(d["datum"]) == {"inner over C (about the fixed points)"}
    sx, sy = (dict(zip(d["point"], d[k])) for k in ("sigma_x_mm", "sigma_y_mm"))
    assert sx["A"] == sy["A"] == 0.0 and sx["B"] > 1e-3
    u = np.array([400.0, 700.0]) / np.hypot(400.0, 700.0)  # A-C, radial
    assert sx["C"] ** 2 / sy["C"] ** 2 == pytest.approx((u[0] / u[1]) ** 2, rel=1e-6)
    with pytest.raises(sim.ConfigError, match="output.inner_over: the points A cannot fix"):
        sim.load(study, output__inner_over=["A"])  # the fixed point holds no rotation about it


def test_a_note_with_control_codes_is_escaped_in_the_readme(tmp_path, tiny_run):
    """A table touched by hand, its record forged to match (a note holding ``\\x1b[2J``):
    written raw into README.md by ``sim report``. Now escaped there and in REPORT.md."""
    import hashlib
    import json
    import shutil

    import pyarrow as pa
    import pyarrow.parquet as pq

    from sim.cli import main
    from sim.mc.table_shape import shape

    out = tmp_path / "results" / "network_plate"
    shutil.copytree(tiny_run("network_plate"), out)
    t = pq.read_table(out / "claims.parquet")
    notes = t.column("note").to_pylist()
    notes[0] = "cleared\x1b[2J here"
    t = t.set_column(
        t.column_names.index("note"), "note", pa.array(notes, t.schema.field("note").type)
    )
    pq.write_table(t, out / "claims.parquet")
    rec = json.loads((out / "run.json").read_text())
    rec["table_shape"]["claims.parquet"] = shape(t)
    rec["table_sha256"]["claims.parquet"] = hashlib.sha256(
        (out / "claims.parquet").read_bytes()
    ).hexdigest()
    (out / "run.json").write_text(json.dumps(rec))
    assert main(["report", "--results", str(out.parent)]) == 0
    readme = (out / "README.md").read_text(encoding="utf-8")
    assert "cleared\\x1b[2J here" in readme
    for f in (out / "README.md", out.parent / "REPORT.md"):
        assert "\x1b" not in f.read_text(encoding="utf-8"), f


def test_the_scratch_note_of_a_non_ascii_study_file_is_said_not_raised(tmp_path, monkeypatch):
    """An environment (strict-ASCII or closed stderr) and a path (``réseau.toml``, not the
    project's): ``default_out``'s note raised UnicodeEncodeError (closed: ValueError), a
    traceback before the run. Now the note is escaped (or dropped) and the scratch place
    returned."""
    from sim.places import default_out

    cfg = {"study": "network"}
    raw = io.BytesIO()
    err = io.TextIOWrapper(raw, encoding="ascii", errors="strict")
    monkeypatch.setattr("sys.stderr", err)
    path = tmp_path / "r\u00e9seau.toml"
    at, shown, overwrite = default_out(cfg, {}, path)
    err.flush()
    assert overwrite and "scratch" in shown
    assert b"r\\xe9seau.toml is not the project's studies/r\\xe9seau.toml" in raw.getvalue()
    err.close()
    assert default_out(cfg, {}, path)[2]
