"""T52: validating a study file loads what validation needs, not the study's run code.

A study package named its run and report functions by importing them, so that reading a study
file's keys (``sim check``, ``sim.load``, the batch's checks, another study's keys named in a
refusal) loaded every module that runs trials, draws and reports, with SciPy and Arrow: about
1 s of CPU per fresh process before a key was read. The packages name those functions now as
data (:class:`sim.studies.Part`), imported when a run or a report calls them, and the code
hash counts every module of a study's package (they are no longer reached by the imports of
its ``__init__``)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

from sim.mc.codehash import study_files
from sim.studies import Part, get_study

ROOT = Path(__file__).resolve().parents[1]

#: the kinds whose keys and checks need neither the engine nor the claim machinery
LIGHT = ("wolf_polynomial", "salsig_encoders")
#: what reading those keys must not load
HEAVY = ("scipy", "pyarrow", "matplotlib", "sim.mc.runner", "sim.claims.book")
#: what reading any kind's keys must not load (gridplate's check of the stated sigma takes a
#: chi-square probability: SciPy's special functions, as a check that needs them may)
RUN_CODE = ("pyarrow", "matplotlib", "sim.mc.runner", "sim.claims.book")


def _loaded_after(code: str) -> dict:
    """``sys.modules``' names after ``code`` in a fresh interpreter (the suite's own ``sim``)."""
    probe = f"{code}\nimport json, sys\nprint(json.dumps(sorted(sys.modules)))"
    done = subprocess.run(
        [sys.executable, "-c", probe],
        capture_output=True,
        text=True,
        cwd=ROOT,
        env={"PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin"},
        timeout=120,
    )
    assert done.returncode == 0, done.stderr[-2000:]
    return set(json.loads(done.stdout.strip().splitlines()[-1]))


def test_reading_a_studys_keys_loads_no_run_code():
    """Class: start-up of a study file's validation. Before: ``get_study("wolf_polynomial")``
    (every ``sim check`` and ``sim.load``) imported the study's run, report, claim book and
    the Monte-Carlo runner (SciPy, Arrow); ``import sim.studies`` alone loaded the runner
    for a type name. Now none of them is loaded until a run or a report needs it."""
    for names, heavy in ((LIGHT, HEAVY), (("gridplate_two_plates",), RUN_CODE)):
        mods = _loaded_after(
            "from sim.studies import get_study\n"
            f"for n in {names!r}:\n"
            "    s = get_study(n)\n"
            "    assert s.schema and s.check is not None\n"
        )
        assert not [m for m in heavy if m in mods], names
        for kind in ("wolf", "salsig", "gridplate"):
            for part in ("run", "report", "data_checks", "figures"):
                assert f"sim.studies.{kind}.{part}" not in mods


def test_named_parts_resolve_to_the_studys_functions():
    """Class: the lazy parts keep the study's interface. Its run and report are the package's
    functions when called, the data check's ``scored`` listing reaches through (``sim check``
    lists the claim ids), and the package still offers its functions by name
    (``sim.studies.wolf.main_chunk``)."""
    import sim.studies.wolf as wolf
    from sim.studies.wolf import chunks, report, run

    s = get_study("wolf_polynomial")
    assert isinstance(s.run, Part) and s.run.function is run.run
    assert s.report.function is report.report
    assert callable(s.data.scored)
    assert wolf.main_chunk is chunks.main_chunk


def test_the_code_hash_counts_the_modules_a_package_names_as_data():
    """Class: the code hash of a study whose ``__init__`` no longer imports its run code.
    Before the packages named their parts as data, the closure of ``__init__``'s imports
    reached every module; without the package's own modules counted, an edit of
    ``run.py`` or ``report.py`` would have left old results current."""
    pkg = ROOT / "sim" / "studies" / get_study("wolf_polynomial").run.module.split(".")[2]
    assert set(pkg.glob("*.py")) <= set(study_files("wolf_polynomial"))
