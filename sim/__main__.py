"""``python -m sim`` and the ``sim`` command: BLAS single-threaded, matplotlib's notes about
an unwritable config directory kept quiet, then the command line."""

from sim.ends import ascii_punctuation, open_standard_streams
from sim.env_vars import refuse_bad_variables
from sim.threads import (
    interrupt_while_loading,
    refuse_bad_environment,
    script_of_another_copy,
    single_threaded_blas,
)

open_standard_streams()  # 2>&-: before any file takes its descriptor
ascii_punctuation()  # PYTHONIOENCODING=ascii: an interval's dash as '-'
loaded = interrupt_while_loading("sim")  # Ctrl-C during the imports: one line, exit 130

import logging  # noqa: E402 - after the guard: Ctrl-C in this import was a traceback
import sys  # noqa: E402

refuse_bad_environment("sim")  # a variable NumPy cannot load with: one line, exit 2
single_threaded_blas()  # before NumPy loads (sim.cli imports it)
refuse_bad_variables("sim")  # SIM_NO_JIT=0, NUMBA_OPT=fast: one line, exit 2


class _CacheDirNotes(logging.Filter):
    """Drops matplotlib's warnings that its config directory (``MPLCONFIGDIR``, else under
    ``HOME`` or ``XDG_CACHE_HOME``) is not writable: it then uses a temporary one of its own,
    removed at exit, and a run is as good as any other; two lines of advice on every run
    (a read-only HOME, a container) are not the command's to print."""

    WORDS = (
        "mkdir -p failed for path",
        "is not a writable directory",
        "temporary cache directory",
        "Could not save font_manager cache",  # a full HOME: the cache is made again next time
    )

    def filter(self, record: logging.LogRecord) -> bool:
        return not any(w in str(record.msg) for w in self.WORDS)


for _name in ("matplotlib", "matplotlib.font_manager"):  # before matplotlib loads (a logger's
    logging.getLogger(_name).addFilter(_CacheDirNotes())  # filter sees its own records only)

from sim.cli import main as command  # noqa: E402
from sim.ends import finish  # noqa: E402
from sim.mc.children import die_with_parent  # noqa: E402
from sim.stops import run_program  # noqa: E402


def main() -> int:
    """The ``sim`` program (``python -m sim``, the ``sim`` script): the command line, and a
    stop signal after it returned ends the process with its exit code (:mod:`sim.stops`)."""
    if (gone := die_with_parent()) is not None:  # a child of sim.batch or make verify that died
        try:
            print(f"sim: {gone}", file=sys.stderr)
        except (OSError, ValueError):  # no one reads it: the driver died
            pass
        return 130
    words = script_of_another_copy()  # copy/.venv/bin/sim: the original's code, not the copy's
    if words is not None:
        print(f"sim: error: {words}", file=sys.stderr)
        return 2
    return finish("sim", lambda: run_program("sim", command, loaded))  # stdout flushed: sim.ends


if __name__ == "__main__":
    sys.exit(main())
loaded()  # imported (the sim script, the tests): the default handlers until main runs
