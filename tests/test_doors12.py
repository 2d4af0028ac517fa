"""The classes of the eleventh sweep of bad inputs (issue 26, doors12: the environment and
a new user's first hour), one case each; each failed on the code before its fix.

* ``python -OO`` (docstrings stripped): ``sim`` ended in "internal error: AttributeError"
  and ``python -m sim.batch`` in a traceback, since their usage text is their docstring;
  it is now read from the source (:func:`sim.cli_args.module_doc`);
* ``MPLBACKEND`` naming a backend matplotlib does not know: a run computed every trial,
  then failed at its first figure; the suite draws PNG files through Agg only, so the
  variable is set aside while matplotlib loads (:mod:`sim.report.mpl`).
"""

import os
import subprocess
import sys

from sim import batch, cli
from sim.cli_args import module_doc


def _python(*args, env=None):
    return subprocess.run(
        [sys.executable, *args],
        capture_output=True,
        text=True,
        timeout=120,
        env={**os.environ, **(env or {})},
    )


def test_python_OO_keeps_the_usage_text():
    assert module_doc(None, cli.__file__) == cli.__doc__ == cli.DOC
    assert module_doc(None, batch.__file__) == batch.__doc__
    p = _python("-OO", "-m", "sim.batch", "--help")
    assert p.returncode == 0 and "Traceback" not in p.stderr, p.stderr
    assert "python -m sim.batch" in p.stdout and "--stale-only" in p.stdout


def test_an_unknown_MPLBACKEND_does_not_stop_the_figures():
    code = (
        "import os\n"
        "from sim.report import mpl\n"
        "mpl.pyplot.figure()\n"
        "print(mpl.pyplot.get_backend().lower(), os.environ['MPLBACKEND'])\n"
    )
    p = _python("-c", code, env={"MPLBACKEND": "nosuch"})
    assert p.returncode == 0, p.stderr
    assert p.stdout.split() == ["agg", "nosuch"]  # drawn through Agg; the variable put back
