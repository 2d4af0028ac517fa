"""The classes of the sweep doors44a (brief A44: the Python API's objects and the helpers
``sim`` exports, as a user writing a study of their own calls them: ``sim.write_table``,
``sim.read_provenance``, ``sim.run_chunks``, ``sim.load_study``; ``Results`` compared; a
handle across threads and processes), one case each; each failed on the code before its fix.

* ``sim.write_table`` into a directory was ``IsADirectoryError``, under a file
  ``FileExistsError``; over a file it did not write (a user's text, another tool's Parquet
  file, a symbolic link) it replaced the file without a word: only a table with the suite's
  provenance is replaced now, the rest refused naming ``path`` (:mod:`sim.api_write`).
* A provenance value JSON does not hold (a ``datetime``, ``bytes``, a set, a complex number, a
  list holding itself, a key that is not a str, NaN) was ``TypeError``/``ValueError`` from
  ``json``, or written as what no JSON reader takes (``NaN``), or as another key (``{1: 2}``
  read back as ``{"1": 2}``): one line naming ``prov`` and where in it.
* A column Arrow cannot hold (mixed types, complex numbers, a set), columns of different
  lengths, a name that is not a str, an infinite value, a tolerance naming no column or not a
  mapping: pyarrow's ``ArrowInvalid``, ``TypeError``, the storage's ``NonFiniteError`` or
  ``ValueError``; one line naming ``columns`` (``tolerances``) and the column now.
* A masked array (``np.ma``) was written as its data: the masked values as numbers. They are
  nulls.
* ``sim.read_provenance`` and ``sim.write_table`` of a FIFO blocked for good (pyarrow opened
  it): refused as not a regular file. ``sim.read_provenance`` of a symbolic-link loop or a
  link to nothing said pyarrow's "Failed to open local file ... Detail: [errno 40]", and
  returned a list for a ``sim.provenance`` key of another tool's holding one.
* Two threads of one process writing one table through ``sim.write_table`` shared one
  temporary file (``.<name>.<pid>.tmp``): one of them said "cannot be written (No such file
  or directory)". They write it one after the other.
* ``sim.run_chunks`` ran a chunk function returning too many rows (``n + 1``), concatenating
  more values than trials without a word; one returning a list, None, a scalar, Python
  objects, or other keys or shapes from chunk to chunk ended in Python's or NumPy's words
  (or pickle's, from a worker), one of one argument in Python's ``TypeError``: each is one line
  naming ``fn``. The function's own exception passes as it is, with a note naming the chunk.
* ``sim.run_chunks`` took ``quiet="no"`` (true: quiet), ``ctx=3`` (no store, no executor),
  ``label=3``, ``units="x"`` (Python's words), and ``trials=10**12`` in chunks of 1 (a list of
  10**12 sizes): each is refused naming it (at most ``MAX_CHUNKS`` chunks, as a study's run).
* ``sim.load_study`` refused ``values={"trials": np.int64(40)}`` and ``seed=np.int64(3)``
  ("must be an integer"), which ``sim.load`` takes; said ``is required`` of a value None, a
  ``TypeError`` of a key not a str; dropped one value of a key given by ``overrides`` and
  ``values`` (or ``values`` and ``trials``); named ``--set`` for a malformed override and no
  argument for a study file that is a directory.
* ``Results`` of two runs into one ``out`` (another seed) were equal (``==``, one element of a
  set), though the first is refused and the second reads: ``run_sha256`` is compared.
* ``sim.load`` of a results directory (or an empty one) said "its study files are DIR/*.toml",
  a pattern that matches nothing there: it says the directory holds a run's results (or no
  study file).

Held (found right): a chunk function that raises, in process and in a worker (its exception,
as it is); a lambda under workers (run in this process, with a note); NaN returned by a chunk
function (returned as it is: NaN may be "missing"); 0-length columns, no column at all, a
10**7-trial run in chunks of 10**6 (half a second); a handle pickled to a process of another
working directory (runs its study by its absolute path); Results pickled and read after their
directory was renamed ("no longer exists"); two threads running one handle into two outs;
``multiprocessing`` pools of ``spawn`` and ``fork`` each running a handle, and ``run(workers=2)``
after them; a handle whose study file was deleted (``run``, ``replace`` refused naming
``study_file``; ``estimate`` and ``repr`` of the loaded config).
"""

