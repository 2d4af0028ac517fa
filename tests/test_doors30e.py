"""The classes of the sweep doors30e (brief D30e: the same results by every route), one case
each; each failed on the code before its fix. The harness that found them (brown_table1,
salsig_encoders and a small network at about 200 trials, each run by ``sim run`` on 1 and 2
workers, the Python API, ``python -m sim.batch``, interrupted by SIGINT, SIGTERM or SIGKILL
and resumed by each of the three, from another working directory, through a symbolic link,
from a clone and a copy of the project, under other ``PYTHONHASHSEED``, BLAS thread counts,
``TZ`` and locale, as a ``[sweep]`` against its ``--set`` runs, and from a study file with
its keys reordered, commented, spelled otherwise or written at their defaults; every file
compared byte for byte, then table by table and key by key of its metadata with pyarrow)
lives outside the project.

* ``sim.load(...).run(out=...)`` wrote no README.md: the results directory of the Python API
  lacked the file ``sim run`` and ``python -m sim.batch`` write into theirs (and that
  ``run.json`` lists), so the same run by two doors gave two directories; a run started by
  ``sim run``, interrupted and finished by the API ended without it too. ``run()`` now writes it
  as ``sim run`` does (:func:`sim.report.run_summary.write_run_readme`, into the sealed staging
  directory before the results are published).

What held (every file byte-identical, the README's directory name aside): 1 and 2 workers,
the batch, every interruption resumed by any of the three doors, ``--chunk`` or ``--set
chunk=`` at the chunk ``--trials`` picks, another working directory, a symbolic link to the
study file or to ``studies/``, a ``git clone`` at another path (a copy without ``.git``:
``git_commit`` is ``unknown`` in the provenance, nothing else), ``PYTHONHASHSEED``,
``OMP_NUM_THREADS``/``OPENBLAS_NUM_THREADS`` = 1, ``TZ``, ``LANG``/``LC_ALL``, ``python -O``,
``umask 077``, ``SOURCE_DATE_EPOCH``; a ``[sweep]`` cell against the ``--set`` run of its
values (``seed_mode = "common"``: the study's seed; ``"spawn"``: ``--seed`` the cell's
recorded seed; the chunks' provenance names the sweep and cell); a study file reordered,
commented, written with inline tables, dotted keys, ``1_024``, ``4.5e1``, an integer for a
float key, or listed by ``sim check`` and saved: the same config and config hash.
"""

from pathlib import Path

import sim
from sim.cli import main

ROOT = Path(__file__).resolve().parent.parent
STUDY = ROOT / "studies" / "brown_table1.toml"
#: brown_table1 at a test's size: 200 trials in 20 chunks, the region at its smallest
SMALL = {"trials": 200, "chunk": 10, "region.points": 256, "region.rounds": 0}


def _files(d: Path) -> dict[str, bytes]:
    return {p.relative_to(d).as_posix(): p.read_bytes() for p in d.rglob("*") if p.is_file()}


def test_the_api_writes_the_directory_sim_run_writes(tmp_path):
    """The same run by ``sim run`` and by ``sim.load(...).run(out=...)``: the same files, each
    byte for byte (README.md and run.json included), each directory named ``bt``."""
    sets = [a for k, v in SMALL.items() for a in ("--set", f"{k}={v}")]
    cli = tmp_path / "cli" / "bt"
    argv = ["run", str(STUDY), "--out", str(cli), "--quiet", "--no-figures", *sets]
    assert main(argv) == 0
    api = tmp_path / "api" / "bt"
    sim.load(STUDY, **SMALL).run(out=api, figures=False)
    a, b = _files(cli), _files(api)
    assert sorted(a) == sorted(b), set(a) ^ set(b)
    assert [f for f in a if a[f] != b[f]] == []
