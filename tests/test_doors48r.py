"""Doors 48r: a hostile reading of session 47's merges (the readers' run-record check, ...),
each test failing on the code before its fix.

- A symbolic link to a sweep's cell (``latest -> sweep/cells/cell0000_r0``): the readers'
  new check of a missing ``run.json`` (:func:`sim.mc.table_shape.record_problem`) looked for
  the cell's sweep through the link's own parents, found none, and refused every table of
  the cell, "latest/run.json is missing (deleted by hand?)", in ``sim show`` and
  ``Results.table`` alike: a false refusal of results the suite wrote.
- Tables of ``sim.write_table`` alone (``results/bench`` too), which no run wrote: the same
  check refused each in ``Results.table`` as a run whose record was deleted.
- A copy beside a sweep cell's tables: listed and read unchecked (a run's own is refused).
- ``OPENBLAS_NUM_THREADS`` of 2**31 or more: passed the new check, which OpenBLAS's ``atoi``
  wraps to a count it ignores.
"""

from __future__ import annotations

import shutil
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))
from conftest import TRIANGLE_NETWORK  # noqa: E402

import sim  # noqa: E402
from sim.cli import main  # noqa: E402

#: one cell of the triangle network: 20 trials in chunks of 1 (the jackknife's 20 chunks)
_SWEEP = (
    TRIANGLE_NETWORK.replace("trials = 40", "trials = 20").replace("chunk = 2", "chunk = 1")
    + '[sweep]\n"reliability.power" = [0.8]\n'
)


@pytest.fixture(scope="module")
def sweep(tmp_path_factory) -> Path:
    """A finished one-cell sweep of the triangle network (no figures). READ ONLY."""
    base = tmp_path_factory.mktemp("sweep48r")
    (base / "sw.toml").write_text(_SWEEP)
    out = base / "sw"
    assert main(["run", str(base / "sw.toml"), "--out", str(out), "--no-figures", "--quiet"]) == 0
    return out


def _cell(sweep: Path) -> Path:
    (cell,) = sorted((sweep / "cells").iterdir())
    return cell


def test_a_link_to_a_sweep_cell_is_read_as_the_cell(sweep, tmp_path, capsys):
    """A symbolic link to a sweep's cell: refused before as a run record deleted by hand
    (the sweep's run.json looked for above the link, not above the cell); read now, its
    tables checked against the sweep's record as through the cell's own path."""
    link = tmp_path / "latest"
    link.symlink_to(_cell(sweep), target_is_directory=True)
    want = sim.Results(_cell(sweep), "network").claims()
    assert sim.Results(link, "network").claims().equals(want)
    capsys.readouterr()
    assert main(["show", str(link)]) == 0, capsys.readouterr().err
    assert "run.json is missing" not in capsys.readouterr().err


def test_a_linked_cells_missing_sweep_record_is_named_where_it_is(sweep, tmp_path):
    """The sweep's run.json removed, its cell read through a link: named as the sweep's
    record, where it is (before: the link's own 'latest/run.json', which no run writes)."""
    copy = tmp_path / "sw"
    shutil.copytree(sweep, copy, symlinks=True)
    (copy / "run.json").unlink()
    link = tmp_path / "latest"
    link.symlink_to(_cell(copy), target_is_directory=True)
    with pytest.raises(sim.ConfigError) as e:
        sim.Results(link, "network").claims()
    assert f"{copy.resolve() / 'run.json'} is missing" in str(e.value)


def test_tables_of_write_table_alone_are_read(tmp_path):
    """Tables written by ``sim.write_table`` alone (a user's, or ``make bench``'s
    ``results/bench``): no run, so no ``run.json``. ``names()`` listed them and ``table()``
    refused each as a directory whose record was "deleted by hand? ... run the study again";
    read as before now. A run's directory (it holds claims.parquet) without its record is
    still refused."""
    sim.write_table(tmp_path / "x.parquet", {"a": [1.0, 2.0]}, {"study": "mine"})
    res = sim.Results(tmp_path, "mine")
    assert res.names() == ["x"]
    assert res.table("x").column("a").to_pylist() == [1.0, 2.0]
    sim.write_table(tmp_path / "claims.parquet", {"a": [1.0]}, {"study": "mine"})
    with pytest.raises(sim.ConfigError, match="run.json is missing"):
        res.table("x")


