"""The lead's sweep of session 35 (issue 26): what the merges of its helpers' branches left.

* ``make verify`` printed ``largest deviation/tolerance 0 ()`` for every study reproduced
  exactly: the brackets name the file and column of the largest deviation, and with none
  they named nothing (N35's left item). A study with a deviation keeps its column.
* ``sim show results/x`` of a missing directory was told of ``results/results/x``: a path is
  no study's name, looked for under results/ and scratch/ (N35's left item).
* A gridplate run at `comparator.coord_sigma_um = 0.6`, `readings.sigma_um = 1.0` (exit 0)
  printed numpy's "All-NaN slice" RuntimeWarning: a row without a value is NaN, silently.
* A network over the memory limit is refused before it is built (M35), naming the key that
  holds most of its points: with grids beside sights generated to the nearest points, a grid
  of 5 x 900,000,000 points was blamed on ``network.generate`` (F35's case at the merge).
"""

from __future__ import annotations

from sim.report.verify.cli import _print
from sim.report.verify.rules import Comparison
from sim.studies.network.validate import _size_key


def test_a_study_reproduced_exactly_names_no_empty_column(capsys):
    _print([Comparison("net", files=7), Comparison("b", files=2, max_ratio=0.5, worst="t:x_um")])
    out = capsys.readouterr().out.splitlines()
    assert out[0] == "net: ok; 7 files; largest relative deviation 0; largest deviation/tolerance 0"
    assert out[1].endswith("largest deviation/tolerance 0.5 (t:x_um)"), out


def test_a_networks_size_is_named_by_the_key_holding_its_points():
    gen = [{"kind": "distance", "from": "G*", "to": "G*", "nearest": 8, "sigma_mm": 2.0}]
    grid = {"network.grids": [{"prefix": "G", "nx": 5, "ny": 900_000_000}], "network.generate": gen}
    assert _size_key(grid, 4_500_000_003) == "network.grids"
    rnd = {"network.random": [{"prefix": "R", "n": 10**7}], "network.generate": gen}
    assert _size_key(rnd, 10**7 + 3) == "network.random"
    listed = {"network.grids": [{"prefix": "G", "nx": 2, "ny": 2}], "network.generate": gen}
    assert _size_key(listed, 10**6) == "network.generate"  # the points are listed ones
    assert _size_key({"network.generate": []}, 10**6) == "network.points"


def test_show_of_a_path_is_not_looked_for_under_results(capsys):
    # before: "results/nosuch does not exist (nor is there a directory results/results/nosuch
    # or scratch/results/nosuch)": a path given is no study's name (N35's left item)
    from sim.cli import main

    assert main(["show", "results/nosuch"]) == 2
    assert capsys.readouterr().err == "sim: error: DIR: results/nosuch does not exist\n"
    assert main(["show", "nosuch"]) == 2
    assert "(nor is there a directory results/nosuch or scratch/nosuch)" in capsys.readouterr().err


def test_a_row_without_a_value_gives_nan_without_a_warning():
    # before: numpy's "RuntimeWarning: All-NaN slice encountered" on standard error of a
    # gridplate run that exits 0 (comparator.coord_sigma_um=0.6, readings.sigma_um=1.0:
    # region points where no calibration has a positive re-weighting; R35's left item)
    import warnings

    import numpy as np

    from sim.claims.intervals import spread_rows

    x = np.array([[1.0, 2.0, np.nan, 4.0], [np.nan] * 4, [3.0, 1.0, 2.0, 0.0]])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        med, lo, hi = spread_rows(x)
    assert np.isnan([med[1], lo[1], hi[1]]).all()
    from sim.claims.intervals import LEVEL, _half

    a = _half(LEVEL) * 100  # numpy's own values on the rows with values
    want = np.nanpercentile(x[[0, 2]], [a, 50, 100 - a], axis=1)
    assert np.array_equal(np.stack([lo, med, hi])[:, [0, 2]], want)
