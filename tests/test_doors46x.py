"""The classes of the sweep doors46x (brief X46: the kinds and forms of a GNU Gama file not yet
compared with ``gama-local`` 2.03: lone and repeated directions, vectors between fixed heights,
observed coordinates of band > 0, ``from_dh``/``to_dh``, d-m-s forms, every frame of one
handedness), one case each; each failed on the code before its fix. The tests that run
``gama-local`` skip without it (``$GAMA_LOCAL``, else ``/tmp/gama-build/gama-local``); each has
a check that does not need it.

* An angular ``val`` of many turns (``val="1e17"`` gon, ``-1e20``, or an ``<obs
  orientation="1e17">``) held the reader for good: its absolute-term test reduced the angle one
  turn a step, as ``gama-local`` does (which never ends on such a file either); the degrees of a
  C ``int`` took 4 s a value. Refused now over 1000 turns, naming the attribute (past thousands
  of turns ``gama-local``'s reduction loses the angle's digits: 1e-3 rad at 6e6 turns).
* ``distance-stdev = "a b c"`` whose power overflows (``val="1e300"``, c = 2) ended in Python's
  ``OverflowError``, a traceback, even beside the distance's own ``stdev``: the default is inf
  now, as in ``gama-local``'s C, refused as a standard deviation only where it is used.
* ``<vec from_dh="abc">`` (or ``to_dh``) was read; ``gama-local`` refuses it ("bad
  instrument/reflector height"). Now one line naming the attribute.
* A set of one direction is left out by ``gama-local`` (``revision_observations``: a set of
  fewer than two targets is passive, untested), but the suite tested its term: a lone direction
  with an ``<obs orientation>`` far from it was refused as one "gama-local removes" (it adjusts
  the file), and its term could start the removal of others. It is no term now; the network
  read is the same (one direction, one orientation: no degree of freedom, no precision).
* A set whose directions all aim at one point (two sightings of A) is left out whole by
  ``gama-local``; the suite kept them: one degree of freedom more, silently. Refused now, the
  line saying what ``gama-local`` does; and a study's such set is not exported (the export
  wrote it, and gama-local adjusted the file with a degree of freedom fewer, unsaid).
* d-m-s minutes or seconds of 60 or more (``11-94-56.7``), read by ``gama-local`` as d + m/60 +
  s/3600, were refused (X44's leftover). Decided: read as there (the value is used only for the
  absolute-term test, which then agrees with ``gama-local``'s), the report's note naming the
  first such value (a slip of the file, likely; 60.00 seconds, a value rounded up, is not named).
* A ``dz`` that ``gama-local`` removes as an outlying term was never named (X44's leftover):
  alone, it is named in the note now (this study drops every dz, so the networks are the same);
  when its term starts the test that removes a direction by its weighted term only, the line
  names the dz as what starts it, and counts it among those removed.
* Observed coordinates other than the point's: ``gama-local`` takes the last x, y given as the
  point's (a ``<coordinates>`` point sets them) and tests every term there; the suite kept the
  ``<point>``'s and tested none: C observed 2 m off, four observations of C removed there, all
  kept here (another geometry, four degrees of freedom more), silently. The point moves as
  there (the note says so), and observed coordinates are tested against a ``<point>`` after
  them.
* An ``<obs>`` with no observation was read; ``gama-local`` refuses the file. Refused now.
"""

from __future__ import annotations

import math
import re
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from benchmarks.scaling import gama_local
from sim.mc.config import ConfigError
from sim.studies import load_study
from sim.studies.network.definition import build
from sim.studies.network.gama import export, merge_gama
from sim.studies.network.gama_read import read_gama
from tests.test_doors20d import agree_with_gama, ours, study_of
from tests.test_doors39x import FIXED, XY, _file, _obs

needs_gama = pytest.mark.skipif(gama_local() is None, reason="no gama-local on this machine")
ONS = "{http://www.gnu.org/software/gama/gama-local-adjustment}"


def _gon(s: str, t: str, xy: dict = XY) -> float:
    (xs, ys), (xt, yt) = xy[s], xy[t]
    return math.degrees(math.atan2(yt - ys, xt - xs)) % 360 / 0.9


