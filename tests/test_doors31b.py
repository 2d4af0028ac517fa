"""The classes of the sweep doors31b (brief A31b: the Python API in a long-lived process, a
notebook or a script that loops, interrupts and goes on), one case each; each failed on the
code before its fix.

* Any run of the API (``workers=1`` or ``2``, quiet or not) fixed the process's
  ``multiprocessing`` start method for good: tqdm's first bar made a
  ``multiprocessing.RLock`` on the default context, and the local pool read the method with
  ``multiprocessing.get_start_method()``, each of which sets the default. The caller's own
  ``multiprocessing.set_start_method("spawn")`` after a run then failed with "context has
  already been set". The suite's bars take a thread lock of their own
  (:func:`sim.mc.progress._bar_class`) and the method is read without fixing it
  (:func:`sim.mc.executors.process_start_method`).
* In a process whose working directory was removed (a notebook started in a scratch
  directory since deleted), ``sim.load`` of an absolute path, and ``run(out=...)`` of an
  absolute one, were refused as "is relative, but the working directory is gone":
  :func:`sim.mc.paths.absolute` joined every path to the working directory. An absolute path
  runs; a relative one is still refused so.

Held (found right, over 20 runs in one process, workers 1 and 2): open descriptors, threads,
child processes, ``atexit`` callbacks, resident memory (about 1 MB a run, caches), signal
handlers (SIGINT's is Python's own after a run and after an interrupted one), the
``unraisablehook``, ``np.geterr()``, the caller's ``rcParams``, ``os.environ``, the working
directory, ``umask``, ``sys.path``, the ``random`` and NumPy global seeds; SIGINT from a
timer at seven moments of a run (chunks, report, figures): the next run into the same
``out`` resumes and its tables are those of an uninterrupted run.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
TABLE1 = str(ROOT / "studies" / "brown_table1.toml")


@pytest.mark.long
def test_a_run_leaves_the_start_method_unset(tmp_path):
    """In a fresh Python: after a run with one worker and one with two, the start method is
    still the caller's to choose."""
    code = "\n".join(
        [
            "import multiprocessing, sim",
            f"st = sim.load({TABLE1!r}, trials=40, chunk=2)",
            "for w in (1, 2):",
            f"    st.run(out={str(tmp_path)!r} + f'/o{{w}}', workers=w, figures=False)",
            "    print(multiprocessing.get_start_method(allow_none=True))",
            "multiprocessing.set_start_method('spawn')",
            "print('set')",
        ]
    )
    p = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, timeout=300
    )
    assert p.stdout.split() == ["None", "None", "set"], p.stdout + p.stderr[-2000:]


@pytest.mark.long
def test_an_absolute_path_runs_where_the_working_directory_is_gone(tmp_path):
    """In a fresh Python whose working directory is removed: the absolute study file and
    ``out`` run; a relative ``out`` is refused naming it."""
    gone = tmp_path / "gone"
    gone.mkdir()
    code = "\n".join(
        [
            "import os, sim",
            f"os.chdir({str(gone)!r}); os.rmdir({str(gone)!r})",
            f"st = sim.load({TABLE1!r}, trials=40, chunk=2)",
            f"print(st.run(out={str(tmp_path / 'o')!r}, figures=False).claims().num_rows > 0)",
            "try:",
            "    st.run(out='rel', figures=False)",
            "except sim.ConfigError as e:",
            "    print(e)",
        ]
    )
    p = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, timeout=300
    )
    assert p.stdout.splitlines() == [
        "True",
        "out: rel is relative, but the working directory is gone (No such file or directory)",
    ], p.stdout + p.stderr[-2000:]
