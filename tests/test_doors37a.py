"""The classes of the sweep doors37a (brief A37: the Python API, every statement of
docs/python.md tried as written, argument types not tried before, its objects' life), one case
each; each failed on the code before its fix.

* A path too long for the system (a name over the file system's 255 bytes, or the whole over
  its limit: ``sim.load("a" * 5000)``, ``run(out="/tmp/<300 b>/<300 b>")``, ``sim.Results``
  of such a path, of a study name or a table name of that length) ended in pathlib's
  ``OSError: [Errno 36] File name too long`` with a traceback: pathlib's ``exists``,
  ``is_dir`` and ``glob`` raise it where they read "absent" for a name that is not there
  (:func:`sim.api_paths.too_long`); ``python -m sim.batch`` of such a study file or
  ``--results`` too (a traceback, exit 1).
* An ``os.PathLike`` of the caller's whose ``__fspath__`` raises (a ``ValueError`` of its
  own; ``TypeError``, returning bytes or an int, was refused already) passed its exception
  through ``sim.load``, ``run(out=...)`` and ``sim.Results`` as a traceback.
* An ``executor`` whose ``__eq__`` raises (an object of the caller's) ran that ``__eq__`` in
  ``executor not in ("local", "dask")``: its exception, a traceback (``workers``,
  ``scheduler`` and the flags were refused in one line already).
* ``run(workers=np.array(2))`` (a 0-d array), ``Decimal("2")``, ``Fraction(2)`` were refused
  as "must be an integer between 1 and 8 (got array(2))", where ``trials`` and ``seed`` of
  the same ``run()`` take each as the integer it is: a worker count is read as a config
  key's number is.
* A value whose ``__repr__`` raises, where the API refuses it (``trials=``, an element of
  ``plate.points``, ``executor=``, ``out=``, ``sim.load``'s path, ``sim.Results``' path and
  study, ``table()``): the refusal's line quotes it by its ``repr``, whose exception passed
  through as a traceback naming nothing; it is now one line naming the argument
  (:func:`sim.api_args._unshown`).
* ``sim.Results`` of a sweep's cell (``<sweep>/cells/<label>/``, run by the API or ``sim
  run``): ``names()`` listed ``chunks`` and ``trials``, each of which ``table()`` refused as
  "run.json is missing or not a run record, so the chunks cannot be checked" (a cell has no
  record of its own, and its sweep's records none of the cells' chunks); they are no longer
  listed, and the refusal says the directory is a sweep's cell
  (:func:`sim.api_paths.cell_chunks`).
* A file the study reads, edited after ``sim.load`` (``network.gama_xml``, Wolf's
  ``table1.file``): ``run()`` refused it ("has changed since the study was loaded"), but
  ``replace(...)`` and ``run(trials=..., seed=...)``, which load the study file again, read the
  edited file without a word, one handle running two networks (the class doors13 closed for
  the study file itself); both refuse it now (:func:`sim.api_state.check_files`).
* A very long string as a value or a key (``sim.load(f, plate__pattern="y" * 100_000)``, a
  key of that length, ``--set plate.pattern=yyy...``) was quoted whole: a refusal of one line
  of 100 KB, its key and reason lost in the scroll-back. A run of more than 200 characters
  without white space is now shown cut, with its length (:func:`sim.long_words.clipped`).
* ``Results`` whose directory another study's run replaced since (``overwrite=True``) were
  refused with the advice "read it with sim.Results(path, 'brown_table1')", which, followed,
  is refused in turn ("holds tables of 'brown_dilution'"); the line now names the study whose
  run the directory holds (:func:`sim.api_paths.another_run`).
* What the API returns and ``sim show`` prints for one directory differed without a word in
  docs/python.md: ``res.claims()``'s ``verdict`` is ``input`` or ``not applicable`` where
  ``sim show`` prints ``input (inconclusive)``, ``not applicable (holds)`` (the ``outcome``
  column in brackets), and ``Results`` raise none of the notes ``sim show`` prints (results
  of another code version, a run off the paper's setup); the page now says so.

Held (found right): every example and statement of docs/python.md, from the project's root
and (its relative study file refused in one line) from a fresh directory; bytes paths,
``__fspath__`` returning bytes or an int, pathlib subclasses, ``np.str_``; NumPy scalars and
0-d arrays for ``trials``, ``seed``, config keys and the flags; bools for integers;
``Decimal``/``Fraction`` NaN, infinite, beyond and below a double; a ``MappingProxyType`` or a
dict for a table key (refused naming its keys); generators and sets; self-referencing and
deeply nested lists; values whose ``__eq__``/``__hash__`` raise (refused by the key); keys
``comparator..beta_mm``, ``__trials``, ``trials__`` named as unknown; a handle whose study
file was edited, whose ``config`` was changed in place, or made by ``dataclasses.replace``
with another path.
"""