def _refused(path: Path, xml: str, *needles: str) -> str:
    path.write_text(xml)
    with pytest.raises(ConfigError) as e:
        read_gama(path)
    line = str(e.value)
    assert "\n" not in line and path.name in line and all(n in line for n in needles), line
    return line


def _gama_run(path: Path) -> tuple[str, int]:
    """gama-local's text output of ``path`` and its degrees of freedom (from its XML)."""
    txt, out = path.with_suffix(".txt"), path.with_suffix(".out.xml")
    subprocess.run(
        [gama_local(), str(path), "--text", str(txt), "--xml", str(out)],
        check=True,
        capture_output=True,
        timeout=60,
    )
    dof = int(next(ET.parse(out).getroot().iter(f"{ONS}degrees-of-freedom")).text)
    return txt.read_text(), dof


def _outlying(text: str) -> list[str]:
    """The kinds gama-local lists as outlying absolute terms (``z dif``, ``dir.``, ``angle``:
    the row that ends in the observed value and the term; an angle's fore sight on a line of
    its own, without the row's number and station; an observed coordinate's, ``x``, without a
    target)."""
    if "Outlying absolute terms in project equations" not in text:
        return []
    table = text.split("Outlying absolute terms in project equations")[1].split("Observations")[0]
    kinds = []
    for row in table.splitlines():
        w = row.split()
        if len(w) >= 4 and all(re.fullmatch(r"-?[\d.]+(e[+-]\d+)?", x) for x in w[-2:]):
            if not re.match(r"\s+\d+\s", row):
                kinds.append(" ".join(w[1:-2]))
            else:  # an observed coordinate has no target: its kind follows the station
                kinds.append(" ".join(w[3:-2]) or w[2])
    return kinds


# --- many turns: the reader held for good ----------------------------------------------------


MANY_TURNS = [("1e17", None), ("-1e20", None), ("2147483647-0-0", None), (None, "1e17")]


def test_an_angle_of_many_turns_is_refused_at_once(tmp_path):
    """``val`` in gon (1e17, -1e20), the degrees of a C int (6e6 turns: 4 s a value) and an
    ``<obs orientation>`` in radians. The reader runs in a child with a time limit: before the
    fix it never returned."""
    paths = []
    for k, (val, orientation) in enumerate(MANY_TURNS):
        xml = _file(FIXED)
        if val is not None:
            xml = xml.replace(f'val="{_gon("A", "C")!r}"', f'val="{val}"', 1)
        else:
            xml = xml.replace('<obs from="A">', f'<obs from="A" orientation="{orientation}">', 1)
        paths.append(tmp_path / f"n{k}.xml")
        paths[-1].write_text(xml)
    code = (
        "from sim.studies.network.gama_read import read_gama\n"
        "from sim.mc.config import ConfigError\n"
        f"for p in {[str(p) for p in paths]!r}:\n"
        "    try:\n        read_gama(p)\n        print('read')\n"
        "    except ConfigError as e:\n        print(e)\n"
    )
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    lines = p.stdout.splitlines()
    assert p.returncode == 0 and len(lines) == len(MANY_TURNS), (p.stdout, p.stderr)
    for line, (val, _) in zip(lines, MANY_TURNS):
        attr = "val" if val is not None else "orientation"
        assert f"attribute {attr!r}" in line and "turns, over 1000" in line, line


def test_an_angle_within_a_thousand_turns_is_read_as_one_within_a_turn(tmp_path):
    """``val`` plus 999 turns (gon) is the same direction, as gama-local reads it."""
    g = _gon("A", "C")
    plain, turned = tmp_path / "p.xml", tmp_path / "t.xml"
    plain.write_text(_file(FIXED))
    turned.write_text(_file(FIXED).replace(f'val="{g!r}"', f'val="{g + 999 * 400!r}"', 1))
    assert read_gama(turned)["network.observations"] == read_gama(plain)["network.observations"]


# --- distance-stdev whose power overflows: a traceback ---------------------------------------


