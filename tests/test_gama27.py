"""GNU Gama files in every frame ``gama-local`` reads (brief G27): ``axes-xy`` (8) x ``angles``
(2), against ``gama-local`` 2.03 (the comparisons skip without it: ``$GAMA_LOCAL``).

Three reference networks of tests/data/gama (``ne``, left-handed: directions in two sets, an
angle and distances; a free network of directions in the inner datum; observed coordinates
and coordinate-difference vectors) are written in each frame: coordinates mapped into it,
``val`` recomputed in its convention so that ``gama-local``'s adjustment converges. What the
harness found:

* the network is the same in every combination: ``gama-local``'s covariance of each point is
  ne's mapped into the frame, ``M C M'`` (M: the frame's axes in n, e), to its 8 printed
  digits. A direction's or angle's sense (clockwise or counter-clockwise) flips the sign of
  its row of the design (with its orientation unknown's) and leaves the normals unchanged;
* ``gama-local`` adjusts a file whose angles run against its frame (a left-handed frame with
  right-handed angles, or the reverse) with every y negated (``remove_inconsistency``) and
  writes its XML ``<cov-mat>`` in that internal frame: cov(x, y) there has the opposite sign
  of the file's frame, in which it writes the adjusted coordinates. Its text output's ellipse
  bearing alpha runs from +x in the sense of the file's angles in every combination.

So the reader accepts all 16 (it refused the right-handed frames en, nw, se, ws and
right-handed angles), with covariances in the file's frame, and the export of an imported
network is written in the frame it was read in (it was labelled ne).
"""

from __future__ import annotations

import itertools
import math
import subprocess
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest
from oneline import one_line
from test_doors20d import gama_cov, needs_gama, ours, study_of

from benchmarks.scaling import gama_local
from sim.cli import main
from sim.studies import load_study
from sim.studies.network.analysis import bearing_deg, ellipse
from sim.studies.network.definition import build
from sim.studies.network.gama import export, import_note, merge_gama

ROOT = Path(__file__).resolve().parent.parent
DATA = ROOT / "tests/data/gama"
NS = "http://www.gnu.org/software/gama/gama-local"
CASES = ("two_sets", "directions_free", "plate")
LEFT = ("ne", "es", "sw", "wn")  # x to y clockwise, as gama-local's default angles run
RIGHT = ("en", "nw", "se", "ws")
COMBOS = [(ax, ang) for ang in ("left-handed", "right-handed") for ax in LEFT + RIGHT]
_UNIT = {"n": (1.0, 0.0), "e": (0.0, 1.0), "s": (-1.0, 0.0), "w": (0.0, -1.0)}
_GON = math.pi / 200


def frame(axes: str) -> np.ndarray:
    """M: (n, e) coordinates -> the frame's (x, y) (its rows: the x and y axes in n, e)."""
    return np.array([_UNIT[axes[0]], _UNIT[axes[1]]])


def consistent(axes: str, angles: str) -> bool:
    """The frame and the angles have the same handedness (bearings from +x towards +y)."""
    return (axes in LEFT) == (angles == "left-handed")


def reframe(src: Path, axes: str, angles: str) -> str:
    """The ne, left-handed gama-local file ``src`` written in the frame ``axes`` with
    ``angles``: points, observed coordinates and vectors mapped by :func:`frame`; directions
    and angles recomputed from the mapped points in the file's convention (from +x towards +y
    when frame and angles agree, towards -y when they do not), in gon."""
    ET.register_namespace("", NS)
    root = ET.fromstring(src.read_text())
    net = root.find(f"{{{NS}}}network")
    assert net.get("axes-xy", "ne") == "ne" and net.get("angles", "left-handed") == "left-handed"
    net.set("axes-xy", axes)
    net.set("angles", angles)
    m = frame(axes)
    sign = 1.0 if consistent(axes, angles) else -1.0
    xy: dict = {}
    for p in net.iter(f"{{{NS}}}point"):
        if p.get("x") is not None:
            v = m @ [float(p.get("x")), float(p.get("y"))]
            p.set("x", repr(float(v[0])))
            p.set("y", repr(float(v[1])))
            xy.setdefault(p.get("id"), v)
    for v in net.iter(f"{{{NS}}}vec"):
        d = m @ [float(v.get("dx")), float(v.get("dy"))]
        v.set("dx", repr(float(d[0])))
        v.set("dy", repr(float(d[1])))

    def bearing(a: str, b: str) -> float:
        d = xy[b] - xy[a]
        return math.atan2(sign * d[1], d[0]) / _GON % 400

    for o in net.iter(f"{{{NS}}}obs"):
        st = o.get("from")
        for e in o:
            if e.tag == f"{{{NS}}}direction":
                e.set("val", repr(bearing(st, e.get("to"))))
            elif e.tag == f"{{{NS}}}angle":
                e.set("val", repr((bearing(st, e.get("fs")) - bearing(st, e.get("bs"))) % 400))
    return ET.tostring(root, encoding="unicode")


