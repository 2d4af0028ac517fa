"""``python -m sim`` and the ``sim`` command: BLAS single-threaded, then the command line."""

import sys

from sim.threads import single_threaded_blas

single_threaded_blas()  # before NumPy loads (sim.cli imports it)

from sim.cli import main  # noqa: E402

if __name__ == "__main__":
    sys.exit(main())