@pytest.mark.parametrize("stdev", ["", ' stdev="3"'])
def test_a_default_distance_stdev_that_overflows_is_one_line(tmp_path, stdev):
    """``val="1e300"`` and ``distance-stdev="1 1 2"``: OverflowError before, also beside the
    distance's own stdev (the default was computed all the same)."""
    xml = _file(
        FIXED,
        _obs() + f'<obs from="C"><distance to="D" val="1e300"{stdev}/></obs>',
        po=' distance-stdev="1 1 2"',
    )
    what = "standard deviation of inf" if not stdev else "Outlying absolute terms"
    _refused(tmp_path / "n.xml", xml, "<distance>", what)


# --- <vec from_dh to_dh>: garbage read -------------------------------------------------------


def _vectors(pairs, z: dict | None = None, dz_off: float = 0.0, attrs: str = "") -> str:
    z = z or {}
    vecs = "".join(
        f'<vec from="{a}" to="{b}" dx="{XY[b][0] - XY[a][0]!r}" dy="{XY[b][1] - XY[a][1]!r}" '
        f'dz="{z.get(b, 0.0) - z.get(a, 0.0) + (dz_off if k == 0 else 0.0)!r}"{attrs}/>'
        for k, (a, b) in enumerate(pairs)
    )
    n = 3 * len(pairs)
    return f'<vectors>{vecs}<cov-mat dim="{n}" band="0">{" ".join(["1"] * n)}</cov-mat></vectors>'


@pytest.mark.parametrize("attr", ["from_dh", "to_dh"])
def test_a_vectors_instrument_height_is_a_number_as_in_gama_local(tmp_path, attr):
    path = tmp_path / "n.xml"
    _refused(path, _file(FIXED, _obs() + _vectors([("C", "D")], attrs=f' {attr}="abc"')), attr)
    if gama_local() is not None:
        run = subprocess.run([gama_local(), str(path)], capture_output=True, text=True)
        assert "bad instrument/reflector height" in run.stdout + run.stderr
    path.write_text(_file(FIXED, _obs() + _vectors([("C", "D")], attrs=f' {attr}="1.5"')))
    assert len(read_gama(path)["network.observations"]) == 20  # a height: read, unused in 2-D


# --- lone and repeated directions ------------------------------------------------------------


def _lone(orientation: str = "", stdev: str = "10") -> str:
    """The network of doors39x and a second set at C of one direction, to A."""
    ori = f' orientation="{orientation}"' if orientation else ""
    obs = _obs().replace('stdev="10"', f'stdev="{stdev}"')
    return obs + f'<obs from="C"{ori}><direction to="A" val="{_gon("C", "A")!r}" stdev="10"/></obs>'


@pytest.mark.parametrize("stdev", ["10", "2"])
def test_a_lone_direction_is_no_absolute_term_as_in_gama_local(tmp_path, stdev):
    """Its <obs orientation> 0.5 rad off: 188 m at A, no term of gama-local (the set is
    passive there); with the others' stdev of 2 cc it would also have started their test."""
    path = tmp_path / "n.xml"
    path.write_text(_file(FIXED, _lone("0.5", stdev)))
    got = read_gama(path)
    assert got["network.observations"][-1] == {
        "kind": "direction",
        "from": "C",
        "to": "A",
        "sigma_arcsec": pytest.approx(10 * 0.324),
        "set": "2",
    }
    if gama_local() is not None:
        text, dof = _gama_run(path)
        assert _outlying(text) == [] and "Total of observations      :    18" in text
        net, an = ours(study_of(tmp_path, path.read_text(), "s"))
        assert an.dof == dof == 10  # one direction, one orientation: no degree of freedom


def test_directions_of_a_set_all_to_one_point_are_refused_saying_what_gama_local_does(tmp_path):
    g = _gon("C", "A")
    path = tmp_path / "n.xml"
    xml = _file(
        FIXED,
        _obs() + f'<obs from="C"><direction to="A" val="{g!r}" stdev="10"/>'
        f'<direction to="A" val="{g!r}" stdev="12"/></obs>',
    )
    _refused(path, xml, "<direction>", "a set at 'C' points to 'A'", "1 fewer", "gama-local leaves")
    if gama_local() is not None:  # both left out there: 18 observations, as without the set
        text, dof = _gama_run(path)
        assert "Total of observations      :    18" in text and dof == 10
    third = f'<direction to="B" val="{_gon("C", "B")!r}" stdev="10"/>'
    path.write_text(xml.replace('stdev="12"/>', 'stdev="12"/>' + third))
    assert len(read_gama(path)["network.observations"]) == 21  # two targets: read