from __future__ import annotations

import datetime
import os
import threading
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

import sim
from sim.mc.runner import RunContext

ROOT = Path(__file__).resolve().parents[1]
STUDY = ROOT / "studies" / "brown_table1.toml"
PROV = {"study": "mine"}


def _refused(fn, key: str, *needles: str) -> str:
    with pytest.raises(sim.ConfigError) as e:
        fn()
    line = str(e.value)
    assert e.value.key == key and "\n" not in line, line
    assert all(n in line for n in needles), line
    return line


def test_write_table_into_a_directory_or_under_a_file_names_path(tmp_path):
    (tmp_path / "f.txt").write_text("mine")
    for p in (tmp_path, tmp_path / "f.txt" / "t.parquet"):
        _refused(lambda: sim.write_table(p, {"a": [1]}, PROV), "path", str(p))


def test_write_table_replaces_only_a_table_sim_wrote(tmp_path):
    text, other = tmp_path / "notes.txt", tmp_path / "other.parquet"
    text.write_text("mine")
    pq.write_table(pa.table({"a": [1]}), other)  # another tool's table: no provenance
    link = tmp_path / "link.parquet"
    link.symlink_to(text)
    for p in (text, other, link):
        before = p.read_bytes()
        _refused(lambda: sim.write_table(p, {"a": [2]}, PROV), "path", "sim never replaces it")
        assert p.read_bytes() == before and (p != link or link.is_symlink())
    ours = sim.write_table(tmp_path / "t.parquet", {"a": [1]}, PROV)
    sim.write_table(ours, {"a": [2]}, PROV)  # a run of one's own study again
    assert pq.read_table(ours).column("a").to_pylist() == [2]


@pytest.mark.parametrize(
    "prov, needle",
    [
        ({"when": datetime.datetime(2026, 1, 1)}, "'when' is datetime"),
        ({"raw": b"ab"}, "'raw' is bytes"),
        ({"s": {1, 2}}, "'s' is set"),
        ({"z": 1j}, "'z' is complex"),
        ({"x": {"y": float("nan")}}, "'x'['y'] is nan"),
        ({"x": np.float64("inf")}, "'x' is inf"),
        ({1: 2}, "1: a key must be a str, not an int"),
        ({"d": np.array(["2020-01-01"], dtype="datetime64[D]")}, "'d'[0] is date"),
    ],
)
def test_write_table_names_a_provenance_value_json_does_not_hold(tmp_path, prov, needle):
    _refused(lambda: sim.write_table(tmp_path / "t.parquet", {"a": [1]}, prov), "prov", needle)
    assert not (tmp_path / "t.parquet").exists()


def test_write_table_names_a_provenance_that_holds_itself(tmp_path):
    loop: list = []
    loop.append(loop)
    _refused(lambda: sim.write_table(tmp_path / "t.parquet", {"a": [1]}, {"x": loop}), "prov")
    ok = {"n": np.int64(3), "v": np.arange(2.0), "p": Path("x")}  # converted as the storage does
    assert sim.read_provenance(sim.write_table(tmp_path / "t.parquet", {"a": [1]}, ok)) == {
        "n": 3, "v": [0.0, 1.0], "p": "x"}  # fmt: skip


@pytest.mark.parametrize(
    "columns, tolerances, key, needle",
    [
        ({"a": [1, "x"]}, None, "columns", "column 'a' cannot be stored"),
        ({"a": np.array([1j])}, None, "columns", "column 'a'"),
        ({"a": {1, 2}}, None, "columns", "column 'a' is a set"),
        ({"a": [1, 2], "b": [1]}, None, "columns", "columns differ in length"),
        ({1: [1]}, None, "columns", "a column's name must be a str"),
        ({"a": [np.inf]}, None, "columns", "column a is inf"),
        ({"a": [1.0]}, {"b": {"kind": "exact"}}, "tolerances", "tolerance of b: no such column"),
        ({"a": [1.0]}, {"a": 3}, "tolerances", "'a' must map to a rule"),
    ],
)
def test_write_table_names_a_column_arrow_cannot_hold(tmp_path, columns, tolerances, key, needle):
    p = tmp_path / "t.parquet"
    _refused(lambda: sim.write_table(p, columns, PROV, tolerances), key, needle)
    assert not p.exists()


