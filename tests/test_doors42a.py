"""The classes of the sweep doors42a (brief A42: a careless user of the Python API in a
notebook -- cells run out of order and twice, a handle built or copied by hand, ``dir(sim)``
and ``help()`` of the public names), one case each; each failed on the code before its fix.

* ``sim.StudyHandle`` is a public name (``sim.__all__``, ``dir(sim)``), and a notebook calls
  it as it calls ``sim.Results(path, study)``: ``sim.StudyHandle("studies/x.toml")`` ended
  in Python's ``TypeError`` naming two dataclass fields, and ``sim.StudyHandle(path, study,
  config)`` with a config of the caller's (a dict copied from a handle and edited) ran and
  published that config unvalidated (no state digest to check it against). A handle is made
  by ``sim.load`` (or from its own state: a pickle, ``copy``); any other is one
  ``ConfigError`` naming ``StudyHandle`` and ``sim.load()``, as is
  ``dataclasses.replace(handle, overrides=...)`` (refused only later, by ``run()``).
* ``dir(sim)`` (a notebook's tab completion) listed ``os``, ``resource`` and ``importlib``,
  the modules ``sim/__init__.py`` imports for itself, among the suite's public names; they
  are underscored now.
* The helpers ``sim`` exports beside the API (``sim.load_study``, ``sim.read_provenance``,
  ``sim.write_table``, ``sim.run_chunks``), called from a notebook, ended in tracebacks:
  ``TypeError`` for an argument missing or a handle given as the path, pyarrow's ``OSError``
  or ``ArrowInvalid`` for ``read_provenance`` of a directory, a missing file or a study file
  (and ``help(sim.read_provenance)`` said nothing). They take their arguments as
  ``sim.load`` does now (:mod:`sim.api_helpers`), each misuse one ``ConfigError`` naming it.
* ``handle.replace(trials=None)`` (meant: drop the override, back to the file's value) was
  refused as ``sim.load(f, trials=None)`` is, "leave it out for the file's value": left out
  of ``replace()``, the key keeps the handle's value. It says that ``replace()`` drops no
  override, and ``sim.load()`` the study without the key.
* ``sim.Results(path, "brown_table1", "claims")`` (a table's name given third, where
  ``help(sim.Results)`` shows ``run_sha256``) had every read refused as "holds another run
  than the one that returned these Results (run again into it since)", of a run never made.
  A ``run_sha256`` that is not the 16 hex digits ``run()`` sets is refused naming it.
* A ``ConfigError`` did not survive its pickle (its ``args`` are the whole line, its
  ``__init__`` takes ``key, message``): a handle sent to a worker of the caller's own
  ``multiprocessing.Pool`` (as the docs invite) and refused there (changed in place) ended in
  a ``TypeError`` in the Pool's result thread, and ``pool.map`` waited for good. It pickles
  as it is (:mod:`sim.mc.pickled_error`): the caller gets the worker's one line, its key and
  notes. A handle changed in place unpickles as it was, refused by its ``run()``.

Held (found right): overrides from NumPy values (0-d arrays, ``np.str_``, ``np.float16``,
NaN and inf named), a dict subclass unpacked by ``**``, a NumPy string as a key, a nested
dict (``errors={"settings": 3}``, named as a table with its keys) beside a dotted key; a
cell run twice (the second run resumes the finished results, the same claims); a handle's
Results read after another handle overwrote the same ``out`` (refused, naming the path), a
``sim.Results(path, study)`` made by hand reading the new run; ``pickle``, ``copy``,
``deepcopy`` and ``repr`` of a handle; ``help()`` of ``sim``, a handle and ``Results``; a
run interrupted (``KeyboardInterrupt``, one and two workers: no process or thread left) and
run again, or run with another config into the same ``out`` (its unfinished run named, or
replaced with ``overwrite=True``); ``sim.load`` of a 2500-point network interrupted and run
again; a cell run again with ``figures`` turned on or off; ``run()``'s ``executor``,
``scheduler``, ``workers`` and flags of wrong types; network records as dict subclasses,
``OrderedDict``, ``MappingProxyType`` or an object array.
"""

