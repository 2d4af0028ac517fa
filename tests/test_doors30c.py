"""The classes of the sweep doors30c (brief D30c: the Python API given what Python programs
really pass, and its objects used as objects), one case each; each failed on the code before
its fix.

* ``run(out="~/runs/x")`` made a directory named ``~`` in the working directory (which ``rm
  -rf ~`` would then mistake for home), ``"$HOME/runs/x"`` one named ``$HOME``: Python expands
  neither. A path argument of the API that starts with ``~`` or names a set environment
  variable (and names no file as it is) is refused naming the argument and the function that
  expands it (:mod:`sim.api_paths`; ``sim.load("~/a.toml")`` said "no such study file");
* a ``pathlib.Path`` (any ``os.PathLike`` of a str) for a file key, ``network.gama_xml``, was
  refused as "must be a string (got PosixPath('plate.xml'))": it is the path it names
  (:mod:`sim.mc.pyvalue`);
* a relative ``network.gama_xml`` is read from the working directory: after an ``os.chdir``,
  ``run()`` read another directory's file of that name and said the handle's "has changed
  since the study was loaded", and ``replace()`` or ``run(trials=...)`` loaded that other
  network without a word. Refused naming the key, the two directories and the way out
  (:func:`sim.api_state.check_cwd`);
* a handle did not pickle ("Can't pickle local object 'data_check.<locals>.check'"), so none
  could be sent to a ``multiprocessing`` pool: it pickles with its study by name;
* ``None`` for a key (``sim.load(f, trials=None)``, ``replace(seed=None)``) was refused as
  "trials: is required", of a key the study file gives: it says ``None`` is no value;
* a run into an ``out`` that another run of the same process (a thread of a notebook) writes
  was refused as "being written by a running sim (pid 9485)", the caller's own process (or
  "another process" where it was not): it says a run in this process writes it
  (:func:`sim.execute._this_process`);
* ``run(quiet=np.True_)`` (a flag from a NumPy mask) was refused as "must be True or False
  (got np.True_)", where every config key takes a NumPy bool as the bool.
* ``Results(path, study).names()`` of another study's results listed that study's tables,
  each of which ``table()`` then refused: it refuses the directory, naming whose tables it
  holds (and ``<path>/<study>`` where ``path`` is a results root), and lists only the
  study's own;
* ``replace(self=1)`` said "missing: StudyHandle.replace() needs it": ``self`` is no argument.
* a pyarrow array or column (the suite's own tables: ``res.table("points").column(...)``)
  where a list goes was refused in a message of twenty lines (its repr), and so was any
  array-like of another library (a pandas Series); a pyarrow scalar was "must be a number
  (got <pyarrow.DoubleScalar: 0.5>)". Each is now the list (the value) it holds
  (:mod:`sim.mc.pyvalue`), and a refusal that quotes a many-line repr is one line
  (:func:`sim.api_args.one_line`).
* a ``range``, a ``deque`` or ``d.keys()`` where a list goes was "must be a list (got
  range(0, 3))"; a generator or ``zip`` "(got <zip object at 0x7f...>)", a set alike: a
  sequence is now the list, and an iterator (read once) or a set (no order) is named as one
  with what to give.

Held (found right): ``Path``, an ``os.PathLike`` of the user's, a str subclass and
``np.str_`` for ``study_file``, ``out`` and ``sim.Results``; bytes paths refused in one line;
``OrderedDict``, ``MappingProxyType`` and ``ChainMap`` as ``**overrides``; generators where
lists go refused naming the key; misspelt arguments (``run(trails=...)``); ``repr``, ``==``,
``hash``, ``copy.copy``/``deepcopy`` of handles and Results; Results pickled to a spawned
process; Results read after their directory was deleted, emptied or replaced by another run;
two handles of one file into one ``out``; two runs at once from a ThreadPoolExecutor into two
directories; a pickled handle run in a spawned and a forkserver pool.
"""

from __future__ import annotations

import collections
import multiprocessing
import os
import pickle
import shutil
from pathlib import Path

import numpy as np
import pyarrow as pa
import pytest

import sim
from sim.mc.config import ConfigError
from sim.mc.outputs import stage_dir
from sim.mc.storage import StageLock, write_table

