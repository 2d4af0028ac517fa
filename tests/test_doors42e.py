"""Doors sweep 42e: the environment as a door, the part 32e, 33e and 37e left (the process's
umask, awkward results paths, ``TMPDIR`` on another file system, a project read-only to its
user, ``SOURCE_DATE_EPOCH``, ``TZ``, the locale, one core, the variables Arrow reads), one case
per class found; each failed on the code before its fix.

* ``SOURCE_DATE_EPOCH`` that is not an integer (``abc``, ``99999999999999999999``) through the
  Python API: the commands refused it (one line), but ``sim.load(...)`` ended in a traceback
  from ``numpy.f2py`` (imported by ``scipy.sparse`` while ``sim.api`` loads), "ValueError:
  invalid literal for int() with base 10: 'abc'". ``sim.load`` now raises ``ConfigError``
  naming the variable before anything loads NumPy (``sim._refuse_unloadable``).
* ``ARROW_DEFAULT_MEMORY_POOL`` naming no allocator of Arrow's (``System``, `` system``): every
  door printed Arrow's own line ("/arrow/cpp/src/arrow/memory_pool.cc:106: Unsupported backend
  'System' ...") and ran on Arrow's default allocator, mimalloc, exit 0, under ``ulimit -v`` or
  ``-d`` too, where the suite asks for the system's. It is now one line naming the variable and
  exit 2 at every entry point, a ``ConfigError`` from ``sim.load``
  (:func:`sim.threads.arrow_variables_problem`). Set empty (Arrow's default too) under
  ``ulimit -d``, it kept the suite from choosing the system's allocator: an empty value is now
  taken as unset there.

Held (a harness outside the project ran ``sim run``/``check``/``show``/``report``, ``python -m
sim.batch``, ``python -m sim.report.verify`` and the API): ``umask 077``, ``000`` and ``002``
(every file and directory of a run, chunks, tables, figures, ``run.json``, ``README.md``, takes
the umask's mode, as docs/cli.md says: under 077 no other user reads them); an ``--out`` with a
colon or a leading dash (written), a line break (refused), a last component of 246 to 250
bytes (refused naming the staging suffix's 255-byte limit); ``TMPDIR=/dev/shm`` (another file
system) for the API's temporary results (the staging directory is beside its output, never
renamed across devices); the project read-only to its user (``setpriv`` as ``nobody`` with only
``CAP_DAC_READ_SEARCH``): ``--out`` elsewhere runs (no ``__pycache__`` needed, numba compiles
uncached), without it ``scratch/`` is named ("cannot write to .../scratch: Permission denied"),
``sim report`` names the ``README.md`` it cannot write; ``TZ`` and ``LC_ALL``/``LC_NUMERIC``
(the suite writes no dates and never calls ``setlocale``: numbers keep their points; figures
are PNG, which carries no date); ``nice`` and ``taskset -c 0`` with ``--workers 2`` (the default
worker count is fixed, 1, not read from the cores).
"""

from __future__ import annotations

import os
import resource
import subprocess
import sys
from pathlib import Path

import pytest
from oneline import one_line_of

ROOT = Path(__file__).resolve().parents[1]
TABLE1 = str(ROOT / "studies" / "brown_table1.toml")

#: sim.load in a process of its own: NumPy and Arrow read these variables once, when they load
LOAD = f"""
import sim
try:
    sim.load({TABLE1!r})
except sim.ConfigError as e:
    print("ConfigError:", e)
"""


def _python(*argv: str, env: dict, preexec=None) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, *argv],
        cwd=ROOT,
        env={**os.environ, **env},
        capture_output=True,
        text=True,
        timeout=120,
        preexec_fn=preexec,
    )


@pytest.mark.parametrize("value", ["abc", "99999999999999999999"])
def test_source_date_epoch_not_an_integer_is_a_config_error_of_sim_load(value):
    proc = _python("-c", LOAD, env={"SOURCE_DATE_EPOCH": value})
    assert proc.returncode == 0 and "Traceback" not in proc.stderr, proc.stderr
    assert proc.stdout.startswith("ConfigError: SOURCE_DATE_EPOCH: must be an integer"), proc


def test_an_arrow_pool_arrow_has_not_is_one_line_naming_it():
    env = {"ARROW_DEFAULT_MEMORY_POOL": "System"}
    proc = _python("-m", "sim", "check", TABLE1, env=env)
    line = one_line_of(proc, "sim: error: ARROW_DEFAULT_MEMORY_POOL: ", "got 'System'")
    assert "memory_pool.cc" not in proc.stderr and proc.stdout == "", line
    batch = _python("-m", "sim.batch", "--help", env=env)
    one_line_of(batch, "sim.batch: error: ARROW_DEFAULT_MEMORY_POOL: ", "mimalloc, jemalloc or")
    api = _python("-c", LOAD, env=env)
    assert api.stdout.startswith("ConfigError: ARROW_DEFAULT_MEMORY_POOL: must be"), api
    assert "memory_pool.cc" not in api.stderr, api.stderr


def test_an_empty_arrow_pool_under_a_data_limit_is_the_systems():
    def limit():  # finite, far above what the suite needs
        resource.setrlimit(
            resource.RLIMIT_DATA, (1 << 42, resource.getrlimit(resource.RLIMIT_DATA)[1])
        )

    code = "import sim, pyarrow as pa; print(pa.default_memory_pool().backend_name)"
    proc = _python("-c", code, env={"ARROW_DEFAULT_MEMORY_POOL": ""}, preexec=limit)
    assert proc.stdout.strip() == "system", proc
