"""The classes of the sweep doors50a (brief A50: the Python API under the caller's own global
state), one case each; each failed on the code before its fix.

* A NumPy float given for a key under the caller's ``np.set_printoptions(legacy="1.13")`` (a
  notebook kept on old NumPy output) was read as the 12 digits NumPy then prints:
  ``comparator__beta_mm=np.float64(1/3)`` ran 0.333333333333, another config and code-hash
  input than a clean process's, silently. Read as its shortest digits whatever the print
  options (:mod:`sim.mc.pyvalue`); the caller's options are left as they were.
* A file of the caller's that shadows a library the API loads on first use (an empty
  ``scipy.py``, ``numpy.py`` or ``pyarrow.py`` in a notebook's directory): ``sim.load`` ended in
  an ImportError (or AttributeError) traceback from the suite's own imports, where the
  commands say one line. One :class:`sim.ConfigError` naming the file now (``sim.__getattr__``).
* Such a file found during a run (``tqdm.py``, ``matplotlib.py``: a :class:`sim.StudyError`
  naming it) stayed loaded: renamed as told, the next run in the process was refused again,
  naming a file that no longer exists. Its module is dropped with the refusal
  (:func:`sim.threads.shadowed`), and the next run loads the library.
* A run resumed (or noting anything on standard error: a chunk's length, a sweep's refused
  cells, a table edited by hand) by a caller whose ``sys.stderr`` is closed (a ``StringIO`` it
  closed), broken (a pipe whose reader left: ``OSError``) or ``None``: the note's ``print``
  ended the run in ``ValueError: I/O operation on closed file`` (or the ``OSError``), a
  traceback from the suite, before any chunk; with ``None`` the note went to standard output.
  Each note is dropped when it cannot be written (:func:`sim.standard_error.say`).
* ``importlib.reload(sim.api)`` (a notebook reloading what it imported): a handle loaded
  before it said "trials: must be an integer (got <the handle's>)" on ``run()``, its default
  the sentinel object before the reload. The sentinel survives the reload.
* ``importlib.reload(sim.mc.config)``: the suite's modules raised the first ``ConfigError``,
  which the caller's ``except sim.ConfigError`` (the class made again) let through
  (``sim.load(123)``: a traceback), and ``sim.cli.main`` said "sim: error: ConfigError: ...".
  The classes made by the first import are kept.

Held (found right), each against a clean process's tables (byte-equal): ``np.seterr(all=
"ignore")``, a ``decimal`` context of 3 digits trapping ``Inexact`` and ``Rounded``,
``np.set_printoptions(legacy="1.13")`` over every study's tiny run (tables and claims),
``locale.setlocale(LC_ALL, "de_DE.utf8")``, ``random.seed``/``np.random.seed`` (the caller's
streams untouched), ``PYTHONHASHSEED`` 1 and 2 over two network studies,
``logging.basicConfig(level=DEBUG)`` (matplotlib's debug lines are the caller's asking; levels
kept), ``set_start_method("spawn")`` and ``("forkserver")`` before a two-worker run,
``socket.setdefaulttimeout(1e-5)`` for forkserver and ``1e-3`` for Dask workers, ``python -c``
with ``sys.argv == [""]`` and a thread of its own (forkserver) or Dask (spawn), ``python -i``
fed on standard input with Dask, ``os.umask(0o277)`` (refused in one line),
``importlib.reload(sim)``, a user's ``numba.py`` or ``dask.py`` in the working directory (not loaded by a local run).
"""

from __future__ import annotations

import io
import os
import subprocess
import sys
import types
from pathlib import Path

import numpy as np
import pytest

import sim
import sim.execute
import sim.mc.progress
from tests.conftest import TRIANGLE_NETWORK

ROOT = Path(__file__).resolve().parents[1]
BROWN = ROOT / "studies" / "brown_table1.toml"


def _env() -> dict:
    """The test's environment with this checkout first on the path."""
    return {**os.environ, "PYTHONPATH": str(ROOT)}


def _python(code: str, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        cwd=cwd,
        timeout=300,
        env=_env(),
    )


def test_a_numpy_float_under_legacy_print_options_is_its_shortest_digits():
    """``np.set_printoptions(legacy="1.13")`` of the caller's: ``np.float64(1/3)`` for a key
    was read as the 12 digits NumPy printed, 0.333333333333 (another config, silently)."""
    clean = sim.load(BROWN, comparator__beta_mm=np.float64(1 / 3))
    with np.printoptions(legacy="1.13"):
        legacy = sim.load(BROWN, comparator__beta_mm=np.float64(1 / 3))
        assert np.get_printoptions()["legacy"] == "1.13"  # the caller's options, as they were
    assert legacy.config["comparator.beta_mm"] == 1 / 3 == clean.config["comparator.beta_mm"]
    assert legacy.overrides == clean.overrides


