"""The classes of the sweep doors18a (issue 26: the file system, process limits and two
commands at once), one case each; each failed on the code before its fix. The harness that
found them (``run.sh``, about 250 cases) lives outside the project.

* a second ``sim run`` of another config into the same ``--out``, whose executor started
  (a Dask cluster, a process pool: seconds) while the first run published there, took the
  lock afterwards and replaced the first run's results at its end without ``--overwrite``:
  the output was checked before the lock, and checked again under it only as if
  ``--overwrite`` had been given (:func:`sim.execute.execute`);
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

from oneline import SIM_ERROR, one_line

from sim import execute
from sim.cli import main

ROOT = Path(__file__).resolve().parent.parent
PLATE = str(ROOT / "studies" / "network_plate.toml")
SMALL = ["--trials", "40", "--chunk", "2", "--no-figures", "--quiet"]


def test_a_run_published_while_another_starts_its_executor_is_not_replaced(
    tmp_path, capsys, monkeypatch
):
    other = tmp_path / "other"
    assert main(["run", PLATE, *SMALL, "--seed", "9", "--out", str(other)]) == 0
    out = tmp_path / "out"
    real = execute.make_executor

    def slow_start(*args, **kwargs):  # the first run publishes while this one starts
        if not out.exists():
            shutil.copytree(other, out)
        return real(*args, **kwargs)

    monkeypatch.setattr(execute, "make_executor", slow_start)
    capsys.readouterr()
    rc = main(["run", PLATE, *SMALL, "--out", str(out)])
    one_line(
        capsys, rc, "--out", "holds results of a different config", "--overwrite", prefix=SIM_ERROR
    )
    assert json.loads((out / "run.json").read_text())["config"]["seed"] == 9
    for f in other.rglob("*"):  # the first run's results, byte for byte
        if f.is_file():
            assert (out / f.relative_to(other)).read_bytes() == f.read_bytes()
    assert not (tmp_path / ".out.partial").exists()