# --- d-m-s minutes and seconds of 60 or more -------------------------------------------------


def _dms(deg: float, borrow: str = "") -> str:
    """``deg`` (degrees) as d-m-s, a degree borrowed into the minutes (``m``) or a minute into
    the seconds (``s``): the same angle as gama-local reads it."""
    d = int(deg)
    m = int((deg - d) * 60)
    s = (deg - d - m / 60) * 3600
    if borrow == "m" and d > 0:
        d, m = d - 1, m + 60
    if borrow == "s" and m > 0:
        m, s = m - 1, s + 60
    return f"{d}-{m}-{s:.6f}"


def _angles(borrow: str) -> tuple[str, list[str]]:
    """doors39x's observations and three angles in d-m-s (``borrow`` as in :func:`_dms`);
    the observations and the angles' values."""
    vals = [
        _dms((_gon(at, fs) - _gon(at, bs)) % 400 * 0.9, borrow)
        for at, bs, fs in (("A", "B", "C"), ("B", "C", "D"), ("C", "D", "A"))
    ]
    out = "".join(
        f'<obs from="{at}"><angle bs="{bs}" fs="{fs}" val="{v}"/></obs>'
        for (at, bs, fs), v in zip((("A", "B", "C"), ("B", "C", "D"), ("C", "D", "A")), vals)
    )
    return _obs() + out, vals


@pytest.mark.parametrize("borrow", ["m", "s"])
def test_d_m_s_minutes_or_seconds_of_60_or_more_are_read_as_gama_local_reads_them(tmp_path, borrow):
    """Refused before ("minutes must be below 60 and seconds at most 60"), where gama-local
    adjusts the file: the same network as the angles written plainly, the note naming them."""
    plain, odd = tmp_path / "p.xml", tmp_path / "o.xml"
    po = ' angle-stdev="3"'
    plain.write_text(_file(FIXED, _angles("")[0], po=po))
    obs, vals = _angles(borrow)
    odd.write_text(_file(FIXED, obs, po=po))
    a, b = read_gama(plain), read_gama(odd)
    assert a["network.observations"] == b["network.observations"]
    assert "d-m-s" not in a["note"]
    assert "minutes or seconds of 60 or more read as gama-local reads them" in b["note"]
    odd_vals = [v for v in vals if int(v.split("-")[1]) >= 60 or float(v.split("-")[2]) > 60]
    more = f" and {len(odd_vals) - 1} more" if len(odd_vals) > 1 else ""
    assert f"<angle> val={odd_vals[0]!r}{more}" in b["note"], b["note"]
    d, m, sec = vals[0].split("-")
    wrong = odd.read_text().replace(vals[0], f"{d}-{int(m) + 100}-{sec}")  # 1.7 degrees more
    _refused(tmp_path / "w.xml", wrong, "<angle>", "Outlying absolute terms")
    if gama_local() is not None:
        for path in (plain, odd):
            assert _outlying(_gama_run(path)[0]) == []
        assert _outlying(_gama_run(tmp_path / "w.xml")[0]) == ["angle"]
        agree_with_gama(study_of(tmp_path, odd.read_text(), "s"), tmp_path / "s.xml")


# --- a dz gama-local removes -----------------------------------------------------------------

Z = {"A": 100.0, "B": 101.0, "C": 102.5, "D": 99.0}
PAIRS = [("A", "C"), ("B", "D"), ("C", "D")]


def _heights_fixed() -> str:
    return "\n".join(
        f'<point id="{p}" x="{x!r}" y="{y!r}" z="{Z[p]!r}" '
        + ('fix="xyz"/>' if p in "AB" else 'adj="xy" fix="z"/>')
        for p, (x, y) in XY.items()
    )


