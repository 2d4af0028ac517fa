"""The argparse base of every command line (``sim``, ``python -m sim.batch``, ``make verify``,
``python -m benchmarks``): a bound on the options one command line may hold.

argparse's time grows with the square of the options given (it looks for the next option
among all of them, once per option): 50,000 ``--set`` ran for over three minutes before
"unknown key", and 50,000 ``--study`` kept ``make verify`` busy as long. A study has a few
hundred keys at most, and a study file holds any number of them.
"""

from __future__ import annotations

import argparse
import sys

from sim.ends import stdout_unwritten

__all__ = ["MAX_OPTIONS", "BoundedParser"]

#: options (arguments starting with "-") one command line may hold
MAX_OPTIONS = 2000


class BoundedParser(argparse.ArgumentParser):
    """argparse that reads at most :data:`MAX_OPTIONS` options; more is ``self.error``."""

    def parse_known_args(self, args=None, namespace=None):
        given = sys.argv[1:] if args is None else args
        n = sum(1 for a in given if str(a).startswith("-"))
        if n > MAX_OPTIONS:
            self.error(
                f"{n:,} options: at most {MAX_OPTIONS:,} (write the keys into a study file, "
                "or pass them to the Python API)"
            )
        return super().parse_known_args(args, namespace)

    def _print_message(self, message, file=None):
        """argparse's, which dropped a failed write (``--help > /dev/full`` with unbuffered
        output: exit 0 and no word); one to standard output is kept for the program's end
        (:func:`sim.ends.flush_stdout`: one line naming it, exit 2)."""
        if not message:
            return
        file = file or sys.stderr
        try:
            file.write(message)
        except (AttributeError, OSError) as e:  # a closed or gone stream: as argparse did
            if isinstance(e, OSError) and file is sys.stdout:
                stdout_unwritten(e)
