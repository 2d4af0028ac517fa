"""Doors sweep 37e: the environment as a door, the part 32e and 33e left (the ``SIM_*`` and
``NUMBA_*`` variables, the output's encoding, an address-space limit under the estimate), one
case per class found; each failed on the code before its fix.

* a ``NUMBA_`` variable numba cannot read (``NUMBA_OPT=garbage``, ``NUMBA_DISABLE_JIT=abc``,
  ``NUMBA_BOUNDSCHECK=x``): numba, imported by the kernels' first call in the middle of a run,
  printed a warning of some ten lines carrying a traceback, and the run went on with numba's
  default, exit 0; ``NUMBA_NUM_THREADS=0`` failed the run's first chunk with "ValueError:
  Number of threads specified must be > 0.", naming no variable. Every entry point now refuses
  it when it starts, and ``sim.load`` raises ``ConfigError``, one line naming the variable
  (:func:`sim.env_vars.numba_variables_problem`).
* ``SIM_NO_JIT=0`` (or ``yes``, ``false``: any value but an empty one) turned the compiled
  kernels off without a word: a run on the slow Python path, its numbers other in the last
  digits, recorded as ``SIM_NO_JIT=0``. The variable is now 1, or empty or unset; anything else
  is one line naming it (:func:`sim.env_vars.sim_variables_problem`).
* a run whose memory estimate is over what ``ulimit -v`` (or ``ulimit -d``) leaves the process
  (brown_table1 on a 100 x 100 plate, 0.9 GiB, under ``ulimit -v 1400000``) computed every
  chunk (30 s here, hours for a large run), then failed on "MemoryError: Unable to allocate
  183. MiB", naming no limit; ``sim check`` passed it. Both now refuse it before any work,
  naming the limit, the estimate and the room left (:func:`sim.room.check_room`).
* a small limit of data (``ulimit -d``, which the 1 GiB floor of ``ulimit -v`` did not look
  at): under about 150 MB every command hung for good while it loaded SciPy (OpenBLAS
  retrying its allocations); at 450 MB a 40-trial run failed on a 10 MiB array, advising to
  "reduce trials, chunk or the sizes". Every entry point now refuses to start under 1 GiB of
  data, one line naming ``ulimit -d`` (:data:`sim.env_vars.MIN_DATA_KB`).
* an output encoding that cannot show the suite's own en dash (``PYTHONIOENCODING=ascii``, or
  ``LC_ALL=C`` with ``PYTHONUTF8=0``): ``sim run`` computed and published its results, then
  ended with exit 2 on its closing summary's first interval ("the output (encoding ascii) cannot
  show '\\u2013'"), and ``sim show`` of any results failed so. The dash is now written as ``-``
  there (:func:`sim.ends.ascii_punctuation`); a name of the user's the encoding cannot show is
  still refused in one line.

Held (a harness outside the project ran ``sim check``/``run``/``show``/``report``, ``python -m
sim.batch``, ``python -m sim.report.verify`` and the API): ``SIM_MAX_MEMORY_GB`` and
``SIM_MAX_ADJUSTMENTS`` empty, blank, text, negative, zero, NaN, infinite, ``1e400``,
``1e-400``, fullwidth digits, with spaces (refused naming the variable, or read as the number;
empty is the default); ``SIM_DEBUG`` of any value; ``SIM_STOP_WITH_PARENT`` garbage;
``OMP_NUM_THREADS``, ``OPENBLAS_NUM_THREADS``, ``MKL_NUM_THREADS`` at 0, -1, text or 100000 and
``OPENBLAS_CORETYPE`` garbage (the run as ever); ``NUMBA_CACHE_DIR`` missing or ``/dev/null``;
``TMPDIR`` a file, relative, missing, empty, with spaces and non-ASCII (``make verify`` and the
API pass it over for ``/tmp`` or use it); ``HOME`` unset; ``TERM`` unset, ``NO_COLOR``;
``MPLBACKEND=TkAgg``; ``MPLCONFIGDIR`` a file; ``PYTHONWARNINGS=error`` (also with 2 workers);
``PYTHONDEVMODE=1``; ``COLUMNS`` 0, -1, text or 100000; a non-UTF-8 ``--out`` under
``LC_ALL=POSIX PYTHONUTF8=0`` (named); standard input closed (``<&-``) for every command and
executor; ``sim run``, ``python -m sim.batch`` and ``make verify`` piped into ``head -1``.
"""

from __future__ import annotations

import os
import resource
import subprocess
import sys
from pathlib import Path

import pytest
from oneline import one_line_of

import sim
from sim.mc.config import ConfigError