from __future__ import annotations

import subprocess
import sys
from decimal import Decimal
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest

import sim

ROOT = Path(__file__).resolve().parents[1]
TABLE1 = str(ROOT / "studies" / "brown_table1.toml")
RESULTS = str(ROOT / "results" / "brown_table1")


@pytest.fixture(scope="module")
def handle():
    return sim.load(TABLE1, trials=20, chunk=1)


def _refused(fn) -> str:
    with pytest.raises(sim.ConfigError) as e:
        fn()
    assert "\n" not in str(e.value)
    return str(e.value)


def test_a_path_too_long_for_the_system_is_one_line(handle, tmp_path):
    """Each path argument, a study name and a table name too long for the file system."""
    deep = str(tmp_path / "/".join(["b" * 300] * 3))
    assert _refused(lambda: sim.load("a" * 5000)).startswith("study_file: aaaa")
    assert "too long a path" in _refused(lambda: sim.load("a" * 5000 + ".toml"))
    assert "its longest name 300 bytes" in _refused(lambda: handle.run(out=deep))
    assert _refused(lambda: sim.Results(deep, "brown_table1")).startswith("path: ")
    res = sim.Results(RESULTS, "brown_table1")
    assert "has no table" in _refused(lambda: res.table("c" * 300))
    other = sim.Results(RESULTS, "b" * 300)
    assert _refused(other.names).startswith("study: ")
    p = subprocess.run(
        [sys.executable, "-m", "sim.batch", "--results", deep, TABLE1],
        capture_output=True,
        text=True,
        cwd=ROOT,
        timeout=120,
    )
    assert p.returncode == 2 and p.stderr.startswith("sim.batch: --results: "), p.stderr[-500:]
    assert len(p.stderr.splitlines()) == 1


def test_a_pathlike_whose_fspath_raises_is_one_line(handle):
    """``__fspath__`` raising a ValueError of its own: refused naming the argument."""

    class Broken:
        def __fspath__(self):
            raise ValueError("no path today")

    msg = "is not a path: os.fspath() of its Broken raised ValueError: no path today"
    assert _refused(lambda: sim.load(Broken())) == f"study_file: {msg}"
    assert _refused(lambda: handle.run(out=Broken())) == f"out: {msg}"
    assert _refused(lambda: sim.Results(Broken(), "brown_table1")) == f"path: {msg}"


def test_an_executor_whose_eq_raises_is_one_line(handle, tmp_path):
    """The caller's object as ``executor``: its ``__eq__`` is never run."""

    class Odd:
        def __eq__(self, other):
            raise RuntimeError("eq")

        __hash__ = object.__hash__

        def __repr__(self):
            return "Odd()"

    msg = _refused(lambda: handle.run(out=tmp_path / "o", executor=Odd()))
    assert msg == "executor: must be 'local' or 'dask' (got Odd())"


@pytest.mark.parametrize("count", [np.array(99), Decimal("99"), Fraction(99, 1), 99.0])
def test_workers_is_read_as_the_number_it_is(handle, tmp_path, count):
    """Any integer type is the integer (refused here for its size, not its type: before any
    work); a whole float too, as ``trials=400.0`` is 400 (the lead: ``workers=1.0`` was "must be
    an integer"), but not a fraction."""
    msg = _refused(lambda: handle.run(out=tmp_path / "o", workers=count))
    assert msg.startswith("workers: must be between 1 and ") and msg.endswith("(got 99)")
    msg = _refused(lambda: handle.run(out=tmp_path / "o", workers=1.5))
    assert msg.startswith("workers: must be an integer between 1 and ") and "(got 1.5)" in msg


def test_a_value_whose_repr_raises_is_one_line(handle, tmp_path):
    """A refusal that would quote the value names the argument instead."""

    class Mute:
        def __repr__(self):
            raise RuntimeError("no repr")

    for key, fn in [
        ("trials", lambda: sim.load(TABLE1, trials=Mute())),
        ("plate.points", lambda: sim.load(TABLE1, plate__points=[Mute()])),
        ("executor", lambda: handle.run(out=tmp_path / "o", executor=Mute())),
        ("out", lambda: handle.run(out=Mute())),
        ("study_file", lambda: sim.load(Mute())),
        ("study", lambda: sim.Results(RESULTS, Mute())),
    ]:
        msg = _refused(fn)
        assert msg.startswith(f"{key}: cannot be quoted in a message: repr() of its "), msg


