"""The classes of the review R44 of last session's change (lead41's argument checks of the
helpers ``sim`` exports, L41's working directory gone, R41's names() of a results root, T43's
Dask under ``ulimit -m``), one case each; each failed on the code before its fix.

* ``sim.write_table`` checked that ``columns`` is a mapping of 1-D arrays, and its neighbours
  slipped past into pyarrow or Python: columns of unequal lengths (``ArrowInvalid: Column 1
  named b expected length 3 but got length 4``), a name that is not a string (``TypeError:
  expected bytes, int found``), values pyarrow cannot hold in one column (a set: "only handle
  1-dimensional arrays"; mixed dicts and numbers), a ``prov`` that is not JSON (``TypeError:
  not JSON serialisable``), a tolerance that is not a rule (``ValueError: dictionary update
  sequence element #0``), an infinite value (the suite's ``NonFiniteError``, a ValueError), a
  ``path`` that is a directory (``IsADirectoryError``) or below a file (``FileExistsError``).
  Each is one ``sim.ConfigError`` naming the argument now; a good table is written as before.
* ``sim.run_chunks`` with a count of chunks no run may have (``10**12`` trials in chunks of 1)
  built its list of chunk sizes for good (a hang, then memory); it is refused naming
  ``chunk``, at the runs' own limit (``sim.mc.config.MAX_CHUNKS``). ``units`` not a number
  ended in "could not convert string to float" from the progress bar: refused naming it. A
  chunk function that returns no mapping (an ``int``) ended in "'int' object has no
  attribute 'items'" from inside the runner: refused naming ``fn``.
* ``sim.read_provenance`` of a FIFO nobody writes to waited for good (pyarrow opened it to
  read; a directory, a missing file and a study file were refused, a pipe slipped past): it
  is refused naming ``path``, as ``sim.load`` refuses a study file that is one.
* ``sim.load_study`` given ``values`` whose key is not a string (``{1: 2}``) ended in
  "TypeError: normalize() argument 2 must be str, not int"; ``sim.load`` named ``values``.
* ``python -m sim.report.verify`` (``make verify``'s command) from a working directory that
  was deleted ended "sim verify: error: No such file or directory", naming nothing: its own
  refusal ("no studies/ directory in <cwd>") raised asking for the directory. It names the
  relative argument, as ``sim`` and ``sim.batch`` do (doors41l).
* ``sim.Results(root, study)`` of a results root (R41 named the directories holding the
  study's runs) with a study none of them holds, a name mistyped (``brown_tabel1``), said
  "holds tables of 'verify', not of 'brown_tabel1'" (the root's make verify record), naming
  none of the studies there. It names them, and the one the name most likely meant.
* ``--executor dask`` under any hard ``ulimit -m`` below the machine's memory was refused
  (t43 refused the limits Dask fails under: 400 MB for two workers hung): ``ulimit -m
  20000000`` (19 GiB of 24) said "its workers stall or fail under it" of a run that fits. A
  limit that leaves each worker 400 MiB runs (two workers under 1,000,000 kB ran as fast as
  without it); a smaller one is refused as before, saying each worker's share.
"""

from __future__ import annotations

import json
import os

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

import sim
from sim.report.verify.cli import main as verify_main
from tests.oneline import VERIFY_ERROR, one_line, python_lines


@pytest.mark.parametrize(
    "columns, prov, tolerances, key, words",
    [
        ({"a": np.arange(3), "b": np.arange(4)}, {}, None, "columns", "'b' 4"),
        ({1: np.arange(3)}, {}, None, "columns", "name must be a str"),
        ({"a": {1, 2}}, {}, None, "columns", "'a' is a set"),
        ({"a": [{"x": 1}, 2]}, {}, None, "columns", "'a' cannot be stored"),
        ({"a": [1.0, np.inf]}, {}, None, "columns", "column a is inf"),
        ({"a": [1, 2]}, {"x": object()}, None, "prov", "JSON"),
        ({"a": [1, 2]}, {1: 2, "x": 1}, None, "prov", "must be a str"),
        ({"a": [1, 2]}, {}, {"a": "x"}, "tolerances", "'a' must map to a rule"),
        ({"a": [1, 2]}, {}, {"zz": {"kind": "exact"}}, "tolerances", "zz: no such column"),
    ],
)
def test_write_table_names_the_argument_pyarrow_or_python_refused(
    tmp_path, columns, prov, tolerances, key, words
):
    with pytest.raises(sim.ConfigError) as e:
        sim.write_table(tmp_path / "t.parquet", columns, prov, tolerances)
    assert e.value.key == key and words in str(e.value) and "\n" not in str(e.value), str(e.value)
    assert not (tmp_path / "t.parquet").exists()