def test_a_dz_gama_local_removes_alone_is_named_in_the_note(tmp_path):
    path = tmp_path / "n.xml"
    path.write_text(_file(_heights_fixed(), _obs() + _vectors(PAIRS, Z, dz_off=1.5)))
    got = read_gama(path)
    assert "gama-local removes the dz of <vec from='A' to='C'>" in got["note"], got["note"]
    assert "1500 mm from the fixed heights" in got["note"]
    path.write_text(_file(_heights_fixed(), _obs() + _vectors(PAIRS, Z)))
    assert "dz" not in read_gama(path)["note"]
    if gama_local() is not None:
        for off, gone in ((1.5, ["z dif"]), (0.0, [])):
            path.write_text(_file(_heights_fixed(), _obs() + _vectors(PAIRS, Z, dz_off=off)))
            text, dof = _gama_run(path)
            assert _outlying(text) == gone
            # gama-local counts each dz it keeps (no unknown: fixed heights) as a degree of
            # freedom; the study drops them all
            net, an = ours(study_of(tmp_path, path.read_text(), "s"))
            assert dof == an.dof + len(PAIRS) - len(gone)
            agree_with_gama(tmp_path / "s.toml", tmp_path / "s.xml")


def test_a_dz_that_starts_the_removal_of_a_direction_is_named_in_the_line(tmp_path):
    """C's direction 300 mm across (under tol-abs) of stdev 2 cc: 1500 mm weighted, removed
    by gama-local only because the dz's 1500 mm starts its test."""
    shift = 0.3 / math.dist(XY["A"], XY["C"]) * 200 / math.pi
    g = _gon("A", "C")
    obs = _obs().replace(
        f'<direction to="C" val="{g!r}" stdev="10"/>',
        f'<direction to="C" val="{g + shift!r}" stdev="2"/>',
    )
    path = tmp_path / "n.xml"
    xml = _file(_heights_fixed(), obs + _vectors(PAIRS, Z, dz_off=1.5))
    line = _refused(path, xml, "<direction> attribute 'val' (to='C')", "(and 1 more)")
    assert "the test runs as the dz of <vec from='A' to='C'> is 1500 mm off" in line, line
    path.write_text(_file(_heights_fixed(), obs + _vectors(PAIRS, Z)))
    assert len(read_gama(path)["network.observations"]) == 24  # the dz right: nothing starts it
    if gama_local() is not None:
        path.write_text(xml)
        assert sorted(_outlying(_gama_run(path)[0])) == ["dir.", "z dif"]
        path.write_text(_file(_heights_fixed(), obs + _vectors(PAIRS, Z)))
        assert _outlying(_gama_run(path)[0]) == []


# --- seeded random files of the kinds above, against gama-local ------------------------------

#: the frames whose angles have the frame's handedness (gama-local's covariances as written)
CONSISTENT = [(a, "left-handed") for a in ("ne", "es", "sw", "wn")] + [
    (a, "right-handed") for a in ("en", "nw", "se", "ws")
]