ROOT = Path(__file__).resolve().parents[1]
TABLE1 = str(ROOT / "studies" / "brown_table1.toml")


def _sim(*argv: str, env: dict | None = None, preexec=None, timeout=120):
    """``python -m sim ARGV`` in the project's root with ``env`` added to the environment."""
    return subprocess.run(
        [sys.executable, "-m", "sim", *argv],
        cwd=ROOT,
        env={**os.environ, **(env or {})},
        capture_output=True,
        text=True,
        timeout=timeout,
        preexec_fn=preexec,
    )


@pytest.mark.parametrize(
    "var, value, words",
    [
        ("NUMBA_OPT", "garbage", "numba cannot read its value 'garbage'"),
        ("NUMBA_DISABLE_JIT", "abc", "invalid literal for int()"),
        ("NUMBA_NUM_THREADS", "0", "numba cannot load with it"),
    ],
)
def test_a_numba_variable_numba_cannot_read_is_one_line_naming_it(var, value, words):
    proc = _sim("check", TABLE1, env={var: value})
    line = one_line_of(proc, f"sim: error: {var}: ", words)
    assert proc.stdout == "", line
    if var != "NUMBA_OPT":
        return  # sim.load's check is the same function: once is enough
    api = subprocess.run(
        [sys.executable, "-c", f"import sim; sim.load({TABLE1!r})"],
        env={**os.environ, var: value},
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert api.returncode == 1 and f"ConfigError: {var}: " in api.stderr, api.stderr
    assert "warn" not in api.stderr, api.stderr  # numba's own warning is not printed too


@pytest.mark.parametrize("value", ["0", "yes"])
def test_sim_no_jit_other_than_1_or_empty_is_refused(value, monkeypatch):
    line = one_line_of(_sim("check", TABLE1, env={"SIM_NO_JIT": value}), "SIM_NO_JIT", "must be 1")
    assert f"got {value!r}" in line
    monkeypatch.setenv("SIM_NO_JIT", value)
    with pytest.raises(ConfigError, match="SIM_NO_JIT: must be 1"):
        sim.load(TABLE1, trials=40)
    for fine in ("1", ""):
        monkeypatch.setenv("SIM_NO_JIT", fine)
        sim.load(TABLE1, trials=40)


def _limited(limit: int, kb: int):
    """A ``preexec_fn`` setting the soft ``limit`` to ``kb`` kB (skipped under a lower hard one)."""
    hard = resource.getrlimit(limit)[1]
    if hard != resource.RLIM_INFINITY and hard < kb * 1024:
        pytest.skip("the hard limit is lower than the test's")
    return lambda: resource.setrlimit(limit, (kb * 1024, hard))


@pytest.mark.parametrize(
    "limit, words", [(resource.RLIMIT_AS, "ulimit -v"), (resource.RLIMIT_DATA, "ulimit -d")]
)
def test_a_run_over_the_room_a_limit_leaves_is_refused_before_it_starts(limit, words):
    big = ["--set", "plate.grid=120", "--set", "plate.spacing_mm=1"]
    big += ["--set", "trials=2000", "--set", "chunk=10"]  # about 1.46 GiB
    proc = _sim("check", TABLE1, *big, preexec=_limited(limit, 1200 * 1024))  # over the floor
    one_line_of(
        proc, "the run needs about 1.46 GiB", f"{words} (1228800 kB) leaves", f"raise {words}"
    )
    if limit == resource.RLIMIT_AS:  # without a limit: as before
        assert _sim("check", TABLE1, *big).returncode == 0


def test_a_command_under_a_small_data_limit_does_not_start():
    """``ulimit -d 100000``: every command hung while loading SciPy (no line, no end)."""
    proc = _sim("check", TABLE1, preexec=_limited(resource.RLIMIT_DATA, 100_000), timeout=60)
    one_line_of(proc, "not enough memory: ulimit -d is 100000 kB", "at least 1048576 kB")


@pytest.mark.long
def test_an_ascii_output_shows_the_suites_dash_as_ascii():
    proc = _sim("show", "results/brown_table1", env={"PYTHONIOENCODING": "ascii"})
    assert proc.returncode == 0 and "cannot show" not in proc.stderr, proc.stderr
    utf8 = _sim("show", "results/brown_table1", env={"PYTHONIOENCODING": "utf-8"}).stdout
    assert "\u2013" in utf8 and proc.stdout == utf8.replace("\u2013", "-")
    name = ["--set", 'network.name="caf\u00e9"']  # the user's own name: refused as before
    one_line_of(
        _sim("check", "studies/network_brown.toml", *name, env={"PYTHONIOENCODING": "ascii"}),
        "cannot show '\\xe9'",
    )
