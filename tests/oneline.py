"""The assertion the door tests share: a command refused bad input with exit 2 and one line on
stderr (no traceback) that holds every needle; the line is returned for more checks. And a small
program run in a fresh Python, for what a test must not do to its own process."""

import subprocess
import sys


def one_line(capsys, rc: int, *needles: str) -> str:
    """The stderr captured by ``capsys`` since its last read, checked as above."""
    err = capsys.readouterr().err.strip()
    assert rc == 2 and "\n" not in err and "Traceback" not in err, (rc, err)
    assert all(n in err for n in needles), err
    return err


def python_lines(*lines: str) -> subprocess.CompletedProcess:
    """Run ``lines`` as a program in a fresh Python (signals, imports and forks of its own,
    apart from the test process); its exit code and text output."""
    code = "\n".join(lines) + "\n"
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