def _random_file(seed: int) -> tuple[str, int]:
    """A small network of fixed heights in a random frame of :data:`CONSISTENT`: at every
    point a set of directions to every other (gon or d-m-s, with minutes or seconds borrowed,
    some with their set's ``orientation``), a lone second set at one or two, distances with
    ``from_dh``/``to_dh``, one point's coordinates observed (``<cov-mat band="1">``), and
    vectors, one dz perhaps 1.5 m off. Returns the file and its number of vectors."""
    rng = np.random.default_rng(seed)
    names = [f"P{i}" for i in range(int(rng.integers(4, 7)))]
    xy = {p: (float(rng.uniform(-400, 400)), float(rng.uniform(-400, 400))) for p in names}
    z = {p: float(rng.uniform(90, 110)) for p in names}
    axes, angles = CONSISTENT[int(rng.integers(len(CONSISTENT)))]
    pts = "\n".join(
        f'<point id="{p}" x="{xy[p][0]!r}" y="{xy[p][1]!r}" z="{z[p]!r}" '
        + ('fix="xyz"/>' if k < 2 else 'adj="xy" fix="z"/>')
        for k, p in enumerate(names)
    )

    def value(s: str, t: str, ori_gon: float) -> str:
        g = (_gon(s, t, xy) - ori_gon) % 400
        form = rng.integers(4)
        if form == 0:
            return f'val="{g!r}" stdev="{float(rng.uniform(3, 20)):.3f}"'
        return f'val="{_dms(g * 0.9, ["", "m", "s"][form - 1])}" stdev="{rng.uniform(1, 6):.3f}"'

    obs = []
    for s in names:
        ori = float(rng.uniform(0, 400))
        attr = f' orientation="{ori * math.pi / 200!r}"' if rng.random() < 0.3 else ""
        dh = f' from_dh="{rng.uniform(1, 2):.3f}"' if rng.random() < 0.3 else ""
        o = [f'<obs from="{s}"{attr}{dh}>']
        o += [f'<direction to="{t}" {value(s, t, ori)}/>' for t in names if t != s]
        for t in names:
            if t > s and rng.random() < 0.8:
                d = math.dist(xy[s], xy[t])
                th = f' to_dh="{rng.uniform(0, 2):.3f}"' if rng.random() < 0.3 else ""
                o.append(f'<distance to="{t}" val="{d!r}" stdev="{rng.uniform(1, 5):.3f}"{th}/>')
        obs.append("".join(o) + "</obs>")
    for s in rng.choice(names, size=int(rng.integers(1, 3)), replace=False):
        t = names[(names.index(s) + 1) % len(names)]
        ori = float(rng.uniform(0, 400))
        obs.append(
            f'<obs from="{s}" orientation="{rng.uniform(0, 6.28):.6f}">'
            f'<direction to="{t}" {value(s, t, ori)}/></obs>'
        )
    p = names[-1]
    obs.append(
        f'<coordinates><point id="{p}" x="{xy[p][0]!r}" y="{xy[p][1]!r}"/>'
        '<cov-mat dim="2" band="1">25 0 25</cov-mat></coordinates>'
    )
    pairs = [(names[0], names[2]), (names[1], names[3]), (names[2], names[-1])]
    off = 1.5 if rng.random() < 0.5 else 0.0
    vecs = "".join(
        f'<vec from="{a}" to="{b}" dx="{xy[b][0] - xy[a][0]!r}" dy="{xy[b][1] - xy[a][1]!r}" '
        f'dz="{z[b] - z[a] + (off if k == 0 else 0.0)!r}"/>'
        for k, (a, b) in enumerate(pairs)
    )
    var = [16.0, 16.0, 4.0] * len(pairs)  # dx, dy, dz (mm^2), a band of 2 of zeros
    n = len(var)
    band = [var[r] if c == r else 0.0 for r in range(n) for c in range(r, min(n, r + 3))]
    obs.append(
        f'<vectors>{vecs}<cov-mat dim="{n}" band="2">'
        f"{' '.join(f'{v:g}' for v in band)}</cov-mat></vectors>"
    )
    xml = _file(pts, "\n".join(obs)).replace(
        '<network axes-xy="ne">', f'<network axes-xy="{axes}" angles="{angles}">'
    )
    return xml, len(pairs)


@needs_gama
@pytest.mark.parametrize("seed", range(4601, 4613))
def test_random_files_of_these_kinds_agree_with_gama_local(tmp_path, seed):
    xml, n_vec = _random_file(seed)
    path = tmp_path / "n.xml"
    path.write_text(xml)
    text, dof = _gama_run(path)
    gone = _outlying(text)
    assert set(gone) <= {"z dif"}, gone  # the generator's values are right but the dz
    note = read_gama(path)["note"]
    assert ("gama-local removes the dz" in note) == bool(gone)
    st = study_of(tmp_path, xml, "s")
    net, an = ours(st)
    assert dof == an.dof + n_vec - len(gone)
    agree_with_gama(st, tmp_path / "s.xml")


# --- observed coordinates other than the point's ---------------------------------------------


def _observed_c(x: float) -> str:
    return (
        f'<coordinates><point id="C" x="{x!r}" y="280"/>'
        '<cov-mat dim="2" band="0">4 4</cov-mat></coordinates>'
    )


