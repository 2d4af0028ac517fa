"""The classes of the sweep doors47j (brief A47: the Python API in notebooks, threads and
processes), one case each; each failed on the code before its fix.

* A run whose workers start by ``forkserver`` (``run(workers=2)`` in a process with threads
  of the caller's own: a notebook's, a script's timer) or ``spawn`` (``executor="dask"``)
  fixed the process's ``multiprocessing`` start method for good: starting such a child reads
  ``multiprocessing.get_start_method()`` for its preparation data, which sets the default.
  The caller's ``multiprocessing.set_start_method("spawn")`` after the run then failed with
  "context has already been set", against docs/python.md's promise (doors31b held it for a
  forked pool only). The method is put back unset when the last run of the process ends
  (:mod:`sim.start_method`).
* A script read from standard input (``python - < script.py``: ``__file__`` is ``<stdin>``)
  whose run starts ``forkserver`` or ``spawn`` workers (a thread of its own, or Dask): each
  worker ran ``<stdin>`` again as the main module, printed a ``FileNotFoundError`` traceback,
  and the run was refused as a script without its main guard. Such a ``__file__`` is hidden
  while runs are under way (:mod:`sim.start_method`), so the workers import only the suite.
* A Dask run left the variables its nannies set before spawning each worker in the caller's
  ``os.environ`` (``OMP_NUM_THREADS``, ``MKL_NUM_THREADS``, ``OPENBLAS_NUM_THREADS`` at 1,
  ``MALLOC_TRIM_THRESHOLD_``, ``PYTHONHASHSEED``, ``__DASK_PARENT_PID``): every process the
  notebook started afterwards inherited them. They are as before once the last run ends.

Held (found right): a run inside ``asyncio.run`` (and from its default executor), with
``sys.stdout``/``sys.stderr`` replaced by ``io.StringIO`` or closed, under ``-W error`` or
``warnings.simplefilter("error")`` (in the main thread or another), under
``np.seterr(all="raise")`` with an ``np.seterrcall`` (left as set), with the caller's own
handlers (or ``SIG_IGN``) for SIGINT, SIGTERM, SIGHUP, SIGUSR1, SIGALRM, SIGQUIT, SIGCHLD
(each given back), the signal mask, ``os.environ``, ``sys.path``, the hooks, the loggers;
the API called in workers of ``spawn``, ``forkserver`` and ``fork`` pools (equal claims),
``run(workers=2)`` in a daemonic worker refused in one line, a ``ProcessPoolExecutor``'s
worker; two studies run by three threads (equal claims for equal configs), two threads into
one ``out`` (the second refused naming it); a run in a script without a main guard that
starts threads refused naming the guard (documented); ``KeyboardInterrupt`` from a timer
mid-run, then the same run again (resumes; without ``out`` the note names it); ``os.chdir``
between runs; ``Results`` pickled to another process; ``sys.stdout``/``stderr``/``stdin``
``None``; ``-W error`` and ``-X dev`` for local and Dask runs; ``warnings.filters`` after
eight runs in four threads.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
NETWORK = str(ROOT / "studies" / "network_plate.toml")


def test_a_forkserver_run_leaves_the_start_method_unset(tmp_path):
    """In a fresh Python with a thread of its own running (so the pool's workers start by
    forkserver): after ``run(workers=2)`` the start method is still unset and the caller's
    ``set_start_method('spawn')`` works (before: 'fork', then "context has already been
    set")."""
    code = "\n".join(
        [
            "import multiprocessing, threading, sim",
            "if __name__ == '__main__':",
            "    stop = threading.Event()",
            "    threading.Thread(target=stop.wait, daemon=True).start()",
            f"    st = sim.load({NETWORK!r}, trials=40, chunk=2)",
            f"    st.run(out={str(tmp_path / 'o')!r}, workers=2, quiet=True, figures=False)",
            "    print(multiprocessing.get_start_method(allow_none=True))",
            "    multiprocessing.set_start_method('spawn')",
            "    print('set')",
            "    stop.set()",
        ]
    )
    script = tmp_path / "script.py"  # forkserver's workers import the main module by path
    script.write_text(code + "\n")
    p = subprocess.run(
        [sys.executable, str(script)],
        capture_output=True,
        text=True,
        cwd=ROOT,
        timeout=300,
        env=_env(),
    )
    assert p.stdout.split() == ["None", "set"], p.stdout + p.stderr[-2000:]


def _env() -> dict:
    """The test's environment with this checkout first on the path (a script's directory,
    not the working directory, is first on its ``sys.path``)."""
    import os

    return {**os.environ, "PYTHONPATH": str(ROOT)}


@pytest.mark.long
def test_a_dask_run_of_a_script_read_from_standard_input(tmp_path):
    """A script piped to ``python -`` (its ``__file__`` is ``<stdin>``, no file) running
    ``executor="dask"``: the spawned workers ran ``<stdin>`` again, each printed a
    ``FileNotFoundError`` traceback, and the run was refused as a script without its main
    guard. It runs now, as from a notebook, ``__file__`` is ``<stdin>`` again after, and the
    variables the nannies set in the caller's environment (``OMP_NUM_THREADS=1``,
    ``PYTHONHASHSEED``, ...) are gone again (before: left set for every later child)."""
    code = "\n".join(
        [
            "import os, sim",
            "before = dict(os.environ)",
            f"st = sim.load({NETWORK!r}, trials=40, chunk=2)",
            f"res = st.run(out={str(tmp_path / 'o')!r}, executor='dask', quiet=True)",
            "print(res.claims().num_rows > 0, __file__)",
            "print(sorted(k for k in {*before, *os.environ} if before.get(k) != os.environ.get(k)))",
        ]
    )
    env = {k: v for k, v in _env().items() if k not in ("OMP_NUM_THREADS", "PYTHONHASHSEED")}
    p = subprocess.run(
        [sys.executable, "-"],
        input=code + "\n",
        capture_output=True,
        text=True,
        cwd=tmp_path,
        timeout=300,
        env=env,
    )
    assert p.returncode == 0, p.stdout + p.stderr[-2000:]
    assert p.stdout.splitlines() == ["True <stdin>", "[]"], p.stdout + p.stderr[-2000:]
    assert "Traceback" not in p.stderr, p.stderr[-2000:]
