"""Reproducibility verified, not promised: re-run the studies and compare with committed results.

``python -m sim.report.verify`` (``make verify``) re-runs every study of a results directory
(its study file in ``studies/``, or in ``--studies DIR`` for the results of study files
kept elsewhere) into a scratch directory and compares, file by file and column
by column, the Parquet tables there with the committed ones, each column by the rule declared
with it for the kind of number it holds (:mod:`sim.mc.tolerance`; docs/reproducibility.md):

* ``exact`` (labels, counts, flags, and every ``verdict``, ``outcome`` and ``holds`` column,
  in any table): any change fails;
* ``arithmetic``: within the bound from its conditioning, ``cond * eps`` relative plus ``atol``
  (the default for a number that declares nothing: 1e-7 relative plus 1e-9);
* ``mc``: beyond that, a fraction of its Monte-Carlo standard error (from its row's interval);
* ``chain``: within its Monte-Carlo interval;
* ``axial``/``circular``: modulo the period; a null (an undefined value, with its reason)
  matches a null only;
* other text columns: listed when they differ (notes format numbers), never a failure;
* the set of files, their columns and row counts must be the same.

Results made with overrides (``sim run --set``, ``--trials``, ``--seed``, ``--chunk``; the
API's keys) are re-run with exactly those their ``run.json`` records (``overrides``;
:mod:`sim.mc.overrides`, which passes on only ``--set KEY=VALUE`` of a key of the run's own
config), so a study file edited since the run still gives another config.

``--trials N`` (with ``--set KEY=VALUE`` for other trial counts) re-runs with fewer trials and
compares at the Monte-Carlo level: ``mc`` and ``chain`` columns within ``MC_K`` combined
standard errors of the two runs, columns declared ``analytic`` by their rule, the rest not at
all, and no verdict (a smaller run may be inconclusive where the full one decides).
``tests/test_verify.py`` runs it under another numerical path (``OPENBLAS_CORETYPE``,
``SIM_NO_JIT=1``, another worker count): the environment passes to the re-runs.

A full comparison of every study is written to ``<results>/reproducibility.parquet`` (one row
per study, with the sha256 of the tables it read, and the machine and package versions in the
provenance: :mod:`sim.report.verify.record`) for the report's *Reproducibility* section, which
marks results changed since as not checked now. A bad option, an unknown study, an empty
results directory or a re-run this machine cannot run (its scratch directory full or read-only,
memory short, a re-run killed by a signal) is one line and exit 2; a failed comparison exit 1. ``--scratch`` replaces only what the suite wrote
there (a directory with its ``run.json``); anything else is refused, never deleted.
"""

import sys

from sim.env_vars import refuse_bad_variables
from sim.threads import interrupt_while_loading, refuse_bad_environment

# python -m sim.report.verify imports this package first (sys.argv[0] is "-m" meanwhile):
# Ctrl-C during its imports is one line and exit 130 (sim.report.verify.__main__). A host
# process may have no sys.argv, or None (an embedded Python): every study imports this.
_as_main = list(getattr(sys, "argv", None) or [])[:1] == ["-m"]
_loaded = interrupt_while_loading("sim verify") if _as_main else (lambda: None)
if _as_main:
    refuse_bad_environment("sim verify")  # a variable NumPy cannot load with: one line, exit 2
    refuse_bad_variables("sim verify")  # SIM_NO_JIT=0, NUMBA_OPT=fast: one line, exit 2
else:  # imported from Python (sim.report.verify.cli.main([...])): a ConfigError naming it
    import sim.entry_env  # noqa: F401

from sim.report.verify.cli import main  # noqa: E402
from sim.report.verify.record import markdown, write_record  # noqa: E402
from sim.report.verify.rerun import rerun_study, study_dirs, verify  # noqa: E402
from sim.report.verify.rules import (  # noqa: E402
    DEFAULT_ATOL,
    DEFAULT_RTOL,
    Comparison,
    VerifyError,
    compare_dirs,
    compare_tables,
)

_loaded()

__all__ = [
    "compare_dirs",
    "compare_tables",
    "verify",
    "main",
    "markdown",
    "rerun_study",
    "study_dirs",
    "write_record",
    "DEFAULT_RTOL",
    "DEFAULT_ATOL",
    "Comparison",
    "VerifyError",
]
