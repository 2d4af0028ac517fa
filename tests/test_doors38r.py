"""The classes of the review R38 (a fresh reading of session 37's merges), one case each; each
failed on the code before its fix.

* a requirement with an extra (``pyproject.toml``'s ``dask[distributed]``): :mod:`sim.venv_check`
  checked the distribution by its name alone, so a ``.venv`` from which ``distributed`` was
  removed (``pip uninstall distributed``) was taken for whole by ``make venv`` and every target
  (each ``--executor dask`` test failed). The requirements an extra adds are checked too, one
  line naming the missing one.
* a run over the room ``ulimit -v`` (or ``-d``) leaves (session 37's :mod:`sim.room`, which a
  sweep's limits call too): its one line ended "make the run smaller (sim check lists its
  sizes)", and ``sim check`` refused the same run in the same words, listing nothing. It now
  names the keys to reduce, and a sweep's largest cell, as the memory limit's refusal does.
* ``datum.kind = "inner"`` on a network whose datum one fixed point and a weighted one hold
  together (the merge of ``inner_left`` with the lead's naming of weighted coordinates): the
  refusal said "the fixed points A already fix the network's datum", which one point cannot.
  It names both, the fixed points and the weighted coordinates.
* a directory beside the results whose ``run.json`` holds a config that is not a table
  (``{"config": "brown_table1", ...}``): ``sim report`` wrote REPORT.md, then its note on
  results of older code (:mod:`sim.stale`) failed, "sim: internal error: AttributeError:
  'str' object has no attribute 'get'", exit 3. Such a record is not the suite's: skipped as
  the report skips it.
"""

from __future__ import annotations

import os
import resource
import shutil
import subprocess
import sys
from importlib import metadata
from pathlib import Path

import pytest
from oneline import one_line_of

import sim
from sim import venv_check

ROOT = Path(__file__).resolve().parents[1]
TABLE1 = str(ROOT / "studies" / "brown_table1.toml")


def _pyproject(tmp_path, dep: str):
    p = tmp_path / "pyproject.toml"
    p.write_text(f'[project]\nname = "sim"\ndependencies = ["{dep}"]\n', encoding="utf-8")
    return p


def test_a_requirements_extra_is_checked(tmp_path, monkeypatch):
    real = metadata.requires

    def requires(name):  # dask's extra x asks for a distribution that is not installed
        if name == "dask":
            return ['no-such-dist-38r>=1; extra == "x"', 'also-absent-38r; extra == "y"']
        return real(name)

    monkeypatch.setattr(metadata, "requires", requires)
    words = venv_check.problem(_pyproject(tmp_path, "dask[x]>=2023.1"))
    assert words is not None and "lacks no-such-dist-38r" in words, words
    assert "dask[x]>=2023.1" in words
    # another extra's requirement and the name alone are not asked for
    assert venv_check.problem(_pyproject(tmp_path, "dask>=2023.1")) is None
    assert venv_check.problem(_pyproject(tmp_path, "dask[z]>=2023.1")) is None


def _address_space(kb: int):
    """A ``preexec_fn`` setting the soft ``ulimit -v`` to ``kb`` kB (skipped under a lower hard)."""
    hard = resource.getrlimit(resource.RLIMIT_AS)[1]
    if hard != resource.RLIM_INFINITY and hard < kb * 1024:
        pytest.skip("the hard limit is lower than the test's")
    return lambda: resource.setrlimit(resource.RLIMIT_AS, (kb * 1024, hard))


def test_a_run_over_the_room_of_ulimit_names_the_keys_to_reduce():
    big = ["--set", "plate.grid=120", "--set", "plate.spacing_mm=1"]
    big += ["--set", "trials=2000", "--set", "chunk=10"]  # about 1.46 GiB
    proc = subprocess.run(
        [sys.executable, "-m", "sim", "check", TABLE1, *big],
        cwd=ROOT,
        env=dict(os.environ),
        capture_output=True,
        text=True,
        timeout=120,
        preexec_fn=_address_space(1200 * 1024),
    )
    line = one_line_of(proc, "ulimit -v (1228800 kB) leaves", "raise ulimit -v, or reduce chunk")
    assert "plate.grid" in line and "sim check" not in line, line


MIXED = """study = "network"
trials = 200
chunk = 10
seed = 1

[network]
name = "mixed"
points = [ { name = "A", x_m = 0.0, y_m = 0.0, role = "fixed" },
           { name = "B", x_m = 60.0, y_m = 0.0, role = "observed", sigma_mm = 0.01 },
           { name = "C", x_m = 60.0, y_m = 40.0 }, { name = "D", x_m = 0.0, y_m = 40.0 } ]
generate = [
  { kind = "distance", from = "*", to = "*", sigma_mm = 0.5 },
  { kind = "direction", from = "*", to = "*", sigma_arcsec = 1.0 },
]

[datum]
kind = "inner"
"""


def test_an_inner_datum_held_by_a_fixed_and_a_weighted_point_names_both(tmp_path):
    f = tmp_path / "mixed.toml"
    f.write_text(MIXED, encoding="utf-8")
    with pytest.raises(sim.ConfigError) as e:
        sim.load(f)
    assert e.value.key == "datum.kind"
    words = "the fixed points A and the observed (weighted) coordinates of B already fix"
    assert words in str(e.value), e.value


def test_a_record_whose_config_is_no_table_is_not_an_internal_error(tmp_path, capsys):
    from sim.cli import main

    shutil.copytree(ROOT / "results" / "brown_table1", tmp_path / "brown_table1")
    (tmp_path / "junk").mkdir()
    (tmp_path / "junk" / "run.json").write_text('{"config": "brown_table1", "code_hash": "x"}')
    assert main(["report", "--results", str(tmp_path)]) == 0
    assert "internal error" not in capsys.readouterr().err