def test_write_table_writes_a_masked_value_as_null(tmp_path):
    a = np.ma.masked_array([1.0, 2.0, 3.0], mask=[True, False, True])
    p = sim.write_table(tmp_path / "t.parquet", {"a": a}, PROV)
    assert pq.read_table(p).column("a").to_pylist() == [None, 2.0, None]


def test_read_provenance_and_write_table_of_a_fifo_do_not_block(tmp_path):
    fifo = tmp_path / "t.parquet"
    os.mkfifo(fifo)
    for call in (lambda: sim.read_provenance(fifo), lambda: sim.write_table(fifo, {"a": [1]}, {})):
        got: list = []
        t = threading.Thread(target=lambda: got.append(_refused(call, "path", "not a regular")))
        t.start()
        t.join(20)
        if t.is_alive():  # blocked in open(): a writer lets it go on, and the test fails
            os.close(os.open(fifo, os.O_WRONLY | os.O_NONBLOCK))
            t.join(20)
        assert got, "blocked on the FIFO"


def _rows(rng, n):
    return {"x": rng.standard_normal(n + 1)}


def _listed(rng, n):
    return [1.0] * n


def _scalar(rng, n):
    return {"x": 1.0}


def _objects(rng, n):
    return {"x": np.array([object()] * n)}


def _keys(rng, n):
    return {"x" if n > 1 else "y": np.zeros(n)}


def _shapes(rng, n):
    return {"x": np.zeros((n, n))}


def _short_rows(rng, n):
    return {"rows.a": np.zeros(n - 1)}


def _one(rng):
    return {}


def _raises(rng, n):
    raise KeyError("my own")


@pytest.mark.parametrize(
    "fn, needle",
    [
        (_rows, "'x' of shape (3,) for a chunk of 2 trials"),
        (_listed, "must return a dict of arrays, returned a list"),
        (_scalar, "'x' of shape ()"),
        (_objects, "of Python objects"),
        (_keys, "the key 'x' in one chunk unlike another"),
        (_shapes, "arrays in one chunk unlike another"),
        (_short_rows, "'rows.a' of shape (1,) for 2 trials"),
        (_one, "_one(rng) cannot be called as fn(rng, n)"),
    ],
)
def test_run_chunks_checks_what_its_chunk_function_returns(fn, needle):
    _refused(lambda: sim.run_chunks(fn, 5, 1, 2), "fn", needle)


def test_run_chunks_passes_the_functions_own_error_with_a_note():
    with pytest.raises(KeyError) as e:  # a KeyError, as the runner's for other keys is not
        sim.run_chunks(_raises, 5, 1, 2)
    assert e.value.args == ("my own",)
    assert e.value.__notes__ == ["(in the chunk function of sim.run_chunks, a chunk of 2 trials)"]


def _fn(rng, n):
    return {"x": rng.standard_normal(n)}


@pytest.mark.parametrize(
    "kwargs, key",
    [
        ({"quiet": "no"}, "quiet"),
        ({"keep_rows": "no"}, "keep_rows"),
        ({"ctx": 3}, "ctx"),
        ({"ctx": {"executor": None}}, "ctx"),
        ({"label": 3}, "label"),
        ({"units": "x"}, "units"),
        ({"units": float("nan")}, "units"),
        ({"trials": 100_001, "chunk": 1}, "chunk"),  # 10**12: a list of 10**12 sizes
    ],
)
def test_run_chunks_names_an_option_of_the_wrong_kind(kwargs, key):
    args = {"fn": _fn, "trials": 4, "seed": 1, "chunk": 2, **kwargs}
    _refused(lambda: sim.run_chunks(**args), key)
    out = sim.run_chunks(_fn, 4, 1, 2, quiet=np.True_, ctx=RunContext(quiet=True), units=2)
    assert out["x"].shape == (4,)