def test_a_file_shadowing_a_library_is_one_config_error_then_forgotten(tmp_path):
    """An empty ``scipy.py`` in the caller's working directory: ``sim.load`` was an ImportError
    traceback from the suite's imports. It is one ConfigError naming the file; once renamed,
    the same process loads the study."""
    study = tmp_path / "tri.toml"
    study.write_text(TRIANGLE_NETWORK)
    (tmp_path / "scipy.py").write_text("")
    code = "\n".join(
        [
            "import os, sim",
            "try:",
            f"    sim.load({str(study)!r})",
            "except sim.ConfigError as e:",
            "    print('REFUSED', e)",
            "os.rename('scipy.py', 'mine.py')",
            f"print('LOADED', sim.load({str(study)!r}).name)",
        ]
    )
    p = _python(code, tmp_path)
    assert p.returncode == 0, p.stderr[-2000:]
    refused, loaded = p.stdout.splitlines()
    assert refused.startswith("REFUSED cannot load the suite: ")
    assert f"{tmp_path / 'scipy.py'} shadows the library scipy" in refused
    assert loaded == "LOADED network", p.stdout


def test_a_file_shadowing_a_library_in_a_run_is_forgotten_with_its_refusal(tmp_path, monkeypatch):
    """A user's ``tqdm.py`` loaded when the run's progress bar starts: refused naming it, but
    it stayed loaded, and the next run (the file renamed as told) was refused again naming a
    file gone. Its module is dropped with the refusal: the next run draws with tqdm."""
    study = tmp_path / "tri.toml"
    study.write_text(TRIANGLE_NETWORK)
    handle = sim.load(study)
    mine = types.ModuleType("tqdm")
    mine.__file__ = str(tmp_path / "tqdm.py")  # as an empty tqdm.py imported from the cwd
    real = {n: m for n, m in sys.modules.items() if n.split(".")[0] == "tqdm"}
    monkeypatch.setattr(sim.mc.progress, "_bar", [])  # tqdm imported again: not the cached bar
    sys.modules["tqdm"] = mine
    try:
        with pytest.raises(sim.StudyError, match="tqdm.py shadows the library tqdm"):
            handle.run(out=tmp_path / "o", quiet=False, figures=False)
        assert sys.modules.get("tqdm") is not mine
        res = handle.run(out=tmp_path / "o", quiet=False, figures=False)  # the file renamed
        assert res.claims().num_rows > 0
    finally:
        for name in [n for n in sys.modules if n.split(".")[0] == "tqdm"]:
            del sys.modules[name]
        sys.modules.update(real)


def test_a_handle_loaded_before_a_reload_of_the_api_runs(tmp_path):
    """``importlib.reload(sim.api)`` after ``sim.load``: the handle's ``run()`` said "trials:
    must be an integer (got <the handle's>)". It runs, as the same handle did before."""
    study = tmp_path / "tri.toml"
    study.write_text(TRIANGLE_NETWORK)
    code = "\n".join(
        [
            "import importlib, sim, sim.api",
            f"h = sim.load({str(study)!r})",
            "importlib.reload(sim.api)",
            f"res = h.run(out={str(tmp_path / 'o')!r}, figures=False)",
            "print(res.table('trials').num_rows)",
        ]
    )
    p = _python(code, tmp_path)
    assert p.returncode == 0 and p.stdout.split() == ["40"], p.stdout + p.stderr[-2000:]


def test_a_run_resumed_under_a_closed_standard_error_goes_on(tmp_path, monkeypatch):
    """The caller closed its ``sys.stderr`` (a ``StringIO``): the resumed run's note "sim:
    resuming ..." ended it in "ValueError: I/O operation on closed file" from the suite's
    ``print``. The note is dropped; the run resumes and finishes."""
    study = tmp_path / "tri.toml"
    study.write_text(TRIANGLE_NETWORK)
    handle, out = sim.load(study), tmp_path / "o"

    def interrupted() -> None:  # Ctrl-C once every chunk was computed: the stage is kept
        raise KeyboardInterrupt

    monkeypatch.setattr(sim.execute, "check_interrupt", interrupted)
    with pytest.raises(KeyboardInterrupt):
        handle.run(out=out, figures=False)
    monkeypatch.undo()
    closed = io.StringIO()
    closed.close()
    monkeypatch.setattr(sys, "stderr", closed)
    res = handle.run(out=out, figures=False)
    assert res.table("trials").num_rows == 40


def test_the_errors_are_one_class_after_a_reload_of_the_config_module(tmp_path):
    """``importlib.reload(sim.mc.config)``: ``sim.load(123)`` raised the ConfigError of the
    first import, which ``except sim.ConfigError`` (the reloaded class) did not catch."""
    code = "\n".join(
        [
            "import importlib, sim, sim.api, sim.mc.config",
            "importlib.reload(sim.mc.config)",
            "try:",
            "    sim.load(123)",
            "except sim.ConfigError as e:",
            "    print('REFUSED', e.key)",
            "print(sim.StudyError is sim.mc.config.StudyError)",
        ]
    )
    p = _python(code, tmp_path)
    assert p.returncode == 0 and p.stdout.split() == ["REFUSED", "study_file", "True"], (
        p.stdout + p.stderr[-2000:]
    )
