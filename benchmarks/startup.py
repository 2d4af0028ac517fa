"""Start-up rows of the benchmark (``startup.parquet``): what a command costs before it does
its work.

Every ``python -m sim ...`` is a fresh process, and the test suite starts hundreds of them
(a refusal, ``--help``, a ``sim check``). Each command of :data:`COMMANDS` is run in a fresh
process :data:`REPEAT` times; ``cpu_s`` is the best child CPU time (user + system: steadier
than wall time on a shared machine), ``wall_s`` that round's wall time. The command line
loads a command's module only when that command runs (:data:`sim.cli.COMMANDS`), so
``sim --version``, ``--help`` and a refused option load no study, runner or SciPy; their
rows carry the :data:`TARGET_S` target (``target_s``; NaN on the rows of commands that load
a study, whose cost is the study's code; the rows ``keys of ...`` read one study's keys, as
``sim check`` and :func:`sim.load` validate against them: the target applies to the kinds
whose keys need neither the engine nor the claim machinery). ``exit`` is the command's exit
code (2 on the refusals, as they should be). Nothing is written: the refused ``sim check`` names a study
file that does not exist.
"""

from __future__ import annotations

import resource
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from sim.mc.children import ended

__all__ = ["COMMANDS", "REPEAT", "TARGET_S", "startup_rows"]

#: the CPU seconds a command that loads no study may take before it ends (issue 26's T50:
#: 1.1 to 1.4 s before, every command loading the whole suite)
TARGET_S = 0.45
#: rounds per command (the best counts)
REPEAT = 3
#: the study file of the rows that check one (the project's, from wherever the benchmark runs)
WOLF = str(Path(__file__).resolve().parent.parent / "studies" / "wolf_polynomial.toml")
#: the code of the rows that read a study's keys alone (``sim.studies.get_study``)
_KEYS = "from sim.studies import get_study; get_study({!r}).schema"
#: row name -> (arguments of ``python``, its expected exit code, whether TARGET_S applies)
COMMANDS = {
    "sim --version": (["-m", "sim", "--version"], 0, True),
    "sim --help": (["-m", "sim", "--help"], 0, True),
    "sim check --bad-option": (["-m", "sim", "check", "--bad-option", "x.toml"], 2, True),
    "sim check (bad study name)": (["-m", "sim", "check", "~no-such.toml"], 2, True),
    "sim check (no such file)": (["-m", "sim", "check", "no-such-study.toml"], 2, False),
    "sim check wolf_polynomial": (["-m", "sim", "check", WOLF], 0, False),
    # refused after the file is read (issue 26's T54: 1.2 and 1.9 s, the command's modules
    # loading the run, the claim rules and the report first; sim.room still loads SciPy, an
    # unknown key every kind's keys)
    "sim check wolf (bad value)": (["-m", "sim", "check", WOLF, "--set", "trials=-1"], 2, False),
    "sim check wolf (unknown key)": (["-m", "sim", "check", WOLF, "--set", "nosuch=1"], 2, False),
    "sim.batch --help": (["-m", "sim.batch", "--help"], 0, False),
    # a study's keys (what sim check and sim.load validate against) without its run code
    # (issue 26's T52: 1.3 to 1.6 s, the package loading its run, report and claim book)
    "keys of wolf_polynomial": (["-c", _KEYS.format("wolf_polynomial")], 0, True),
    "keys of salsig_encoders": (["-c", _KEYS.format("salsig_encoders")], 0, True),
    "keys of brown_table1": (["-c", _KEYS.format("brown_table1")], 0, False),
}


def _cpu(cmd: list[str], code: int, what: str) -> tuple[float, float]:
    """``(cpu_s, wall_s)`` of the child process ``cmd``, which must exit with ``code``."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t = time.perf_counter()
    done = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - t
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if done.returncode != code:
        last = (done.stderr.strip().splitlines() or ["(no message)"])[-1]
        raise RuntimeError(f"bench: {what} {ended(done.returncode)}, not exit {code}: {last}")
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime), wall


def startup_rows(quick: bool = False) -> dict[str, list]:
    """The columns of ``startup.parquet``: ``command``, ``exit``, ``cpu_s``, ``wall_s``,
    ``target_s``, ``within_target`` (false where there is no target). ``quick``: one round."""
    cols = ("command", "exit", "cpu_s", "wall_s", "target_s", "within_target")
    rows: dict[str, list] = {c: [] for c in cols}
    for name, (args, code, targeted) in COMMANDS.items():
        best = min(
            (_cpu([sys.executable, *args], code, name) for _ in range(1 if quick else REPEAT)),
            key=lambda r: r[0],
        )
        target = TARGET_S if targeted else np.nan
        for c, v in zip(cols, (name, code, best[0], best[1], target, bool(best[0] <= target))):
            rows[c].append(v)
        print(f"{name:>28}: cpu {best[0]:5.2f} s, wall {best[1]:5.2f} s")
    return rows
