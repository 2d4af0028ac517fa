"""The classes of the sweep doors29c (brief D29c: one Python process used for hours, as a
designer's notebook is: hundreds of ``sim.load(...).run(...)`` of variants, some refused, some
interrupted), one case each; each failed on the code before its fix.

* Ctrl-C while a run imports matplotlib or numba for the first time (about a second of the
  first run in a process) left their already loaded submodules bound to the half-made
  package: every later run of the process failed ("the run failed in
  sim.studies.brown.figures._fig: AttributeError: module 'matplotlib' has no attribute
  '_docstring'"; numba's "partially initialized module 'numba.core.types'") until the kernel
  was restarted. A failed or interrupted command now drops them
  (:func:`sim.execute.drop_half_imported`), and the next run imports the library afresh.
* ``run(out=None)`` that was refused (``workers=999``, a work limit) left an empty
  ``$TMPDIR/sim-<study>-XXXX/`` behind, one per call; an interrupted one left its staging
  directory there, finished chunks and all, under a name the caller was never told (so
  never resumed, never removed). The empty directory is now removed, and an interrupted run
  names the ``out`` that resumes it in a note of its ``KeyboardInterrupt``
  (:func:`sim.api_state.anonymous_dir`).
* A handle's ``config`` (and ``overrides``) changed in place after ``sim.load`` ran
  unvalidated: ``config["errors.setting_sigma_um"] = "abc"`` ended in an internal error of
  the model, ``config["study"] = "brown_dilution"`` ran Brown's Table 1 and published it as
  brown_dilution's. A run, an estimate or ``replace`` now refuses such a handle in one line
  naming ``replace()`` (:func:`sim.api_state.check_state`).

Measured and found bounded over 120 calls of five study kinds in one process (workers 1 and
2, figures on and off, out given and not, refused loads, interrupts): resident memory (about
440 MB after the first calls, flat), open descriptors, threads, child processes (a
forkserver and its resource tracker once a thread exists), matplotlib figures (none),
warnings filters, ``np.geterr()``, logging handlers and loggers, modules; an interrupted run
with workers 1 or 2 resumes to tables equal to a fresh process's.
"""

from __future__ import annotations

import importlib
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest

import sim
from sim.mc.config import ConfigError

network_run = importlib.import_module("sim.studies.network.run")  # the package's run() shadows it
ROOT = Path(__file__).resolve().parents[1]
PLATE = str(ROOT / "studies" / "network_plate.toml")
TABLE1 = str(ROOT / "studies" / "brown_table1.toml")
SMALL = {"trials": 40, "chunk": 2}


@pytest.mark.long
def test_an_interrupt_in_a_first_import_does_not_poison_the_process(tmp_path):
    """In a fresh Python: Ctrl-C (raised by the import system, as the signal handler would)
    in numba's first import, then in matplotlib's; each next run imports the library anew."""
    lines = [
        "import importlib.abc, sys",
        "import sim",
        "assert 'numba' not in sys.modules and 'matplotlib' not in sys.modules",
        "left = ['numba.core.types', 'matplotlib.cm']",
        "class Stop(importlib.abc.MetaPathFinder):",
        "    def find_spec(self, name, path, target=None):",
        "        if left and name == left[0]:",
        "            left.pop(0)",
        "            raise KeyboardInterrupt",
        "sys.meta_path.insert(0, Stop())",
        f"st = sim.load({TABLE1!r}, trials=40, chunk=2)",
        "for i in range(3):",
        "    try:",
        f"        st.run(out={str(tmp_path / 'o')!r}, overwrite=True)",
        "        print('ok')",
        "    except KeyboardInterrupt:",
        "        print('interrupted')",
        "    except Exception as e:",
        "        print(type(e).__name__, e)",
        "print(left)",
    ]  # a fresh Python (python_lines's, with room for numba's first compile on a busy machine)
    proc = subprocess.run(
        [sys.executable, "-c", "\n".join(lines)],
        capture_output=True,
        text=True,
        timeout=600,
        env={k: v for k, v in os.environ.items() if k != "SIM_NO_JIT"},  # numba is imported
    )
    assert proc.stdout.split("\n") == ["interrupted", "interrupted", "ok", "[]", ""], proc


def test_a_refused_run_without_out_leaves_no_temporary_directory(tmp_path, monkeypatch):
    base = tmp_path / "tmp"
    base.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(base))
    st = sim.load(PLATE, **SMALL)
    with pytest.raises(ConfigError, match="^workers: "):
        st.run(workers=999)
    monkeypatch.setenv("SIM_MAX_ADJUSTMENTS", "1")
    with pytest.raises(ConfigError, match="SIM_MAX_ADJUSTMENTS"):
        st.run()
    assert list(base.iterdir()) == []


def test_an_interrupted_run_without_out_names_where_it_resumes(tmp_path, monkeypatch):
    base = tmp_path / "tmp"
    base.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(base))
    st = sim.load(PLATE, **SMALL)

    def cut_short(*args, **kwargs):  # after every trial: the chunks are on disk
        raise KeyboardInterrupt

    with monkeypatch.context() as m:
        m.setattr(network_run, "write_points", cut_short)
        with pytest.raises(KeyboardInterrupt) as info:
            st.run(figures=False)
    (note,) = info.value.__notes__
    (made,) = base.iterdir()
    out = made / "network"
    assert (
        note
        == f"sim: the finished chunks are kept in {made}: run(out={str(out)!r}) resumes the run"
    )
    assert len(list(made.glob(".network.partial/trials/part-*/chunk-*.parquet"))) == 20
    res = st.run(out=out, figures=False)
    assert res.path == out and res.table("points").num_rows == 25


@pytest.mark.parametrize(
    "change",
    [
        lambda h: h.config.__setitem__("errors.setting_sigma_um", "abc"),
        lambda h: h.config.__setitem__("study", "brown_dilution"),
        lambda h: h.overrides.__setitem__("seed", 99),
    ],
    ids=["a key's value", "the study", "an override"],
)
def test_a_handle_changed_in_place_is_refused(change):
    st = sim.load(TABLE1, trials=40, seed=1)
    change(st)
    for call in (st.run, st.estimate, lambda: st.replace(trials=60)):
        with pytest.raises(ConfigError, match=r"^config: .* changed in place since sim\.load"):
            call()


def test_a_handle_changed_and_changed_back_runs_as_loaded(tmp_path):
    st = sim.load(PLATE, **SMALL)
    st.config["seed"], seed = 99, st.config["seed"]
    st.config["seed"] = seed
    assert st.run(out=tmp_path / "o", figures=False).table("points").num_rows == 25