def suite_cov(tmp_path: Path, xml: str, name: str) -> dict:
    """The suite's covariance of each estimated point (mm^2) of the file ``xml``."""
    net, an = ours(study_of(tmp_path, xml, name))
    return {nm: an.cov[a] for a, nm in enumerate(net.names) if net.role[a] != 1}


def file_frame(cov: dict, axes: str, angles: str) -> dict:
    """gama-local's XML covariances in the file's frame: as written for a consistent file,
    with cov(x, y) negated for one whose angles run against its frame (its internal y)."""
    d = np.diag([1.0, 1.0 if consistent(axes, angles) else -1.0])
    return {k: d @ c @ d for k, c in cov.items()}


def assert_same(got: dict, want: dict, tol: float) -> None:
    assert sorted(got) == sorted(want)
    scale = max(np.abs(c).max() for c in want.values())
    for k in want:
        np.testing.assert_allclose(got[k], want[k], rtol=0, atol=tol * scale, err_msg=k)


@needs_gama
@pytest.mark.parametrize("case", CASES)
def test_gama_local_adjusts_the_same_network_in_every_frame(tmp_path, case):
    """gama-local's covariances of each of the 16 files are the ne file's mapped into the
    frame, once its internal frame (y negated) is undone for an inconsistent file; without
    that step they differ (cov(x, y) of the wrong sign) in a network with correlated x, y."""
    ne = suite_cov(tmp_path, (DATA / f"{case}.xml").read_text(), "ne")
    for axes, angles in COMBOS:
        src = tmp_path / f"{axes}_{angles}.xml"
        src.write_text(reframe(DATA / f"{case}.xml", axes, angles))
        raw = gama_cov(src)
        m = frame(axes)
        want = {k: m @ c @ m.T for k, c in ne.items()}
        assert_same(file_frame(raw, axes, angles), want, 1e-6)
        off = max(abs(c[0, 1]) for c in want.values()) / max(np.abs(c).max() for c in want.values())
        if not consistent(axes, angles) and off > 1e-3:  # the internal frame is visible
            with pytest.raises(AssertionError):
                assert_same(raw, want, 1e-6)


@pytest.mark.parametrize("case", CASES)
def test_every_frame_is_read_with_the_ne_covariance_mapped_into_it(tmp_path, case):
    """All 16 combinations are read (the right-handed frames and angles were refused): each
    point's covariance in the file's frame is ne's mapped, M C M' (the normals are the same
    up to the sign of rows), and the report's note names the frame and, for angles against
    it, what that changes."""
    ne = suite_cov(tmp_path, (DATA / f"{case}.xml").read_text(), "ne")
    for axes, angles in COMBOS:
        xml = reframe(DATA / f"{case}.xml", axes, angles)
        m = frame(axes)
        got = suite_cov(tmp_path, xml, f"{axes}_{angles}")
        assert_same(got, {k: m @ c @ m.T for k, c in ne.items()}, 1e-9)
        note = import_note(load_study(tmp_path / f"{axes}_{angles}.toml")[1])
        if (axes, angles) == ("ne", "left-handed"):
            assert "axes-xy" not in note, note
        else:
            assert f"axes-xy = '{axes}'" in note and f"{angles} angles" in note, note
            assert ("against its angles" in note) != consistent(axes, angles), note


@needs_gama
@pytest.mark.parametrize("case", CASES)
def test_the_suite_agrees_with_gama_local_on_every_frame(tmp_path, case):
    """Each of the 16 files, read by the suite and adjusted by gama-local: the covariances in
    the file's frame agree (gama-local's internal frame undone, :func:`file_frame`)."""
    for axes, angles in COMBOS:
        src = tmp_path / f"{axes}_{angles}.xml"
        xml = reframe(DATA / f"{case}.xml", axes, angles)
        mine = suite_cov(tmp_path, xml, f"{axes}_{angles}")
        assert_same(mine, file_frame(gama_cov(src), axes, angles), 1e-6)


def _exported(tmp_path: Path, case: str, axes: str, angles: str):
    """The file ``case`` in the frame, imported, and the suite's export of it: the run's
    covariances and the export's path."""
    name = f"{axes}_{angles}"
    study_of(tmp_path, reframe(DATA / f"{case}.xml", axes, angles), name)
    full = merge_gama(load_study(tmp_path / f"{name}.toml")[1])
    net, an = ours(tmp_path / f"{name}.toml")
    out = tmp_path / f"{name}.export.xml"
    note = export(build(full), full, out)
    assert not note.startswith("not exported"), note
    cov = {nm: an.cov[a] for a, nm in enumerate(net.names) if net.role[a] != 1}
    return cov, out


def _angular(path: Path) -> tuple[dict, dict]:
    """The file's direction sets ``{(station, n-th set there): {target: val}}`` and angles
    ``{(station, bs, fs): val}`` (gon)."""
    root = ET.parse(path).getroot()
    sets: dict = {}
    angs: dict = {}
    for o in root.iter(f"{{{NS}}}obs"):
        st = o.get("from")
        d = {e.get("to"): float(e.get("val")) for e in o if e.tag == f"{{{NS}}}direction"}
        if d:
            sets[(st, sum(k[0] == st for k in sets))] = d
        for e in o.iter(f"{{{NS}}}angle"):
            angs[(st, e.get("bs"), e.get("fs"))] = float(e.get("val"))
    return sets, angs


