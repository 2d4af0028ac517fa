"""The classes of the sweep doors41x (brief X41: what ``gama-local`` 2.03 accepts and the suite
refused, the default datum of an imported file, the estimate of a file's size), one case each;
each failed on the code before its fix. Each refusal left was run through ``gama-local``
first; its line now says what ``gama-local`` does instead and why the suite refuses. The
tests that run ``gama-local`` skip without it (``$GAMA_LOCAL``, else
``/tmp/gama-build/gama-local``).

* An empty attribute that ``gama-local`` reads as absent (its parser tests ``if (sv !=
  "")``: ``stdev=""`` takes the default stdev, ``<obs orientation="" from_dh="">``, ``x="" y=""``
  a point without coordinates, ``fix=""``) was refused as "'' is not a number". It is now
  read as absent, as there (``id=""``, ``val=""``, ``sigma-apr=""``, refused there, still are).
* ``<parameters cov-band="-2">`` (read as -1, the whole matrix, by ``gama-local``) and an
  ``algorithm`` outside gso, svd, cholesky, envelope (``gama-local`` adjusts with envelope)
  were refused; neither is used by the suite: both are read.
* A point listed without coordinates (or neither fixed nor adjusted in xy) that nothing
  observes was refused; ``gama-local`` leaves it out ("Removed points ... missing
  coordinates") and adjusts the rest. It is left out here too, and the report's note names
  it; an observed one is still refused, the line saying what ``gama-local`` does.
* A negative stdev (``gama-local`` squares it: the variance of its absolute value) and zero
  degrees of freedom (``gama-local`` adjusts the file, with no test) stay refused; the line
  now says what ``gama-local`` does and why the suite refuses (the sign is a typing error;
  the study's global test needs a degree of freedom).
* One fixed point, coordinate differences (``<vectors>``) and ``adj="XY"`` points: the
  default datum fell back to inner ("fewer than two points held"), then the check refused it
  ("inner has nothing to constrain ... use datum.kind = fixed"), where ``gama-local`` adjusts
  the file in its fixed datum (the vectors hold the rotation). The fallback now asks the
  design for the defect the fixed points leave; none, and the datum stays fixed.
* The estimate of a ``gama-local`` file counted its size (80 bytes an observation, 4 a point):
  a 2,000-point network's export was counted as 10,000 unknowns for its 6,081. Its elements
  are now counted (:mod:`sim.mc.gama_count`): points, rows by kind and orientation sets.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

from sim.cli import main
from sim.mc.network_size import network_counts
from sim.studies import load_study
from sim.studies.network.definition import build
from sim.studies.network.gama import export, merge_gama, write_gama
from sim.studies.network.gama_read import read_gama
from tests.oneline import one_line
from tests.test_doors20d import agree_with_gama, gama_xml, needs_gama, study_of
from tests.test_doors39x import FIXED, XY, _file, _obs, _refused


def _read(tmp_path: Path, xml: str, name: str = "n") -> dict:
    path = tmp_path / f"{name}.xml"
    path.write_text(xml, encoding="utf-8")
    return read_gama(path)


def test_empty_attributes_gama_local_reads_as_absent_are_read_as_absent(tmp_path):
    """stdev="" beside a default stdev, an <obs> with empty orientation and from_dh, a point's
    z="": read as without them. An empty id or val, refused by gama-local, still is."""
    plain = _file(FIXED, _obs(), po=' distance-stdev="3"')
    empty = plain.replace('stdev="3"', 'stdev=""', 1)
    empty = empty.replace('<obs from="A">', '<obs from="A" orientation="" from_dh="">', 1)
    empty = empty.replace('id="C" x="250" y="280" adj="xy"', 'id="C" x="250" y="280" adj="xy" z=""')
    assert empty.count('=""') == 4
    assert (
        _read(tmp_path, empty, "e")["network.observations"]
        == _read(tmp_path, plain)["network.observations"]
    )
    for bad, attr in ((r'id="A"', "'id'"), (r'val="[^"]*"', "'val'")):  # refused there too
        _refused(tmp_path, re.sub(bad, attr[1:-1] + '=""', empty, count=1), attr, "missing")


def test_cov_band_below_minus_one_and_an_unknown_algorithm_are_read(tmp_path):
    """gama-local reads cov-band="-2" as -1 and algorithm="foo" as envelope; neither is used."""
    plain = _read(tmp_path, _file(FIXED))
    for params in ('sigma-act="apriori" cov-band="-2"', 'sigma-act="apriori" algorithm="foo"'):
        assert _read(tmp_path, _file(FIXED, params=params), "p") == plain
    _refused(tmp_path, _file(FIXED, params='cov-band="-2x"'), "'cov-band'", "gama-local refuses")


def test_points_listed_without_coordinates_and_not_observed_are_left_out_and_named(tmp_path):
    """E without coordinates and F neither fixed nor adjusted, both unobserved: gama-local
    removes them; here too, and the note names them. Observed, such a point is refused with
    what gama-local does."""
    extra = '\n<point id="E" adj="XY"/>\n<point id="F" x="5" y="5"/>'
    rec = _read(tmp_path, _file(FIXED + extra))
    assert rec["network.observations"] == _read(tmp_path, _file(FIXED), "p")["network.observations"]
    assert [p["name"] for p in rec["network.points"]] == list(XY) and rec["datum.points"] == []
    assert "left out, as gama-local leaves them: 'E', 'F'" in rec["note"]
    seen = _obs() + '<obs from="C"><distance to="F" val="350" stdev="3"/></obs>'
    _refused(tmp_path, _file(FIXED + extra, seen), "'F'", "neither fix nor adj", "gama-local")
    seen = _obs() + '<obs from="C"><distance to="E" val="350" stdev="3"/></obs>'
    _refused(tmp_path, _file(FIXED + extra, seen), "'E'", "no coordinates", "gama-local")


def test_a_negative_stdev_is_refused_saying_what_gama_local_does(tmp_path):
    xml = _file(FIXED, _obs().replace('stdev="10"', 'stdev="-10"', 1))
    _refused(tmp_path, xml, "<direction>", "'stdev'", "'-10' is negative", "gama-local squares")


def test_no_degree_of_freedom_is_refused_saying_what_gama_local_does(tmp_path, capsys):
    d = {p: math.hypot(XY["C"][0] - XY[p][0], XY["C"][1] - XY[p][1]) for p in "AB"}
    obs = "".join(f'<distance to="{p}" val="{v!r}" stdev="3"/>' for p, v in d.items())
    pts = FIXED.split('\n<point id="D"')[0]
    st = study_of(tmp_path, _file(pts, f'<obs from="C">{obs}</obs>'))
    rc = main(["check", str(st)])
    one_line(
        capsys, rc, "network.observations", "0 degrees of freedom", "global test", "gama-local"
    )


def _vector_file(roles: dict) -> str:
    """A, B, C, D (XY of test_doors39x), heights fixed at 0, four vectors around them."""
    pts = []
    for p, (x, y) in XY.items():
        role = 'fix="xyz"' if roles[p] == "fix" else f'adj="{roles[p]}" fix="z"'
        pts.append(f'<point id="{p}" x="{x!r}" y="{y!r}" z="0" {role}/>')
    pairs = [("A", "B"), ("B", "C"), ("C", "D"), ("D", "A")]
    vec = "".join(
        f'<vec from="{a}" to="{b}" dx="{XY[b][0] - XY[a][0]!r}" dy="{XY[b][1] - XY[a][1]!r}" '
        'dz="0"/>'
        for a, b in pairs
    )
    cov = " ".join(["1 1 1"] * len(pairs))
    obs = f'<vectors>{vec}<cov-mat dim="{3 * len(pairs)}" band="0">{cov}</cov-mat></vectors>'
    return gama_xml("\n".join(pts), obs)


def test_one_fixed_point_and_vectors_keep_the_fixed_datum_as_gama_local(tmp_path, capsys):
    """The vectors hold the rotation about A: no defect is left, gama-local adjusts in the
    fixed datum (its adj="XY" points change nothing); the check refused the inner fallback."""
    st = study_of(tmp_path, _vector_file({"A": "fix", "B": "XY", "C": "XY", "D": "XY"}))
    assert main(["check", str(st)]) == 0, capsys.readouterr().err
    assert merge_gama(load_study(st)[1])["datum.kind"] == "fixed"
    free = study_of(tmp_path, _vector_file(dict.fromkeys("ABCD", "XY")), "free")
    assert merge_gama(load_study(free)[1])["datum.kind"] == "inner"  # no fixed point: inner


@needs_gama
def test_one_fixed_point_and_vectors_agree_with_gama_local(tmp_path):
    st = study_of(tmp_path, _vector_file({"A": "fix", "B": "XY", "C": "XY", "D": "XY"}))
    agree_with_gama(st, tmp_path / "net.xml")


def test_the_estimate_counts_a_gama_file_from_its_elements(tmp_path):
    """A 400-point export: its unknowns and observations as built (the size said 1.6 times
    the unknowns)."""
    side = 20
    net = build(load_study(_grid_study(tmp_path, side))[1])
    path = write_gama(net, tmp_path / "grid.xml")
    k = network_counts({"network.gama_xml": str(path), "solver.max_iter": 20})
    assert (k.points, k.rows, k.unknowns) == (net.n, net.m, net.q)
    assert k.nonlinear


def _grid_study(tmp_path: Path, side: int) -> Path:
    st = tmp_path / "grid.toml"
    st.write_text(
        'study = "network"\ntrials = 40\nchunk = 2\n[network]\n'
        f'grids = [ {{ prefix = "P", nx = {side}, ny = {side}, spacing_m = 100.0 }} ]\n'
        'points = [ { name = "A", x_m = -100.0, y_m = -100.0, role = "fixed" },\n'
        f'  {{ name = "B", x_m = {100.0 * side}, y_m = -100.0, role = "fixed" }} ]\n'
        'generate = [ { kind = "direction", from = "P*", to = "P*", nearest = 8, '
        "sigma_arcsec = 1.0 },\n"
        '  { kind = "distance", from = ["A", "B"], to = "P*", nearest = 3, sigma_mm = 1.0 } ]\n'
    )
    return st


def test_an_export_over_the_readers_limit_says_so(tmp_path, monkeypatch):
    """A 50,000-point triangulation's export is 36 MiB, over the 16 MiB a gama_xml import
    reads: the summary said "network.xml", and the file was refused when read back. The
    limit is lowered here to a 400-point export's size."""
    net = build(load_study(_grid_study(tmp_path, 20))[1])
    cfg = {"datum.kind": "fixed", "datum.points": [], "network.points": []}
    assert export(net, cfg, tmp_path / "network.xml") == "network.xml"
    monkeypatch.setattr("sim.studies.network.gama.MAX_BYTES", 2**17)
    said = export(net, cfg, tmp_path / "network.xml")
    assert said.startswith("network.xml (") and "over the 0.125 MiB network.gama_xml reads" in said
