"""Networks in national grid coordinates (issue 26: doors20d left them refused). A surveyor's
file holds coordinates of millions of metres (UTM northings, Gauss-Krueger eastings with their
zone, Gama's own ``gama-local.xml`` at 1,054 km); the suite refused every coordinate over
1000 km. The network is now taken from a whole kilometre near its centre
(:attr:`~sim.studies.network.definition.Network.origin_mm`), so the simulated readings keep
their digits, and the tables and the export give the coordinates back as the file had them;
what is refused is a network spanning over 1000 km (a plane network no longer) and a
coordinate no plane grid on the earth reaches."""

from __future__ import annotations

import math
import re
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest

from sim.cli import main
from sim.studies import load_study
from sim.studies.network.analysis import analyse
from sim.studies.network.definition import build
from sim.studies.network.gama import merge_gama
from sim.studies.network.model import datum
from tests.oneline import one_line

ROOT = Path(__file__).resolve().parent.parent
NS = "{http://www.gnu.org/software/gama/gama-local}"
SHIFT_M = (5_432_100.0, 612_300.0)  # a UTM northing and easting, metres


def shifted(tmp_path: Path, dx_m: float, dy_m: float, kind: str = "fixed") -> Path:
    """The shipped test field moved by (dx, dy) m, at a tiny size (``kind``: its datum)."""
    src = (ROOT / "studies" / "network_testfield.toml").read_text()
    src = src.replace("trials = 2000", "trials = 40").replace("chunk = 100", "chunk = 2")
    src = re.sub(r"x_m = ([0-9.]+)", lambda m: f"x_m = {float(m[1]) + dx_m!r}", src)
    src = re.sub(r"y_m = ([0-9.]+)", lambda m: f"y_m = {float(m[1]) + dy_m!r}", src)
    src = src.replace("origin_m = [12.5, 15.0]", f"origin_m = [{12.5 + dx_m!r}, {15.0 + dy_m!r}]")
    if kind == "inner":
        src = src.replace(', role = "fixed"', "").replace('kind = "fixed"', 'kind = "inner"')
    st = tmp_path / f"field_{dx_m:.0f}_{kind}.toml"
    st.write_text(src)
    return st


def pre(study: Path):
    cfg = merge_gama(load_study(study)[1])
    net = build(cfg)
    return net, analyse(net, datum(net, cfg), 0.001, 0.8)


@pytest.mark.parametrize("kind", ["fixed", "inner"])
def test_a_field_network_in_national_grid_coordinates_has_the_same_precision(tmp_path, kind):
    """Precision is translation invariant: the same field 5,432 km north gives the same
    covariances (to rounding), and its points keep the coordinates the file gave."""
    net0, an0 = pre(shifted(tmp_path, 0.0, 0.0, kind))
    net1, an1 = pre(shifted(tmp_path, *SHIFT_M, kind))
    assert net0.origin_mm == (0.0, 0.0)
    assert net1.origin_mm == (5_432_000_000.0, 612_000_000.0)
    np.testing.assert_allclose(net1.xy_mm - net0.xy_mm, [[s * 1000 for s in SHIFT_M]] * net0.n)
    np.testing.assert_allclose(an1.cov, an0.cov, rtol=1e-9, atol=1e-12 * np.abs(an0.cov).max())


