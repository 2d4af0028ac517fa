"""The assertion the door tests share: a command refused bad input with exit 2 and one line on
stderr (no traceback) that holds every needle; the line is returned for more checks. Every
door test asserts its one line with :func:`one_line` (one rule, no copies of it). And a small
program run in a fresh Python, for what a test must not do to its own process."""

import re
import subprocess
import sys
from pathlib import Path
from types import SimpleNamespace

#: how the one line of the sim command and of make verify begin
SIM_ERROR = "sim: error: "
VERIFY_ERROR = "sim verify: error: "
#: every one line begins with the program that says it (sim, sim.batch, sim verify, the
#: benchmarks) and a colon
PROGRAM = re.compile(r"(?:sim(?:\.batch| verify)?|benchmarks): \S")


def one_line(capsys, rc: int, *needles: str, prefix: str = "", code: int = 2) -> str:
    """The stderr captured by ``capsys`` since its last read, checked as above: exit ``code``
    (2; 130 for an interrupted command) and exactly one line, ended by its newline, that
    begins with its program's name (:data:`PROGRAM`) and ``prefix`` (:data:`SIM_ERROR`, say)
    and holds every needle; returned without the newline."""
    err = capsys.readouterr().err
    line = err.removesuffix("\n")
    assert rc == code and err.endswith("\n") and "\n" not in line, (rc, err)
    assert PROGRAM.match(line) and "Traceback" not in err, (rc, err)
    assert line.startswith(prefix) and all(n in line for n in needles), err
    return line.strip()


def one_line_of(proc: subprocess.CompletedProcess, *needles: str, prefix: str = "", code=2):
    """:func:`one_line` for a command run as a subprocess (its ``stderr`` captured as text):
    the same checks on ``proc.returncode`` and ``proc.stderr``; the line is returned."""

    captured = SimpleNamespace(readouterr=lambda: SimpleNamespace(out="", err=proc.stderr))
    return one_line(captured, proc.returncode, *needles, prefix=prefix, code=code)


def python_lines(*lines: str) -> subprocess.CompletedProcess:
    """Run ``lines`` as a program in a fresh Python (signals, imports and forks of its own,
    apart from the test process); its exit code and text output."""
    code = "\n".join(lines) + "\n"
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)


def check_argv(study: str, *sets: str) -> list[str]:
    """``sim check studies/<study>.toml --set S ...`` as ``sim.cli.main``'s arguments."""
    argv = ["check", str(Path(__file__).resolve().parent.parent / "studies" / f"{study}.toml")]
    for s in sets:
        argv += ["--set", s]
    return argv