def _gon_apart(a: float, b: float) -> float:
    return abs((a - b + 200) % 400 - 200)


@pytest.mark.parametrize("case", CASES)
def test_the_export_of_an_imported_file_is_written_in_its_frame(tmp_path, case):
    """network.xml of a run on a file in any frame keeps that file's axes-xy and angles (it
    was labelled ne: the same numbers in another frame, a mirror image of the network for a
    right-handed one), its angles and, up to each set's orientation, its directions (their
    sign changed where the angles run against the frame); read back, it has the run's
    covariances."""
    for axes, angles in COMBOS:
        cov, out = _exported(tmp_path, case, axes, angles)
        net = ET.parse(out).getroot().find(f"{{{NS}}}network")
        assert (net.get("axes-xy"), net.get("angles")) == (axes, angles)
        sets, angs = _angular(tmp_path / f"{axes}_{angles}.xml")
        got_sets, got_angs = _angular(out)
        assert angs.keys() == got_angs.keys()
        for k, v in angs.items():
            assert _gon_apart(got_angs[k], v) < 1e-9, (k, v, got_angs[k])
        assert sets.keys() == got_sets.keys()
        for k, d in sets.items():
            assert d.keys() == got_sets[k].keys()
            shift = [(got_sets[k][t] - v) % 400 for t, v in d.items()]
            assert all(_gon_apart(x, shift[0]) < 1e-9 for x in shift), (k, shift)
        back = suite_cov(tmp_path, out.read_text(), f"back_{axes}_{angles}")
        assert_same(back, cov, 1e-9)


@needs_gama
def test_gama_local_on_the_export_agrees_with_the_run(tmp_path):
    for case, (axes, angles) in itertools.product(CASES, COMBOS):
        (tmp_path / case).mkdir(exist_ok=True)
        cov, out = _exported(tmp_path / case, case, axes, angles)
        assert_same(file_frame(gama_cov(out), axes, angles), cov, 1e-6)


@pytest.mark.parametrize(
    "attr,value", [("axes-xy", "xy"), ("axes-xy", "NE"), ("angles", "clockwise")]
)
def test_a_frame_outside_gama_locals_vocabulary_is_refused_naming_it(tmp_path, capsys, attr, value):
    xml = reframe(DATA / "two_sets.xml", "ne", "left-handed")
    old = 'axes-xy="ne"' if attr == "axes-xy" else 'angles="left-handed"'
    assert old in xml
    st = study_of(tmp_path, xml.replace(old, f'{attr}="{value}"'))
    one_line(capsys, main(["check", str(st)]), f"'{value}' is not one of", f"'{attr}'")


def gama_ellipses(src: Path) -> dict:
    """gama-local's text output's mean error ellipses: ``{point: (a mm, b mm, alpha gon)}``
    (printed to 0.1)."""
    out = src.with_suffix(".txt")
    subprocess.run([gama_local(), str(src), "--text", str(out)], check=True, capture_output=True)
    lines = out.read_text().splitlines()
    at = next(n for n, t in enumerate(lines) if t.startswith("Mean errors and parameters"))
    at = next(n for n in range(at, len(lines)) if lines[n].startswith("====")) + 2
    rows = {}
    for t in lines[at:]:
        if not t.strip():
            break
        w = t.split()
        rows[w[0]] = (float(w[3]), float(w[4]), float(w[5]))
    return rows


@needs_gama
def test_the_ellipses_bearings_run_from_x_towards_y_against_inconsistent_angles(tmp_path):
    """gama-local's ellipse bearing alpha runs from +x in the sense of the file's angles; the
    suite's (``ellipse_bearing_deg``) from +x towards +y: the same where frame and angles
    agree, alpha = -bearing (mod 200 gon) where they do not. The semi-axes are the same."""
    for axes, angles in COMBOS:
        name = f"{axes}_{angles}"
        net, an = ours(study_of(tmp_path, reframe(DATA / "two_sets.xml", axes, angles), name))
        est = [a for a in range(net.n) if net.role[a] != 1]
        a, b, _ = ellipse(an.cov[est])
        bearing, _ = bearing_deg(an.cov[est])
        got = gama_ellipses(tmp_path / f"{name}.xml")
        assert sorted(got) == sorted(net.names[p] for p in est)
        for n, p in enumerate(est):
            ga, gb, alpha = got[net.names[p]]
            assert abs(ga - a[n]) <= 0.051 and abs(gb - b[n]) <= 0.051
            mine = bearing[n] / 0.9 * (1 if consistent(axes, angles) else -1)
            assert abs((alpha - mine + 100) % 200 - 100) <= 0.051, (name, alpha, mine)
            assert 5 < abs((alpha + mine + 100) % 200 - 100)  # the other sense is far off