ROOT = Path(__file__).resolve().parents[1]
PLATE = str(ROOT / "studies" / "network_plate.toml")
BROWN_NET = str(ROOT / "studies" / "network_brown.toml")
TABLE1 = str(ROOT / "studies" / "brown_table1.toml")
GAMA = ROOT / "tests" / "data" / "gama"
SMALL = {"trials": 40, "chunk": 2}


class _PathLike:  # a path class of the user's own
    def __init__(self, p: str):
        self.p = p

    def __fspath__(self) -> str:
        return self.p


def _gama_study(d: Path, xml: str = "plate.xml") -> Path:
    f = d / "g.toml"
    f.write_text(
        f'study = "network"\ntrials = 40\nchunk = 2\nseed = 1\n[network]\ngama_xml = "{xml}"\n'
    )
    return f


def test_a_tilde_or_a_variable_in_a_path_is_refused_not_made(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("SIM_D30C", str(tmp_path))
    st = sim.load(PLATE, **SMALL)
    with pytest.raises(ConfigError, match=r"^out: ~/runs/x starts with '~', which Python does"):
        st.run(out="~/runs/x")
    with pytest.raises(ConfigError, match=r"os.path.expandvars\('\$SIM_D30C/x'\)$"):
        st.run(out=Path("$SIM_D30C/x"))
    with pytest.raises(ConfigError, match=r"^study_file: ~/a.toml starts with '~'"):
        sim.load("~/a.toml")
    with pytest.raises(ConfigError, match=r"^path: \$\{SIM_D30C\}/r names an environment"):
        sim.Results("${SIM_D30C}/r", "network")
    assert list(tmp_path.iterdir()) == []  # no directory "~" nor "$SIM_D30C" made
    (tmp_path / "~b.toml").write_text(Path(PLATE).read_text())  # a file of that very name
    assert sim.load("~b.toml").name == "network"


def test_a_path_object_is_the_path_of_a_file_key(tmp_path, monkeypatch):
    shutil.copy(GAMA / "plate.xml", tmp_path / "plate.xml")
    f = _gama_study(tmp_path, "other.xml")
    monkeypatch.chdir(tmp_path)
    for p in (Path("plate.xml"), _PathLike("plate.xml"), tmp_path / "plate.xml"):
        st = sim.load(f, **{"network.gama_xml": p})
        assert st.config["network.gama_xml"] == os.fspath(p)
        assert type(st.config["network.gama_xml"]) is str


def test_a_relative_gama_file_after_chdir_is_refused_not_another_read(tmp_path, monkeypatch):
    a, b = tmp_path / "a", tmp_path / "b"
    a.mkdir()
    b.mkdir()
    shutil.copy(GAMA / "plate.xml", a / "plate.xml")
    shutil.copy(GAMA / "one_fixed.xml", b / "plate.xml")  # another network of that name
    monkeypatch.chdir(a)
    st = sim.load(_gama_study(a))
    monkeypatch.chdir(b)
    words = f"^network.gama_xml: plate.xml is read from the working directory, {a} at sim.load"
    for call in (st.run, lambda: st.run(trials=42), lambda: st.replace(seed=4)):
        with pytest.raises(ConfigError, match=words):
            call()
    monkeypatch.chdir(a)  # back: the handle's own file again
    assert st.replace(seed=4).config["network.gama_sha256"] == st.config["network.gama_sha256"]
    monkeypatch.chdir(b)  # an absolute path names one file from anywhere
    absolute = sim.load(a / "g.toml", network__gama_xml=a / "plate.xml")
    assert (
        absolute.replace(seed=4).config["network.gama_sha256"] == st.config["network.gama_sha256"]
    )


def _run(h: sim.StudyHandle, out: str) -> int:  # a task of a pool of the user's
    return h.run(out=out, quiet=np.True_, figures=np.False_).claims().num_rows


@pytest.mark.long
def test_a_handle_pickles_and_runs_in_a_spawned_process(tmp_path):
    st = sim.load(TABLE1, **SMALL)  # its study holds closures (the claim book's check)
    again = pickle.loads(pickle.dumps(st))
    assert again == st and again.study is st.study and again.config == st.config
    assert again.estimate().trials == 40  # its state is the one validated
    with multiprocessing.get_context("spawn").Pool(1) as pool:
        (rows,) = pool.starmap(_run, [(st, str(tmp_path / "o"))])
    assert rows == sim.Results(tmp_path / "o", "brown_table1").claims().num_rows > 0


def test_none_for_a_key_is_refused_as_none_not_as_missing():
    with pytest.raises(ConfigError, match="^trials: is None, which no study file holds"):
        sim.load(TABLE1, trials=None)
    with pytest.raises(ConfigError, match="^seed: is None, which no study file holds"):
        sim.load(TABLE1).replace(seed=None)


def test_an_out_another_run_of_this_process_writes_names_this_process(tmp_path):
    out = tmp_path / "o"
    lock = StageLock(stage_dir(out)).acquire()  # as a run in another thread holds it
    try:
        with pytest.raises(ConfigError) as info:
            sim.load(PLATE, **SMALL).run(out=out)
    finally:
        lock.release()
    assert str(info.value) == (
        f"out: {out} is being written by a running sim (another run in this process: a "
        "thread); wait for it to finish or choose another out"
    )


def test_run_takes_numpy_bools_for_its_flags(tmp_path):
    assert _run(sim.load(PLATE, **SMALL), str(tmp_path / "o")) > 0
    assert not list((tmp_path / "o").glob("*.png"))  # figures=np.False_ is False
    with pytest.raises(ConfigError, match=r"^overwrite: must be True or False \(got 1\)"):
        sim.load(PLATE, **SMALL).run(overwrite=1)
    assert os.path.isdir(tmp_path / "o")


def test_names_of_another_studys_results_are_refused(tmp_path):
    d = tmp_path / "x"
    write_table(d / "claims.parquet", {"claim": ["c"], "verdict": ["holds"]}, {"study": "x"})
    assert sim.Results(d, "x").names() == ["claims"]
    with pytest.raises(ConfigError, match=f"^study: {d} holds tables of 'x', not of 'y'$"):
        sim.Results(d, "y").names()  # it listed x's tables, each then refused
    with pytest.raises(ConfigError, match=f"; {d} holds the study's results: give that path$"):
        sim.Results(tmp_path, "x").claims()  # the results root, for its study's directory


def test_self_as_a_keyword_is_no_argument():
    with pytest.raises(ConfigError, match=r"^self: StudyHandle.replace\(\) takes no argument"):
        sim.load(TABLE1).replace(self=1)  # it was "missing: StudyHandle.replace() needs it"


class _Rows:  # an array-like of another library, printed over lines (a pandas Series)
    def __init__(self, rows, fails=False):
        self.rows, self.fails = rows, fails

    def __array__(self, dtype=None, copy=None):
        if self.fails:
            raise ValueError("cannot")
        return np.array(self.rows)

    def __repr__(self) -> str:
        return "Rows(\n  ...\n)"


def test_array_likes_are_lists_and_a_refusal_is_one_line():
    pts = [[0.0, 0.0], [100.0, 0.0], [0.0, 100.0], [100.0, 100.0], [50.0, 50.0]]
    for v in (pa.array(pts), pa.table({"p": pts}).column("p"), _Rows(pts)):
        st = sim.load(TABLE1, plate__pattern="list", plate__points=v)
        assert st.config["plate.points"] == pts
    assert sim.load(TABLE1, trials=pa.scalar(40), chunk=2).config["trials"] == 40
    with pytest.raises(ConfigError) as info:
        sim.load(TABLE1, plate__pattern="list", plate__points=_Rows(pts, fails=True))
    assert str(info.value) == "plate.points: must be a list (got Rows( ... ))"
    with pytest.raises(ConfigError, match=r"^workers: .* \(got Rows\( \.\.\. \)\)$"):
        sim.load(TABLE1).run(workers=_Rows(1, fails=True))  # an array-like of 1 is 1 (A37)


def test_sequences_are_lists_and_iterators_or_sets_are_named():
    names = {"P1": 1, "P5": 2}  # Brown's plate (the plate's weighted coordinates leave no
    for v in (collections.deque(["P1", "P5"]), names.keys(), range(0)):  # inner datum, s37)
        st = sim.load(BROWN_NET, datum__kind="inner", datum__points=v)
        assert st.config["datum.points"] == list(v)
    for v, words in (
        ((n for n in names), r"an iterator, read once \(generator\)"),
        (set(names), "a set"),
    ):
        with pytest.raises(ConfigError, match=f"^datum.points: is {words}.*: give a list"):
            sim.load(PLATE, datum__points=v)  # "must be a list (got <generator object ...>)"
    with pytest.raises(ConfigError, match="^datum.points: has 1000000000000 entries, over"):
        sim.load(PLATE, datum__points=range(10**12))