def test_a_run_in_national_grid_coordinates_simulates_the_same_readings(tmp_path):
    """The Monte-Carlo columns too: readings simulated about a whole-km origin are those of the
    field at the origin (taken from 5,432 km away they lost ~1e-6 mm of each distance)."""
    out = {}
    for dx, dy in ((0.0, 0.0), SHIFT_M):
        out[dx] = tmp_path / f"out{dx:.0f}"
        assert main(["run", str(shifted(tmp_path, dx, dy)), "--out", str(out[dx])]) == 0
    a = pq.read_table(out[0.0] / "points.parquet").to_pydict()
    b = pq.read_table(out[SHIFT_M[0]] / "points.parquet").to_pydict()
    for col in a:
        if col in ("x_mm", "y_mm"):
            shift = SHIFT_M["xy".index(col[0])] * 1000
            np.testing.assert_allclose(np.array(b[col]) - shift, a[col], atol=1e-6)
        elif isinstance(a[col][0], float):
            np.testing.assert_allclose(b[col], a[col], rtol=1e-10, err_msg=col)
    # the export gives gama-local the coordinates the study gave
    pts = ET.parse(out[SHIFT_M[0]] / "network.xml").getroot().iter(NS + "point")
    xs = {p.get("id"): float(p.get("x")) for p in pts if p.get("x") is not None}
    assert xs["A"] == SHIFT_M[0] and xs["C"] == SHIFT_M[0] + 100.0


def test_a_gama_file_in_national_grid_coordinates_is_read(tmp_path):
    """A gama-local file at 5,432 km: read, analysed as the same file near the origin."""
    pts = {"A": (0.0, 0.0), "B": (300.0, 0.0), "C": (250.0, 280.0), "D": (-20.0, 260.0)}

    def xml(dx: float, dy: float) -> str:
        p = "".join(
            f'<point id="{k}" x="{x + dx!r}" y="{y + dy!r}" {"fix" if k < "C" else "adj"}="xy"/>'
            for k, (x, y) in pts.items()
        )
        o = "".join(
            f'<obs from="{s}"><distance to="{t}" val="{math.dist(pts[s], pts[t])!r}" stdev="2"/>'
            "</obs>"
            for s in pts
            for t in pts
            if s < t
        )
        return (
            '<?xml version="1.0"?><gama-local xmlns="http://www.gnu.org/software/gama/gama-'
            'local"><network axes-xy="ne"><parameters sigma-act="apriori"/><points-observations>'
            f"{p}{o}</points-observations></network></gama-local>"
        )

    got = []
    for dx, dy in ((0.0, 0.0), SHIFT_M):
        src = tmp_path / f"g{dx:.0f}.xml"
        src.write_text(xml(dx, dy))
        st = tmp_path / f"g{dx:.0f}.toml"
        st.write_text(f'study = "network"\ntrials = 40\nchunk = 2\n[network]\ngama_xml = "{src}"\n')
        got.append(pre(st))
    (net0, an0), (net1, an1) = got
    np.testing.assert_allclose(net1.xy_mm[:, 0] - net0.xy_mm[:, 0], SHIFT_M[0] * 1000)
    np.testing.assert_allclose(an1.cov, an0.cov, rtol=1e-9, atol=1e-12 * np.abs(an0.cov).max())


def test_a_network_spanning_over_1000_km_is_refused_naming_its_span(tmp_path, capsys):
    st = tmp_path / "wide.toml"
    st.write_text(
        'study = "network"\ntrials = 40\nchunk = 2\n[network]\npoints = [\n'
        '  { name = "A", x_m = 0.0, y_m = 0.0, role = "fixed" },\n'
        '  { name = "B", x_m = 1200000.0, y_m = 0.0 },\n]\n'
        'observations = [ { kind = "distance", from = "A", to = "B", sigma_mm = 1.0 } ]\n'
    )
    one_line(capsys, main(["check", str(st)]), "network.points", "spans 1200 km", "over 1000 km")


def test_a_coordinate_no_plane_grid_reaches_is_refused_naming_the_point(tmp_path, capsys):
    st = tmp_path / "far.toml"
    st.write_text(
        'study = "network"\ntrials = 40\nchunk = 2\n[network]\npoints = [\n'
        '  { name = "A", x_m = 2e8, y_m = 0.0, role = "fixed" },\n'
        '  { name = "B", x_m = 200000100.0, y_m = 0.0 },\n]\n'
        'observations = [ { kind = "distance", from = "A", to = "B", sigma_mm = 1.0 } ]\n'
    )
    one_line(capsys, main(["check", str(st)]), "'B'", "2e+05 km", "100,000 km")