from __future__ import annotations

import dataclasses
import multiprocessing
import pickle
from pathlib import Path

import pytest

import sim

ROOT = Path(__file__).resolve().parents[1]
STUDY = ROOT / "studies" / "brown_table1.toml"


def test_a_handle_is_made_by_load_only():
    h = sim.load(STUDY, trials=40, chunk=2)
    made = [
        lambda: sim.StudyHandle(str(STUDY)),
        lambda: sim.StudyHandle(STUDY, h.study, {**h.config, "trials": 41}),
        lambda: dataclasses.replace(h, overrides={"trials": 5}),
    ]
    for make in made:
        with pytest.raises(sim.ConfigError, match=r"^StudyHandle: is made by sim\.load\(") as e:
            make()
        assert "\n" not in str(e.value)
    assert pickle.loads(pickle.dumps(h)) == h == dataclasses.replace(h)  # its own state
    assert h.replace(seed=3).overrides["seed"] == 3


def test_dir_of_sim_lists_no_module_it_imports_for_itself():
    import sim as fresh

    assert not {"os", "resource", "importlib"} & set(dir(fresh))
    assert set(fresh.__all__) <= set(dir(fresh))


def test_the_helpers_sim_exports_name_their_argument(tmp_path):
    h = sim.load(STUDY, trials=40, chunk=2)
    (tmp_path / "d").mkdir()
    calls = {
        r"^path: .*d: a directory, not a table": lambda: sim.read_provenance(tmp_path / "d"),
        r"^path: .*nope\.parquet: no such file": lambda: sim.read_provenance("nope.parquet"),
        r"^path: .*\.toml: not a Parquet file$": lambda: sim.read_provenance(STUDY),
        r"^path: must be a path .* got StudyHandle\(": lambda: sim.load_study(h),
        r"^fn: missing: run_chunks\(\) needs it": lambda: sim.run_chunks(),
        r"^prov: missing: write_table\(\) needs it": lambda: sim.write_table("x.parquet", {}),
    }
    for want, call in calls.items():
        with pytest.raises(sim.ConfigError, match=want) as e:
            call()
        assert "\n" not in str(e.value)
    assert sim.read_provenance.__doc__ and sim.load_study(STUDY)[0].name == "brown_table1"


def test_replace_with_none_says_how_to_drop_an_override():
    h = sim.load(STUDY, trials=40, chunk=2)
    for given in ({"trials": None}, {"errors.settings": None}):
        with pytest.raises(sim.ConfigError, match=r"replace\(\) drops no override") as e:
            h.replace(**given)
        assert str(e.value).startswith(f"{next(iter(given))}: ") and "sim.load()" in str(e.value)
    with pytest.raises(sim.ConfigError, match=r"^seed: .*leave it out for the handle's value$"):
        h.run(seed=None)


def test_a_results_third_argument_is_the_identity_run_sets():
    res = ROOT / "results" / "brown_table1"
    for bad in ("claims", None, 5):
        with pytest.raises(sim.ConfigError, match=r"^run_sha256: is the identity of the run"):
            sim.Results(res, "brown_table1", bad)
    assert sim.Results(res, "brown_table1", "").path == res


def _trials(h: sim.StudyHandle) -> int:
    return h.estimate().trials


def test_a_refusal_in_a_pool_worker_comes_back_to_the_caller():
    e = sim.ConfigError("trials", "must be an integer")
    e.add_note("a note")
    back = pickle.loads(pickle.dumps(e))
    assert (str(back), back.key, back.__notes__) == (str(e), "trials", ["a note"])
    h = sim.load(STUDY, trials=40, chunk=2)
    h.config["trials"] = 41  # changed in place: the worker's estimate() refuses it
    with multiprocessing.get_context("fork").Pool(1) as pool:
        with pytest.raises(sim.ConfigError, match=r"^config: the handle's config"):
            pool.map_async(_trials, [h]).get(timeout=20)