def test_load_study_reads_values_as_sim_load_does(tmp_path):
    small = {"trials": np.int64(40), "chunk": np.int32(2)}
    assert sim.load_study(STUDY, values=small, seed=np.int64(3))[1]["seed"] == 3
    _refused(lambda: sim.load_study(STUDY, values={"trials": None}), "trials", "is None")
    _refused(lambda: sim.load_study(STUDY, values={1: 3}), "values", "a key must be")
    _refused(lambda: sim.load_study(STUDY, ["trials=40"], values={"trials": 50}), "trials", "twice")
    _refused(lambda: sim.load_study(STUDY, values={"trials": 40}, trials=50), "trials", "twice")
    _refused(lambda: sim.load_study(STUDY, ["trials"]), "overrides", "key=value")
    _refused(lambda: sim.load_study(tmp_path), "path", "is a directory")


def test_results_of_two_runs_into_one_out_are_not_equal(tmp_path):
    first = sim.Results(tmp_path, "brown_table1", "0123456789abcdef")
    second = sim.Results(tmp_path, "brown_table1", "fedcba9876543210")
    assert first != second and len({first, second}) == 2
    assert first == sim.Results(tmp_path, "brown_table1", "0123456789abcdef")


def test_load_of_a_directory_without_study_files_says_so(tmp_path):
    (tmp_path / "run.json").write_text("{}")
    _refused(lambda: sim.load(tmp_path), "study_file", "it holds a run's results and no study")
    (tmp_path / "empty").mkdir()
    os.mkfifo(tmp_path / "empty" / "x.toml")  # not a study file, and never opened (it blocks)
    _refused(lambda: sim.load(tmp_path / "empty"), "study_file", "it holds no study file")
    line = _refused(lambda: sim.load(ROOT / "studies"), "study_file")
    assert line.endswith(f"(its study files are {ROOT / 'studies'}/*.toml)")


def test_read_provenance_of_a_link_or_a_foreign_key_is_in_its_own_words(tmp_path):
    (tmp_path / "loop").symlink_to(tmp_path / "loop")
    (tmp_path / "gone").symlink_to(tmp_path / "nowhere")
    line = _refused(lambda: sim.read_provenance(tmp_path / "loop"), "path", "symbolic-link loop")
    assert "Failed to open" not in line and "Detail" not in line  # pyarrow's words
    _refused(lambda: sim.read_provenance(tmp_path / "gone"), "path", "which does not exist")
    table = pa.table({"a": [1]}).replace_schema_metadata({b"sim.provenance": b"[1, 2]"})
    pq.write_table(table, tmp_path / "t.parquet")  # another tool's key of that name
    _refused(lambda: sim.read_provenance(tmp_path / "t.parquet"), "path", "not a JSON object")


def test_two_threads_writing_one_table_write_it_one_after_the_other(tmp_path, monkeypatch):
    """Both threads past the write of the temporary, before its rename (a barrier; with one
    writer at a time the first goes on alone after 2 s): one temporary file for both, the
    second's rename found it gone."""
    both = threading.Barrier(2, timeout=2)
    real = pq.write_table

    def meeting(*args, **kwargs):  # each has written the temporary; neither renamed it yet
        real(*args, **kwargs)
        try:
            both.wait()
        except threading.BrokenBarrierError:
            pass

    monkeypatch.setattr(pq, "write_table", meeting)
    errors: list = []

    def write(v):
        try:
            sim.write_table(tmp_path / "t.parquet", {"a": np.full(1000, v)}, {"v": v})
        except Exception as e:  # noqa: BLE001 - the OSError of the code before the fix
            errors.append(f"{type(e).__name__}: {e}")

    threads = [threading.Thread(target=write, args=(v,)) for v in (1.0, 2.0)]
    [t.start() for t in threads]
    [t.join() for t in threads]
    assert not errors
    v = sim.read_provenance(tmp_path / "t.parquet")["v"]
    assert set(pq.read_table(tmp_path / "t.parquet").column("a").to_pylist()) == {v}