def test_write_table_into_a_directory_names_the_path(tmp_path):
    with pytest.raises(sim.ConfigError) as e:
        sim.write_table(tmp_path, {"a": [1, 2]}, {})
    assert e.value.key == "path" and "is a directory" in str(e.value)
    (tmp_path / "f").write_text("mine")  # a file where its directory goes: FileExistsError
    with pytest.raises(sim.ConfigError) as e:
        sim.write_table(tmp_path / "f" / "t.parquet", {"a": [1, 2]}, {})
    assert e.value.key == "path" and "is not a directory" in str(e.value)
    assert (tmp_path / "f").read_text() == "mine"


def test_write_table_writes_a_good_table_as_before(tmp_path):
    cols = {"a": np.arange(3.0), "s": ["x", "y", "z"], "l": [[1], [2, 3], []]}
    path = sim.write_table(tmp_path / "ok.parquet", cols, {"study": "x"})
    assert sim.read_provenance(path) == {"study": "x"}
    assert pq.read_table(path).to_pydict()["l"] == [[1], [2, 3], []]
    assert sim.write_table(tmp_path / "t.parquet", pa.table({"a": [1]}), {}).is_file()


def _fn(rng, n):
    return {"x": rng.standard_normal(n)}


def test_run_chunks_refuses_more_chunks_than_a_run_may_have():
    with pytest.raises(sim.ConfigError) as e:
        sim.run_chunks(_fn, 10**12, 1, 1)
    assert e.value.key == "chunk" and "make chunk at least 10,000,000" in str(e.value)


def test_run_chunks_names_units_not_a_number():
    with pytest.raises(sim.ConfigError) as e:
        sim.run_chunks(_fn, 4, 1, 2, units="x")
    assert e.value.key == "units"
    assert sim.run_chunks(_fn, 4, 1, 2, units=2.5)["x"].shape == (4,)


def test_read_provenance_of_a_fifo_is_refused_not_waited_on(tmp_path):
    os.mkfifo(tmp_path / "t.parquet")
    with pytest.raises(sim.ConfigError) as e:
        sim.read_provenance(tmp_path / "t.parquet")
    assert e.value.key == "path" and "not a regular file" in str(e.value)


def test_load_study_names_values_whose_key_is_not_a_string():
    study = os.path.join(os.path.dirname(__file__), "..", "studies", "brown_table1.toml")
    with pytest.raises(sim.ConfigError) as e:
        sim.load_study(study, values={1: 2})
    assert e.value.key == "values" and "must be a dotted str" in str(e.value)


def test_verify_from_a_deleted_working_directory_names_the_argument(tmp_path, monkeypatch, capsys):
    gone = tmp_path / "gone"
    gone.mkdir()
    monkeypatch.chdir(gone)
    gone.rmdir()
    one_line(
        capsys,
        verify_main([]),
        "results is relative, but the working directory is gone",
        prefix=VERIFY_ERROR + "--results",
    )


def test_results_of_a_root_with_a_mistyped_study_names_the_studies_there(tmp_path):
    for name, study in (("brown_table1", "brown_table1"), ("network_plate", "network")):
        (tmp_path / name).mkdir()
        record = {"config": {"study": study}, "code_hash": "0" * 16}
        (tmp_path / name / "run.json").write_text(json.dumps(record), encoding="utf-8")
    sim.write_table(tmp_path / "reproducibility.parquet", {"study": ["x"]}, {"study": "verify"})
    with pytest.raises(sim.ConfigError) as e:
        sim.Results(tmp_path, "brown_tabel1").names()
    line = str(e.value)
    assert "did you mean 'brown_table1'?" in line and "brown_table1, network" in line, line


@pytest.mark.parametrize("kb, refused", [(20_000_000, False), (400_000, True)])
def test_dask_is_refused_only_under_a_ulimit_m_its_workers_cannot_run_under(kb, refused):
    pytest.importorskip("distributed")
    proc = python_lines(  # (a real run under 19 GiB: the same results, see the docstring)
        "import resource",
        f"resource.setrlimit(resource.RLIMIT_RSS, ({kb} << 10, {kb} << 10))",
        "from sim.mc.executors import StartRefused, _rss_limit_not_taken",
        "try:",
        "    _rss_limit_not_taken(2)",
        "except StartRefused as e:",
        "    print(e)",
    )
    assert proc.returncode == 0 and proc.stderr == "", proc.stderr
    assert ("195 MiB each of 2 workers" in proc.stdout) == refused, proc.stdout


def test_run_chunks_names_a_chunk_function_that_returns_no_mapping():
    with pytest.raises(sim.ConfigError) as e:
        sim.run_chunks(lambda rng, n: 5, 4, 1, 2)
    assert e.value.key == "fn" and "returned an int" in str(e.value)
    agg = sim.run_chunks(lambda rng, n: {"s": np.array([n])}, 4, 1, 2)  # a chunk's own rows
    assert agg["s"].tolist() == [2, 2]
