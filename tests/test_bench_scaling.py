"""The scaling section of the benchmark (benchmarks/scaling.py) at toy sizes: gama-local gets
a regular datum (its free-network cofactors are quadratic in the points) and is not given a
network whose dense design matrix (gama-local 2.03 builds one) would not fit; the grid-plate
row is the combined adjustment's. No timings are asserted."""

from types import SimpleNamespace

import numpy as np
import pytest

from benchmarks import scaling
from sim.studies.network.definition import build


def test_gama_input_has_a_regular_datum(tmp_path):
    net = build(scaling._network_cfg("trilateration", 4))  # inner datum in the suite
    xml = tmp_path / "net.xml"
    scaling._gama_xml(net, 4, xml)
    txt = xml.read_text()
    assert txt.count('fix="xy"') == 2 and 'adj="XY"' not in txt
    assert '<point id="P1"' in txt and 'id="P4" x="150.0" y="-150.0" fix="xy"' in txt
    tri = build(scaling._network_cfg("triangulation", 4))  # its own two fixed corners
    scaling._gama_xml(tri, 4, xml)
    assert xml.read_text().count('fix="xy"') == 2


@pytest.mark.skipif(scaling.gama_local() is None, reason="no gama-local on this machine")
def test_gama_runs_on_the_regular_datum(tmp_path):
    net = build(scaling._network_cfg("trilateration", 4))
    row = {"unknowns": 2 * net.n, "gama_s": float("nan")}
    assert scaling._gama(scaling.gama_local(), net, 4, row) == ""
    assert np.isfinite(row["gama_s"])


def test_gama_is_not_given_a_dense_design_that_does_not_fit():
    big = SimpleNamespace(m=80_000)  # the 10,000-point trilateration: 80,000 distances
    row = {"unknowns": 20_000, "gama_s": float("nan")}
    note = scaling._gama("/nonexistent/gama-local", big, 100, row)
    assert note.startswith("not run") and "12 GiB" in note and np.isnan(row["gama_s"])


def test_gridplate_row_is_the_combined_adjustment():
    row = scaling._child_gridplate(5, 3)
    assert row["points"] == 25 and row["unknowns"] == 53 and row["observations"] == 75
    assert row["converged"] == 1.0 and row["analytic_s"] > 0 and row["mc_s_per_trial"] > 0
