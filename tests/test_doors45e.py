"""Doors sweep 45e: every entry point checks the environment, the commands' modules imported or
called from Python (``import sim.cli``, ``sim.batch``, ``sim.report.verify``, ``benchmarks``;
``sim.batch.main([...])``, ``sim.report.verify.cli.main([...])``, ``python -m sim.cli``), one
case per class found; each failed on the code before its fix.

* ``import sim.cli`` (``sim.batch``, ``sim.report.verify``, ``sim.report.verify.cli``,
  ``benchmarks``) from Python, not run as its command, skipped the checks the commands make as
  they start: ``SOURCE_DATE_EPOCH=abc`` was a traceback from ``numpy.f2py`` ("ValueError:
  invalid literal for int()"), ``TQDM_NCOLS=abc`` one from ``tqdm.utils``,
  ``ARROW_DEFAULT_MEMORY_POOL=System`` or ``ARROW_USER_SIMD_LEVEL=bogus`` a line of Arrow's own.
  Importing them now raises the ``sim.ConfigError`` naming the variable, as ``import sim.api``
  does (:mod:`sim.entry_env`); so ``sim.cli.main([...])`` cannot be reached with them, and
  returns 2 with the ``sim`` command's line on what is read later (``SIM_NO_JIT``, ``NUMBA_``).
* ``sim.batch.main([...])``, ``sim.report.verify.cli.main([...])`` and ``benchmarks.main``
  from Python did not refuse ``SIM_NO_JIT=0`` (or ``NUMBA_OPT=fast``, a ``ulimit -d`` too
  small) as ``python -m sim.batch``, ``make verify`` and ``python -m benchmarks`` do: the batch started a ``sim run`` for each study, each of
  which refused it, one line a study and a summary line, and verify re-ran every study into a
  scratch directory, each re-run refusing it, and the benchmark timed the Python path. They
  now refuse it before anything starts, one line, exit 2.
* ``python -m sim.cli`` (the module run as the command, not ``python -m sim``) with one of the
  variables above was a traceback (from ``numpy.f2py`` or ``tqdm.utils``; with the first fix
  alone, of the ``ConfigError``): it is now the ``sim`` command's one line and exit 2.

Held (a harness outside the project): ``python -m sim``, ``runpy.run_module("sim")``, the
``sim`` script, ``python -m sim.batch``, ``python -m sim.report.verify`` and ``python -m
benchmarks`` refuse the four variables above with one line and exit 2; ``import sim.api``
with ``TQDM_NCOLS=abc`` still loads (tqdm loads with the first bar, as docs/python.md says);
``sim.load`` raises the ``ConfigError`` for each.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
from oneline import one_line, one_line_of

ROOT = Path(__file__).resolve().parents[1]

#: a program that imports a module and prints the ConfigError it raises, if any
IMPORT = """
import sys
from sim.mc.config import ConfigError
try:
    __import__(sys.argv[1])
except ConfigError as e:
    print("ConfigError:", e)
"""


@pytest.mark.parametrize(
    "variable, value",
    [("SOURCE_DATE_EPOCH", "abc"), ("TQDM_NCOLS", "abc"), ("ARROW_DEFAULT_MEMORY_POOL", "System")],
)
@pytest.mark.parametrize("module", ["sim.cli", "sim.batch", "sim.report.verify.cli", "benchmarks"])
def test_importing_a_command_module_checks_the_environment(module, variable, value):
    env = {**os.environ, variable: value}
    p = subprocess.run(
        [sys.executable, "-c", IMPORT, module],
        capture_output=True,
        text=True,
        timeout=120,
        cwd=ROOT,
        env=env,
    )
    assert p.returncode == 0 and "Traceback" not in p.stderr, p
    assert p.stdout.startswith(f"ConfigError: {variable}: ") and p.stdout.count("\n") == 1, p


def test_the_batch_from_python_refuses_what_its_command_refuses(tmp_path, monkeypatch, capfd):
    import sim.batch

    monkeypatch.setenv("SIM_NO_JIT", "0")
    files = [str(ROOT / "studies" / f) for f in ("wolf_polynomial.toml", "brown_table1.toml")]
    rc = sim.batch.main(["--results", str(tmp_path / "r"), *files, "--", "--trials", "10"])
    one_line(capfd, rc, "SIM_NO_JIT", "'0'", prefix="sim.batch: error: ")
    assert not (tmp_path / "r").exists()


def test_verify_from_python_refuses_what_its_command_refuses(tmp_path, monkeypatch, capfd):
    from sim.report.verify.cli import main

    monkeypatch.setenv("SIM_NO_JIT", "0")
    scratch = tmp_path / "scratch"
    rc = main(["--results", str(ROOT / "results"), "--study", "wolf_polynomial",
               "--scratch", str(scratch), "--trials", "400"])  # fmt: skip
    one_line(capfd, rc, "SIM_NO_JIT", "'0'", prefix="sim verify: error: ")
    assert not scratch.exists()


def test_python_m_sim_cli_refuses_in_one_line_as_python_m_sim():
    env = {**os.environ, "TQDM_NCOLS": "abc"}
    p = subprocess.run(
        [sys.executable, "-m", "sim.cli", "check", "studies/wolf_polynomial.toml"],
        capture_output=True,
        text=True,
        timeout=120,
        cwd=ROOT,
        env=env,
    )
    one_line_of(p, "TQDM_NCOLS", prefix="sim: error: ")


def test_the_benchmarks_from_python_refuse_what_their_command_refuses(monkeypatch, capsys):
    from benchmarks import main

    monkeypatch.setenv("SIM_NO_JIT", "0")
    one_line(capsys, main(["--help"]), "SIM_NO_JIT", prefix="benchmarks: error: ")
