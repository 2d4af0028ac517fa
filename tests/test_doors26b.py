"""Invariances at the edges of double precision (brief D26b). The pre-analysis is exact under
translation (1e9 mm: 1e-12), rotation, scaling of design and sigmas together, and renaming
and reordering of points and observations; the Monte Carlo is not: an adjusted coordinate is
held to its double-precision spacing, so a point far from the network's origin with a sigma
near that spacing scattered by its rounding, and the run published Monte-Carlo sigmas,
coverages and false-alarm rates of cancellation noise with exit 0 (two clusters 60 km apart,
sigmas 1e-9 mm: coverage of the 95 % ellipse 73 %, global test 10 % at alpha 5 %), or, further
out, blamed ``solver.max_iter``. Such a network is now refused by ``sim check`` and before its Monte Carlo, naming
the point, its distance from the origin and the rounding."""

from __future__ import annotations

from pathlib import Path

import pytest

from sim.cli import main
from sim.studies import load_study
from sim.studies.network.analysis import analyse, estimated_points
from sim.studies.network.definition import build
from sim.studies.network.gama import merge_gama
from sim.studies.network.model import datum
from sim.studies.network.rounding import check_rounding
from tests.oneline import one_line


def clusters(tmp_path: Path, sep_mm: float, sigma_mm: float) -> Path:
    """Two quadrilaterals ``sep_mm`` apart, each held by two fixed points, distances only."""
    pts, obs = [], []
    for c, off in (("P", 0.0), ("Q", sep_mm)):
        for n, x, y, role in (
            ("A", 0, 0, "fixed"),
            ("B", 1000, 0, "fixed"),
            ("C", 500, 900, ""),
            ("D", 300, -700, ""),
        ):
            r = f', role = "{role}"' if role else ""
            pts.append(f'{{ name = "{c}{n}", x_mm = {off + x!r}, y_mm = {float(y)!r}{r} }}')
        for s, t in (("A", "C"), ("A", "D"), ("B", "C"), ("B", "D"), ("C", "D")):
            obs.append(
                f'{{ kind = "distance", from = "{c}{s}", to = "{c}{t}", sigma_mm = {sigma_mm!r} }}'
            )
    st = tmp_path / f"clusters_{sep_mm:g}_{sigma_mm:g}.toml"
    st.write_text(
        'study = "network"\ntrials = 40\nchunk = 2\nseed = 3\n[network]\nname = "clusters"\n'
        f"points = [{', '.join(pts)}]\nobservations = [{', '.join(obs)}]\n"
        '[datum]\nkind = "fixed"\n'
    )
    return st


def test_a_point_whose_sigma_its_rounding_swamps_is_refused_naming_the_magnitude(tmp_path, capsys):
    """60 km between the clusters (30 km from the origin, a spacing of 3.7e-9 mm) and sigmas
    of 1e-9 mm: exit 0 with a coverage of 73 % before; now one line, exit 2."""
    st = clusters(tmp_path, 6e7, 1e-9)
    what = ("network.points", "'PC'", "30 km from the network's origin", "rounds")
    one_line(capsys, main(["check", str(st)]), *what)
    rc = main(["run", str(st), "--out", str(tmp_path / "out")])
    one_line(capsys, rc, *what)
    assert not (tmp_path / "out" / "points.parquet").exists()


@pytest.mark.parametrize(("sep", "sigma"), [(0.0, 1e-9), (6e7, 1e-6), (9e8, 1e-4)])
def test_the_same_clusters_with_sigmas_above_the_rounding_are_accepted(tmp_path, sep, sigma):
    """The check refuses only what the rounding swamps: the clusters side by side at 1e-9 mm,
    60 km apart at 1e-6 mm, 900 km apart at 1e-4 mm pass it."""
    cfg = merge_gama(load_study(clusters(tmp_path, sep, sigma))[1])
    net = build(cfg)
    an = analyse(net, datum(net, cfg), 0.001, 0.8)
    check_rounding(net, an.cov, estimated_points(net, an))


def test_a_sight_of_a_micrometre_is_not_blamed_on_the_datum(tmp_path, capsys):
    """A point 1e-6 mm from another, sighted from it: its rows weigh 1e22 times the others and
    pushed seven singular values under the rank tolerance, so a network held by four fixed
    points was refused as "a rank defect of 12 ... that the datum does not cover". The rank
    is now read from the equilibrated design: the weights are named, with the point."""
    corners = [("A", 0, 0), ("B", 1e5, 0), ("C", 1e5, 1e5), ("D", 0, 1e5)]
    pts = [
        f'{{ name = "{n}", x_mm = {float(x)!r}, y_mm = {float(y)!r}, role = "fixed" }}'
        for n, x, y in corners
    ]
    pts += [
        '{ name = "N", x_mm = 30000.0, y_mm = 40000.0 }',
        '{ name = "Z", x_mm = 30000.000001, y_mm = 40000.0 }',
    ]
    obs = [
        f'{{ kind = "distance", from = "{n}", to = "N", sigma_mm = 1.0 }}' for n, _, _ in corners
    ]
    obs += [f'{{ kind = "distance", from = "{n}", to = "Z", sigma_mm = 1.0 }}' for n in "AB"]
    obs += [
        '{ kind = "direction", from = "N", to = "Z", sigma_arcsec = 1.0 }',
        '{ kind = "direction", from = "N", to = "A", sigma_arcsec = 1.0 }',
        '{ kind = "distance", from = "N", to = "Z", sigma_mm = 0.001 }',
    ]
    st = tmp_path / "near.toml"
    st.write_text(
        'study = "network"\ntrials = 40\nchunk = 2\n[network]\nname = "near"\n'
        f"points = [{', '.join(pts)}]\nobservations = [{', '.join(obs)}]\n"
        '[datum]\nkind = "fixed"\n'
    )
    line = one_line(
        capsys, main(["check", str(st)]), "datum.kind", "near-singular from its weights", "'Z'"
    )
    assert "rank defect" not in line