def _check(capsys, f) -> tuple[int, str]:
    """``sim check f`` in process: its exit code and its standard error."""
    capsys.readouterr()
    try:
        rc = main(["check", str(f)])
    except SystemExit as e:
        rc = e.code
    return rc, capsys.readouterr().err


def test_a_thread_count_atoi_wraps_is_refused(tmp_path, capsys, monkeypatch):
    """``OPENBLAS_NUM_THREADS=4294967296``: all digits, so it passed session 47's check, but
    OpenBLAS reads it with C's ``atoi``, which wraps it to 0, taken for unset: with
    ``OMP_NUM_THREADS=abc`` the run went on every core without a word (the very case the
    check was written for). One line naming the variable now, exit 2."""
    f = tmp_path / "tri.toml"
    f.write_text(TRIANGLE_NETWORK)
    monkeypatch.setenv("OPENBLAS_NUM_THREADS", "4294967296")
    rc, err = _check(capsys, f)
    assert rc == 2 and err.count("\n") == 1, err
    assert "OPENBLAS_NUM_THREADS" in err and "ignore it" in err


def test_a_copy_beside_a_cells_tables_is_not_the_runs(sweep, tmp_path):
    """A copy kept beside a sweep cell's tables (``claims_old.parquet``): session 47 made
    ``Results`` list and read only the tables a run's ``run.json`` lists, but a cell has no
    record of its own, so its copy was listed and read unchecked (a run's own copy is
    refused). The cell's tables are those its sweep's record lists under ``cells/<label>/``."""
    copy = tmp_path / "sw"
    shutil.copytree(sweep, copy)
    cell = _cell(copy)
    shutil.copy(cell / "claims.parquet", cell / "claims_old.parquet")
    res = sim.Results(cell, "network")
    assert "claims_old" not in res.names() and "claims" in res.names()
    with pytest.raises(sim.ConfigError, match="claims_old.parquet is not a table its run wrote"):
        res.table("claims_old")
    assert res.claims().num_rows > 0


_GAMA = """<?xml version="1.0" ?>
<gama-local xmlns="http://www.gnu.org/software/gama/gama-local">
  <network axes-xy="ne" angles="left-handed">
    <parameters sigma-apr="1" sigma-act="apriori" />
    <points-observations distance-stdev="1.0">
      <point id="A" x="0" y="0" fix="xy" />
      <point id="B" x="1000" y="0" fix="xy" />
      <point id="C" x="400" y="700" adj="xy" />
      <obs from="A"><distance to="C" val="806.2257748" /><distance to="B" val="1000" /></obs>
      <obs from="B"><distance to="C" val="921.9544457" /></obs>
      <coordinates>
        <point id="C" x="400.00001" y="700" />
        <cov-mat dim="2" band="0">1e-4 1e-4</cov-mat>
      </coordinates>
      <point id="C" x="AGAIN" y="700" adj="xy" />
    </points-observations>
  </network>
</gama-local>
"""


@pytest.mark.parametrize("again, ok", [("400", True), ("400.5", False)])
def test_a_point_given_again_after_its_observed_coordinates(tmp_path, capsys, again, ok):
    """A ``<point>`` given again, with its first coordinates, after ``<coordinates>`` observed
    it elsewhere (gama-local 2.03 reads the file: the last given holds): session 47's move to
    the observed coordinates made the reader refuse it, "point 'C' declared twice with
    different coordinates", of two ``<point>`` elements that give the same. Read now, the
    point back at its ``<point>``; one that differs from the first is still refused."""
    (tmp_path / "g.xml").write_text(_GAMA.replace("AGAIN", again))
    f = tmp_path / "g.toml"
    f.write_text(
        f'study = "network"\ntrials = 40\nchunk = 2\n[network]\ngama_xml = "{tmp_path}/g.xml"\n'
    )
    rc, err = _check(capsys, f)
    assert (rc == 0) == ok, err
    assert ok or "declared twice with different coordinates" in err