def test_observed_coordinates_after_the_point_move_it_as_in_gama_local(tmp_path):
    """gama-local's <coordinates> point sets the point's x and y (the last given holds): C
    observed 2 m from its <point> moves there, and four observations of C are then over
    tol-abs, removed. The suite kept C at its <point> and every observation, silently; it
    moves C too now (the note says so), and refuses what gama-local removes."""
    path = tmp_path / "n.xml"
    _refused(path, _file(FIXED, _obs() + _observed_c(252.0)), "(to='C')", "(and 3 more)")
    if gama_local() is not None:
        assert len(_outlying(_gama_run(path)[0])) == 4
    path.write_text(_file(FIXED, _obs() + _observed_c(250.001)))
    got = read_gama(path)
    c = next(p for p in got["network.points"] if p["name"] == "C")
    assert (c["x_mm"], c["role"]) == (250001.0, "observed"), c
    assert "'C' at its observed coordinates (<coordinates>, 1 mm from its <point>)" in got["note"]
    if gama_local() is not None:
        agree_with_gama(study_of(tmp_path, path.read_text(), "s"), tmp_path / "s.xml")


def test_observed_coordinates_before_the_point_are_tested_against_it(tmp_path):
    """The <point> after them holds (gama-local): its x 2 m from the observed one is an
    outlying term there (the observed x removed); the suite did not test it."""
    path = tmp_path / "n.xml"
    line = _refused(path, _file(_observed_c(252.0) + "\n" + FIXED), "<point> attribute 'x'")
    assert "(id='C')" in line and "2000 mm" in line, line
    if gama_local() is not None:
        assert _outlying(_gama_run(path)[0]) == ["x"]
    path.write_text(_file(_observed_c(250.5) + "\n" + FIXED))
    c = next(p for p in read_gama(path)["network.points"] if p["name"] == "C")
    assert c["x_mm"] == 250000.0  # the <point>'s, the last given


def test_an_empty_obs_is_refused_as_in_gama_local(tmp_path):
    """``<obs from="C"/>`` was read (as no set); gama-local refuses the file ("variance-
    covariance matrix is not positive definite")."""
    path = tmp_path / "n.xml"
    _refused(path, _file(FIXED, _obs() + '<obs from="C"/>'), "<obs>", "holds no observation")
    if gama_local() is not None:
        run = subprocess.run([gama_local(), str(path)], capture_output=True, text=True)
        assert "not positive definite" in run.stdout + run.stderr


def _study_with(tmp_path: Path, dirs: int) -> dict:
    """A study of doors39x's points, five distances and ``dirs`` directions from C to A in
    one set; its resolved configuration."""
    pts = ", ".join(
        f'{{ name = "{p}", x_m = {x}, y_m = {y}, role = "{"fixed" if p in "AB" else "free"}" }}'
        for p, (x, y) in XY.items()
    )
    obs = [f'{{ kind = "distance", from = "{a}", to = "{b}", sigma_mm = 3.0 }}' for a, b in PAIRS]
    obs += [
        f'{{ kind = "distance", from = "{a}", to = "{b}", sigma_mm = 3.0 }}'
        for a, b in ("AD", "BC")
    ]
    obs += ['{ kind = "direction", from = "C", to = "A", sigma_arcsec = 3.0 }'] * dirs
    st = tmp_path / f"s{dirs}.toml"
    st.write_text(
        'study = "network"\ntrials = 40\nchunk = 2\n[network]\n'
        f"points = [{pts}]\nobservations = [{', '.join(obs)}]\n"
    )
    return merge_gama(load_study(st)[1])


def test_a_study_set_of_directions_all_to_one_point_is_not_exported(tmp_path):
    """The export wrote it, and gama-local adjusted the file with a degree of freedom fewer
    than the study's (1 of 2), the summary saying nothing; now "not exported", saying why."""
    full = _study_with(tmp_path, 2)
    said = export(build(full), full, tmp_path / "network.xml")
    assert said.startswith("not exported:") and "a set at 'C' points to 'A'" in said, said
    assert not (tmp_path / "network.xml").exists()
    full = _study_with(tmp_path, 1)  # one direction: written, read back as written
    assert export(build(full), full, tmp_path / "network.xml") == "network.xml"
    assert len(read_gama(tmp_path / "network.xml")["network.observations"]) == 6