def test_the_claims_table_and_sim_show_differ_as_the_docs_say():
    """``res.claims()`` gives ``verdict`` and ``outcome`` apart where ``sim show`` prints an
    input's or a self-check's ``verdict (outcome)``: docs/python.md said nothing of it, nor that
    ``Results`` raise none of ``sim show``'s notes (off the paper's setup; stale code: a
    warning since L37)."""
    from sim.report.run_summary import verdict_cell

    rows = sim.Results(RESULTS, "brown_table1").claims().to_pylist()
    for r in rows:
        cell = verdict_cell(r)
        bracketed = r["kind"] in ("input", "self-check") and r["outcome"]
        assert cell == (f"{r['verdict']} ({r['outcome']})" if bracketed else r["verdict"])
    doc = " ".join((ROOT / "docs" / "python.md").read_text().split())
    assert "its `outcome` column the rule's own outcome, which `sim show` and README.md" in doc
    assert "which `sim show` notes on standard error) are read as they are, with a" in doc


@pytest.mark.long
def test_a_sweep_cell_lists_only_the_tables_it_reads(tmp_path):
    """A sweep run by the API: a cell's ``names()`` lists no chunk dataset (its sweep records
    no sha256 of the cells' chunks), and ``table("chunks")`` says why it is not read."""
    f = tmp_path / "sweep.toml"
    f.write_text(Path(TABLE1).read_text() + '\n[sweep]\n"errors.settings" = [2, 3]\n')
    res = sim.load(f, trials=20, chunk=1).run(out=tmp_path / "o", figures=False)
    assert res.names() == ["sweep"]
    cell = sim.Results(tmp_path / "o" / "cells" / "cell0000_r0", "brown_table1")
    names = cell.names()
    assert "claims" in names and "chunks" not in names and "trials" not in names
    for name in names:
        cell.table(name)  # every one it lists is read
    msg = _refused(lambda: cell.table("chunks"))
    assert msg.startswith("table: chunks: ") and "is a cell of the sweep" in msg


def test_a_file_the_study_read_edited_since_load_is_refused_by_every_call(tmp_path):
    """``network.gama_xml`` and Wolf's ``table1.file``, edited after ``sim.load``: ``replace``
    and ``run(seed=...)`` (which load the study file again) refuse them as ``run()`` does."""
    xml = tmp_path / "net.xml"
    xml.write_text((ROOT / "tests" / "data" / "gama" / "one_fixed.xml").read_text())
    f = tmp_path / "n.toml"
    f.write_text(f'study = "network"\ntrials = 40\nchunk = 2\n[network]\ngama_xml = "{xml}"\n')
    csv = tmp_path / "t1.csv"
    csv.write_text((ROOT / "studies" / "data" / "wolf_table1.csv").read_text())
    wolf = sim.load(ROOT / "studies" / "wolf_polynomial.toml", table1__file=str(csv))
    net = sim.load(f)
    xml.write_text(xml.read_text() + "\n<!-- edited -->\n")
    csv.write_text(csv.read_text().replace("0", "1", 3))
    for h, key in ((net, "network.gama_sha256"), (wolf, "table1.sha256")):
        for call in (lambda: h.replace(seed=3), lambda: h.run(out=tmp_path / "o", seed=3)):
            msg = _refused(call)
            assert msg.startswith(f"{key}: ") and "has changed since sim.load()" in msg, msg
    assert not (tmp_path / "o").exists()


def test_a_very_long_key_or_value_is_shown_cut(capsys):
    """A string of 100,000 characters as a value or a key, by the API and by ``--set``: the
    refusal is one line of a few hundred characters, not of 100 KB."""
    from sim.cli import main

    long = "y" * 100_000
    for kw in ({"plate__pattern": long}, {"k" * 100_000: 1}):
        msg = _refused(lambda: sim.load(TABLE1, **kw))
        assert len(msg) < 400 and "characters)" in msg, msg[:300]
    assert main(["check", TABLE1, "--set", f"plate.pattern={long}"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("sim: error: plate.pattern: must be one of ") and len(err) < 400


@pytest.mark.long
def test_results_replaced_by_another_study_name_it(tmp_path):
    """Results whose directory another study's run replaced: the line names that study,
    not the advice ``sim.Results(path, study)``, which refuses that directory in turn."""
    out = tmp_path / "o"
    res = sim.load(TABLE1, trials=20, chunk=1).run(out=out, figures=False)
    dilution = str(ROOT / "studies" / "brown_dilution.toml")
    sim.load(dilution, trials=20, chunk=1).run(out=out, figures=False, overwrite=True)
    msg = _refused(res.claims)
    assert msg == (
        f"path: {out} holds a run of 'brown_dilution' now (run into it since), not the run "
        "of 'brown_table1' that returned these Results"
    )
