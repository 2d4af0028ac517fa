"""U51 (issue 26's T54): what ``sim check`` of a study file loads before it refuses the file.

* A refused ``sim check`` of wolf's or salsig's study file (a bad value, ``--set trials=-1``)
  cost about 1.2 s of CPU (1.9 s with an unknown key) after T52 made reading their keys
  light: the command's own modules loaded the run first. ``sim.cli_check`` imported
  ``sim.execute`` (the estimate, the sweep, the run's engine, the report's summary) and
  ``sim.cli_run`` (which held ``load_run``, and imports ``sim.execute`` and tqdm), and
  ``sim.studies.picking`` took ``MIN_CHUNKS`` from the runner (pyarrow, the jackknife). Now
  ``load_run`` lives in ``sim/cli_load.py``, the listing in ``sim/cli_check_list.py``
  (imported once the file is read), and picking takes the number from
  ``sim.mc.chunk_count``. Held here: which modules the refusal loads, not its time
  (``make bench``'s ``startup`` rows time it). SciPy is still loaded, by ``sim.room``
  (hashed: its memory record wraps every load and imports the estimate's engine), and an
  unknown key still loads every kind's keys (``sim.studies.ported``: whose key it is).
"""

import subprocess
import sys

from conftest import ROOT

#: what a refused bad value must not load (the run, the estimate's caller, claims, report)
RUN = ("sim.execute", "sim.mc.runner", "pyarrow", "sim.claims.rules", "sim.report", "tqdm")
#: what a refused unknown key must not load (the other kinds' keys load the runner)
LISTING = ("sim.execute", "sim.claims.rules", "sim.report", "tqdm", "sim.cli_check_list")

CODE = """
import contextlib, io, sys
from sim.cli import main
for argv, heavy in {stages!r}:
    err = io.StringIO()
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
        code = main(argv)
    print(code, err.getvalue().strip(), '|', ' '.join(m for m in heavy if m in sys.modules))
"""


def test_a_refused_check_loads_no_run_listing_claims_or_report():
    """Class: ``sim check`` of a light study file refused for a bad value (wolf, salsig) or
    an unknown key (wolf). Before: each loaded sim.execute, sim.mc.runner, pyarrow, the
    claim rules, the report's summary and tqdm before the file was read (the command's
    modules imported them at the top)."""
    wolf = str(ROOT / "studies" / "wolf_polynomial.toml")
    salsig = str(ROOT / "studies" / "salsig_encoders.toml")
    stages = [
        (["check", wolf, "--set", "trials=-1"], RUN),
        (["check", salsig, "--set", "trials=-1"], RUN),
        (["check", wolf, "--set", "nosuch=1"], LISTING),
    ]
    r = subprocess.run(
        [sys.executable, "-c", CODE.format(stages=stages)],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert r.returncode == 0, r.stderr
    lines = r.stdout.splitlines()
    assert len(lines) == 3, r.stdout
    assert lines[0].startswith("2 sim: error: trials: must be >= 2"), lines[0]
    assert lines[1].startswith("2 sim: error: trials: must be >= 2"), lines[1]
    assert lines[2].startswith("2 sim: error: nosuch: unknown key"), lines[2]
    for line in lines:
        assert line.rstrip().endswith("|"), f"loaded before the refusal: {line.split('|')[1]}"
