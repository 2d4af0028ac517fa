"""GNU Gama interop (issue 24) and the network kind's check-time refusals (issue 26).

The reference outputs in tests/data/gama/ were written by gama-local 2.03 (built from its
public source) on the networks as this suite exports them and on files written as a
gama-local user writes them (d-m-s angles, default stdevs, a <cov-mat>); regenerate them with
``GAMA_LOCAL=... python tests/data/gama/regenerate.py``. gama-local prints covariances to 8
significant digits and adjusted stdevs to 16: the comparisons hold to 1e-6 (relative to the
largest variance of the network for covariances, absolute for redundancy numbers).
"""

import json
import math
import os
import re
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from sim.batch import is_current
from sim.cli import main
from sim.mc.codehash import study_code_hash
from sim.mc.config import ConfigError
from sim.studies import load_study
from sim.studies.network.analysis import analyse, in_datum
from sim.studies.network.definition import build
from sim.studies.network.figures import natural_unit
from sim.studies.network.gama import _distance_sigma, export, merge_gama, write_gama
from sim.studies.network.gama_read import CC, MAX_BYTES, read_gama
from sim.studies.network.model import datum

ROOT = Path(__file__).resolve().parent.parent
DATA = ROOT / "tests/data/gama"
sys.path.insert(0, str(DATA))
from regenerate import EXPORTS  # noqa: E402

OUT_NS = "{http://www.gnu.org/software/gama/gama-local-adjustment}"
ARCSEC = math.pi / 648000


def gama_out(case: str) -> dict:
    """The parts of gama-local's XML output the tests compare: degrees of freedom, defect,
    the covariance of the adjusted unknowns by name (mm^2; orientations in cc^2) and the
    adjusted observations' stdevs keyed by (kind, points)."""
    root = ET.parse(DATA / f"{case}.out.xml").getroot()

    def t(e, tag):
        return e.find(OUT_NS + tag).text.strip()

    pe = root.find(f"{OUT_NS}network-processing-summary/{OUT_NS}project-equations")
    coords = root.find(OUT_NS + "coordinates")
    names = []
    for p in coords.find(OUT_NS + "adjusted"):
        pid = t(p, "id")
        names += [(pid, c.lower()) for c in ("x", "y", "X", "Y") if p.find(OUT_NS + c) is not None]
    names += [("orientation", t(o, "id")) for o in coords.find(OUT_NS + "orientation-shifts")]
    cm = coords.find(OUT_NS + "cov-mat")
    dim, band = int(t(cm, "dim")), int(t(cm, "band"))
    vals = iter(float(f.text) for f in cm.findall(OUT_NS + "flt"))
    cov = np.zeros((dim, dim))
    for r in range(dim):
        for c in range(r, min(dim, r + band + 1)):
            cov[r, c] = cov[c, r] = next(vals)
    obs = []
    for o in root.find(OUT_NS + "observations"):
        kind = o.tag.replace(OUT_NS, "")
        pts = tuple(
            e.text.strip() for e in o if e.tag[len(OUT_NS) :] in ("from", "to", "left", "right")
        )
        obs.append(((kind, pts), float(t(o, "stdev"))))
    return {
        "dof": int(t(pe, "degrees-of-freedom")),
        "defect": int(t(pe, "defect")),
        "names": names,
        "cov": cov,
        "obs": obs,
        "vectors": int(
            t(
                root.find(f"{OUT_NS}network-processing-summary/{OUT_NS}observations-summary"),
                "vectors",
            )
        ),
    }


def ours(cfg: dict):
    full = merge_gama(cfg)
    net = build(full)
    dt = datum(net, full)
    return full, net, dt, analyse(net, dt, 0.001, 0.8)


def study(case: str, *over) -> dict:
    return load_study(EXPORTS[case], list(over))[1]


def _obs_key(net, r: int):
    kind = ("distance", "direction", "angle", "dx", "dy")[net.kind[r]]
    n = net.names
    if kind == "angle":
        return kind, (n[net.i[r]], n[net.j[r]], n[net.k[r]])
    return kind, (n[net.i[r]], n[net.j[r]])


def compare(net, an, cov, g: dict, sig_in: np.ndarray) -> None:
    """Our point covariances ``cov`` (n, 2, 2), orientation variances, redundancy numbers
    and degrees of freedom against gama-local's output ``g`` (to 1e-6)."""
    idx = {nm: a for a, nm in enumerate(g["names"])}
    scale = np.abs(g["cov"]).max()
    seen = 0
    for a, nm in enumerate(net.names):
        if (nm, "x") not in idx:
            assert net.role[a] == 1, nm
            continue
        ix, iy = idx[(nm, "x")], idx[(nm, "y")]
        got = g["cov"][np.ix_([ix, iy], [ix, iy])]
        np.testing.assert_allclose(cov[a], got, rtol=0, atol=1e-6 * scale, err_msg=nm)
        seen += 1
    assert seen == int(np.sum(net.role != 1))
    # orientations: gama-local lists them in the order of the stations' <obs> sets (cc^2)
    ori = [a for a, nm in enumerate(g["names"]) if nm[0] == "orientation"]
    assert [g["names"][a][1] for a in ori] == [s.split("/")[0] for s in net.stations]
    if cov is an.cov:  # the study's own datum: the orientations are comparable too
        pos = {int(q): a for a, q in enumerate(an.free)}
        for s, a in enumerate(ori):
            mine = an.Q[pos[2 * net.n + s], pos[2 * net.n + s]] / CC**2
            assert mine == pytest.approx(g["cov"][a, a], rel=1e-6)
    # redundancy numbers r = 1 - (stdev of the adjusted observation / its stdev)^2
    want: dict = {}
    for r in range(net.m):
        if net.kind[r] <= 4:
            want.setdefault(_obs_key(net, r), []).append((an.redundancy[r], sig_in[r]))
    got: dict = {}
    for key, s in g["obs"]:
        if key[0] in ("distance", "direction", "angle", "dx", "dy"):
            got.setdefault(key, []).append(s)
    assert sorted(got) == sorted(want)
    for k, vals in want.items():
        mine = sorted(v[0] for v in vals)
        theirs = sorted(1 - (s / v[1]) ** 2 for s, v in zip(got[k], vals))
        np.testing.assert_allclose(mine, theirs, rtol=0, atol=1e-6, err_msg=str(k))
    assert an.dof == g["dof"] - g["vectors"]  # gama-local counts each vector's dz (z fixed)


def gama_sigma(net) -> np.ndarray:
    """The stdev of each row as exported (mm; cc for angles and directions)."""
    return np.array(
        [
            _distance_sigma(net, r)
            if net.kind[r] == 0
            else net.sigma[r] / CC
            if net.kind[r] in (1, 2)
            else net.sigma[r]
            for r in range(net.m)
        ]
    )


@pytest.mark.parametrize("case", list(EXPORTS))
def test_export_is_the_committed_gama_input(case, tmp_path):
    """gama-local read exactly these files: the export still writes them byte for byte."""
    cfg = study(case)
    full, net, _, _ = ours(cfg)
    note = export(net, full, tmp_path / "n.xml")
    assert not note.startswith("not exported"), note
    assert (tmp_path / "n.xml").read_text() == (DATA / f"{case}.xml").read_text()
    assert 'angles="400"' not in (DATA / f"{case}.xml").read_text()


@pytest.mark.parametrize("case", list(EXPORTS))
def test_precision_agrees_with_gama_local(case):
    """Per-point covariances, orientations, redundancy numbers, degrees of freedom and the
    datum defect agree with gama-local's adjustment of the exported file."""
    cfg = study(case)
    full, net, dt, an = ours(cfg)
    g = gama_out(case)
    C = dt.constraint_matrix(net.theta_true()[None])
    if cfg["datum.kind"] == "constraints":  # exported as the free network, inner datum
        cov = in_datum(net, an, [a for a in range(net.n) if net.role[a] != 1])
        assert g["defect"] == 3
    else:
        cov = an.cov
        assert g["defect"] == (0 if C is None else C.shape[-1])
    compare(net, an, cov, g, gama_sigma(net))


@pytest.mark.parametrize("case,source", [("user_dms", "two_sets"), ("user_defaults", "one_fixed")])
def test_user_written_files_import_with_gama_locals_precision(case, source, tmp_path):
    """d-m-s angles (stdev in arcsec), default stdevs with a + b D^c, a diagonal <cov-mat>:
    imported, the network has gama-local's precision for that file."""
    cfg = study(source)
    path = DATA / f"{case}.xml"
    imp = {
        **cfg,
        "network.points": [],
        "network.observations": [],
        "network.generate": [],
        "network.gama_xml": str(path),
    }
    full, net, dt, an = ours(imp)
    rec = read_gama(path)
    d_km = np.hypot(*(net.xy[net.j] - net.xy[net.i]).T) / 1e6
    if case == "user_defaults":  # distance-stdev="2 3 1": 2 mm + 3 mm/km; 4.6296... cc
        np.testing.assert_allclose(net.sigma[net.kind == 0], 2 + 3 * d_km[net.kind == 0])
        np.testing.assert_allclose(net.sigma[net.kind == 1], 4.6296296296296 * CC)
    else:  # d-m-s: the stdevs are in arcseconds, the same sigmas as the source study's
        _, src, _, _ = ours(cfg)
        np.testing.assert_allclose(np.sort(net.sigma), np.sort(src.sigma), rtol=1e-12)
        assert net.stations == ("A", "A/2", "B")
    # gama-local states the adjusted observations' stdevs in cc (angles) and mm
    sig = np.where(np.isin(net.kind, (1, 2)), net.sigma / CC, net.sigma)
    compare(net, an, an.cov, gama_out(case), sig)
    assert "apriori" in rec["note"]


@pytest.mark.parametrize("case", list(EXPORTS))
def test_round_trip_export_import_gives_the_same_network(case, tmp_path):
    cfg = study(case)
    full, net, dt, an = ours(cfg)
    path = tmp_path / "n.xml"
    export(net, full, path)
    back = {
        **cfg,
        "network.points": [],
        "network.grids": [],
        "network.random": [],
        "network.observations": [],
        "network.generate": [],
        "network.gama_xml": str(path),
        "network.offset_mm": 0.0,
        "network.constant_mm": 0.0,
        "datum.kind": "fixed" if cfg["datum.kind"] == "fixed" else "inner",
        "datum.points": [],
    }
    full2, net2, dt2, an2 = ours(back)
    assert net2.names == net.names and np.array_equal(net2.role, net.role)
    np.testing.assert_allclose(net2.xy, net.xy, rtol=0, atol=1e-9)
    assert net2.stations == net.stations

    def rows(nt, sig):
        return sorted(zip(nt.kind, nt.i, nt.j, nt.k, np.round(sig, 12)))

    assert rows(net2, net2.sigma) == rows(
        net, gama_sigma(net) * np.where(np.isin(net.kind, (1, 2)), CC, 1.0)
    )
    if cfg["datum.kind"] == "constraints":
        cov = in_datum(net, an, [a for a in range(net.n) if net.role[a] != 1])
    else:
        cov = an.cov
        assert an2.dof == an.dof
    np.testing.assert_allclose(an2.cov, cov, rtol=0, atol=1e-9 * np.abs(cov).max())


def test_inner_over_removes_every_defect_as_gama_locals_adj_XY():
    """Issue 24 item 11: a directions-only network (scale defect too), stated in the inner
    datum over P1-P3 by S-transformation from another datum, is gama-local's adj="XY"."""
    cfg = study("directions_free", 'datum.points=["*"]')
    full, net, dt, an = ours(cfg)
    sel = [net.index(p) for p in ("P1", "P2", "P3")]
    cov = in_datum(net, an, sel)
    g = gama_out("directions_free")
    assert g["defect"] == 4
    compare(net, ours(study("directions_free"))[3], cov, g, gama_sigma(net))


def test_inner_datum_with_one_fixed_point_is_solved():
    """Issue 24 item 12: one fixed point, rotation free: datum.kind = inner is accepted and
    has one constraint (gama-local's defect 1); the fixed datum alone is refused."""
    full, net, dt, an = ours(study("one_fixed"))
    assert an.ok and dt.constraint_matrix(net.theta_true()[None]).shape[-1] == 1
    with pytest.raises(ConfigError, match="rank defect of 1"):
        study("one_fixed", 'datum.kind="fixed"')


def test_inner_over_patterns_are_one_set_and_singular_sets_are_refused_at_check():
    """Issue 24 item 13: the patterns form one datum; a set that cannot fix the defects
    (one point against a rotation) is refused by sim check, not after the Monte Carlo."""
    study("directions_free", 'output.inner_over=["P4", "P5"]')  # 2 points fix 4 defects
    with pytest.raises(ConfigError, match="output.inner_over.*cannot fix"):
        study("directions_free", 'output.inner_over=["P4"]')
    with pytest.raises(ConfigError, match="datum.points.*cannot fix"):
        study("directions_free", 'datum.points=["P5"]')
    with pytest.raises(ConfigError, match="no point matches 'Q'"):
        study("directions_free", 'output.inner_over=["P4", "Q"]')


def test_constraints_export_as_the_free_network_and_refusals(tmp_path):
    cfg = study("brown")
    full, net, dt, an = ours(cfg)
    note = export(net, full, tmp_path / "b.xml")
    assert "constraints has no gama-local form" in note and "inner datum" in note
    for over, msg in [
        ("network.estimate_constant", "additive-constant unknown"),
        ("network.estimate_scale", "scale unknown"),
    ]:
        c2 = {**cfg, over: True}
        assert msg in export(build(c2), c2, tmp_path / "x.xml")
    c3 = study("two_sets")
    c3["network.observations"] = c3["network.observations"] + [
        {"kind": "dx", "from": "A", "to": "B", "sigma_mm": 1.0}
    ]
    with pytest.raises(ConfigError, match="dx from 'A' to 'B' without its dy"):
        write_gama(build(c3), tmp_path / "v.xml")


def test_aposteriori_files_are_read_with_the_apriori_convention_stated(tmp_path):
    text = (DATA / "two_sets.xml").read_text().replace('sigma-act="apriori"', "")
    (tmp_path / "a.xml").write_text(text)
    assert "aposteriori" in read_gama(tmp_path / "a.xml")["note"]


BAD = [
    ('<parameters sigma-apr="1" sigma-act="apriori" />', '<parameters angles="deg" />', "angles"),
    ('<network axes-xy="ne" angles="left-handed">', '<network angles="400">', "angles"),
    ('<network axes-xy="ne" angles="left-handed">', '<network axes-xy="xy">', "axes-xy"),
    ('x="150.0"', 'x="1abc"', "'1abc' is not a number"),
    ('x="150.0"', 'x="1_000"', "not a number"),
    ('x="150.0"', 'x="nan"', "not a number"),
    ('stdev="2.0"', 'stdev="abc"', "<distance> attribute 'stdev' (to='B')"),
    ('stdev="2.0"', 'stdev="-1"', "'-1' is negative (gama-local squares it"),
    ('stdev="2.0"', 'stdev="2.0" colour="red"', "unknown attribute"),
    ('<point id="B"', '<point id="A" x="1" y="1" adj="xy" /><point id="B"', "declared twice"),
    ('adj="xy" />', 'adj="xyz" z="1" />', "height unknowns"),
    ("</obs>", '<z-angle to="B" val="100" /></obs>', "3-D"),
    ("</obs>", '<s-distance to="B" val="100" /></obs>', "3-D"),
    ("</obs>", '<azimuth to="B" val="100" /></obs>', "azimuth"),
    (
        '<obs from="B">',
        '<height-differences><dh to="A" val="1"/></height-differences><obs from="B">',
        "heights",
    ),
    ("</obs>", '<cov-mat dim="2" band="1">1 0.5 1</cov-mat></obs>', "cov-mat"),
    ('fs="F2" val="', 'fs="F2" val="12-2147483648-00', "over 2147483647 minutes"),
    ('to="F1"', 'to="Nowhere"', "no such <point>"),
    ("<points-observations>", '<points-observations distance-stdev="2 x">', "distance-stdev"),
    ("<points-observations>", '<points-observations distance-stdev="1 2 3 4">', "distance-stdev"),
    ("<points-observations>", "<points-observations><frobnicate/>", "unknown element"),
]


@pytest.mark.parametrize("old,new,msg", BAD)
def test_bad_gama_files_are_one_line_naming_file_element_attribute(old, new, msg, tmp_path):
    text = (DATA / "two_sets.xml").read_text()
    assert old in text
    path = tmp_path / "bad.xml"
    path.write_text(text.replace(old, new, 1))
    with pytest.raises(ConfigError) as e:
        read_gama(path)
    line = str(e.value)
    assert msg in line and "bad.xml" in line and "\n" not in line, line


def test_correlated_cov_mat_in_obs_is_refused_with_one_line(tmp_path):
    text = (DATA / "user_dms.xml").read_text()
    i = text.index('band="0">') + len('band="0">')
    j = text.index("</", i)
    var = text[i:j].split()
    band1 = " ".join(f"{v} 0.1" for v in var[:-1]) + f" {var[-1]}"
    (tmp_path / "c.xml").write_text(text[:i].replace('band="0">', 'band="1">') + band1 + text[j:])
    with pytest.raises(ConfigError, match="correlated observations"):
        read_gama(tmp_path / "c.xml")


def test_only_regular_files_of_bounded_size_are_read(tmp_path):
    fifo = tmp_path / "fifo.xml"
    os.mkfifo(fifo)
    with pytest.raises(ConfigError, match="not a regular file"):
        read_gama(fifo)
    big = tmp_path / "big.xml"
    with open(big, "wb") as fh:
        fh.truncate(MAX_BYTES + 1)
    with pytest.raises(ConfigError, match="MiB"):
        read_gama(big)
    with pytest.raises(ConfigError, match="not a regular file"):
        read_gama(tmp_path)


def test_sim_check_on_a_fifo_is_one_line_not_a_hang(tmp_path):
    fifo = tmp_path / "fifo.xml"
    os.mkfifo(fifo)
    study_file = tmp_path / "s.toml"
    study_file.write_text(
        f'study = "network"\ntrials = 200\nchunk = 10\n[network]\ngama_xml = "{fifo}"\n'
    )
    r = subprocess.run(
        [sys.executable, "-m", "sim", "check", str(study_file)],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert "network.gama_xml" in r.stderr and "regular file" in r.stderr


def test_an_edited_gama_file_changes_the_resolved_config(tmp_path):
    """The gama_xml file's sha256 is in the resolved config: an edit makes results stale."""
    path = tmp_path / "n.xml"
    path.write_text((DATA / "two_sets.xml").read_text())
    study_file = tmp_path / "s.toml"
    study_file.write_text(
        f'study = "network"\ntrials = 200\nchunk = 10\n[network]\ngama_xml = "{path}"\n'
    )
    _, c1 = load_study(study_file)
    assert len(c1["network.gama_sha256"]) == 64
    res = tmp_path / "res"
    res.mkdir()
    rec = {"config": c1, "code_hash": study_code_hash("network")}
    (res / "run.json").write_text(json.dumps(rec))
    assert is_current(study_file, res)
    path.write_text(path.read_text().replace('stdev="2.0"', 'stdev="4.0"'))
    _, c2 = load_study(study_file)
    assert c2["network.gama_sha256"] != c1["network.gama_sha256"]
    assert not is_current(study_file, res)
    with pytest.raises(ConfigError, match="network.gama_sha256.*has changed"):
        load_study(study_file, [f'network.gama_sha256="{c1["network.gama_sha256"]}"'])


TWO = EXPORTS["two_sets"]
PTS = [
    {"name": "F1", "x_mm": 0.0, "y_mm": 0.0, "role": "fixed"},
    {"name": "F2", "x_mm": 500000.0, "y_mm": 0.0, "role": "fixed"},
    {"name": "A", "x_mm": 150000.0, "y_mm": 120000.0},
    {"name": "B", "x_mm": 350000.0, "y_mm": 140000.0},
]


def _pts(**change):
    return [{**p, **change.get(p["name"], {})} for p in PTS]


@pytest.mark.parametrize(
    "values,key,msg",
    [
        (
            {"network.points": _pts(A={"role": "fixed"}, B={"role": "fixed"})},
            "network.points",
            "every point is fixed",
        ),
        (
            {"network.points": _pts(B={"x_mm": 150000.0, "y_mm": 120000.0})},
            "network.points",
            "'A' and 'B' coincide",
        ),
        (
            {
                "network.observations": [
                    {"kind": "angle", "at": "B", "from": "F1", "to": "B", "sigma_arcsec": 1.0}
                ]
            },
            "network.observations",
            "an angle at 'B' from 'F1' to 'B': a sight to its own station",
        ),
        (
            {
                "network.observations": [
                    {"kind": "angle", "at": "B", "from": "F1", "to": "F1", "sigma_arcsec": 1.0}
                ]
            },
            "network.observations",
            "the two sights are one",
        ),
        (
            {
                "network.observations": [
                    {"kind": "distance", "from": "A", "to": "B", "sigma_mm": 1e-300}
                ]
            },
            "network.observations[0].sigma_mm",
            "over- or underflow",
        ),
        (
            {
                "network.observations": [
                    {"kind": "direction", "from": "A", "to": "B", "sigma_arcsec": 1e300}
                ]
            },
            "network.observations[0].sigma_arcsec",
            "wraps around the circle",  # an angle's bound, 1e5 arcsec, is the tighter (doors35p)
        ),
        (
            {"network.offset_mm": 192094.0},
            "network.offset_mm",
            "not shorter than the distance from 'F1' to 'A'",
        ),
        (
            {
                "network.points": [
                    {"name": "F1", "x_mm": 0.0, "y_mm": 0.0, "role": "fixed"},
                    {"name": "F2", "x_mm": 500000.0, "y_mm": 0.0, "role": "fixed"},
                    {"name": "X", "x_mm": 250000.0, "y_mm": 1e-7},
                ],
                "network.observations": [
                    {"kind": "distance", "from": "F1", "to": "X", "sigma_mm": 1.0},
                    {"kind": "distance", "from": "F2", "to": "X", "sigma_mm": 1.0},
                    {"kind": "distance", "from": "X", "to": "F2", "sigma_mm": 1.0},
                ],
            },
            "datum.kind",
            "near-singular: point 'X' (y)",
        ),
        (
            {"datum.kind": "constraints", "datum.constraints": [{"A.x": float("nan")}]},
            "datum.constraints[0]",
            "A.x: coefficient must be a finite number",
        ),
        (
            {
                "network.observations": [
                    {"kind": "distance", "from": "A", "to": "B", "sigma_mm": 1.0, "set": "2"}
                ]
            },
            "network.observations[0].set",
            "only a direction",
        ),
    ],
)
def test_degenerate_networks_are_refused_at_check_naming_the_observation(values, key, msg):
    with pytest.raises(ConfigError) as e:
        load_study(TWO, values=values)
    assert e.value.key == key and msg in str(e.value), str(e.value)


def test_check_refusals_are_one_line_exit_2(capsys):
    obs = 'network.observations=[{kind="angle", at="B", from="B", to="F2", sigma_arcsec=1.0}]'
    code = main(["check", str(TWO), "--set", obs])  # sim check, in this process
    err = capsys.readouterr().err
    assert code == 2 and len(err.strip().splitlines()) == 1, err
    assert "'B'" in err and "Traceback" not in err


GARBAGE = [
    "",
    " ",
    "abc",
    "-1",
    "0",
    "1e400",
    "nan",
    "inf",
    "1-2-3",
    "400",
    "XY",
    "z",
    "A",
    "1 2 3 4",
    "0x10",
    "\u00e9",
    "99-99-99",
]


def _mutate(text: str, rng: np.random.Generator) -> str:
    """One seeded mutation of a gama-local file: an attribute's value replaced by garbage or
    removed, an element duplicated or removed, or the file truncated."""
    attrs = list(re.finditer(r'(\w[\w-]*)="([^"]*)"', text))
    elems = list(re.finditer(r"<(\w[\w-]*) [^<>]*/>", text))
    op = rng.integers(5)
    if not attrs or not elems:
        op = 4
    if op == 0:
        m = attrs[rng.integers(len(attrs))]
        g = GARBAGE[rng.integers(len(GARBAGE))]
        return text[: m.start(2)] + g + text[m.end(2) :]
    if op == 1:
        m = attrs[rng.integers(len(attrs))]
        return text[: m.start()] + text[m.end() :]
    if op == 2:
        m = elems[rng.integers(len(elems))]
        return text[: m.end()] + m.group(0) + text[m.end() :]
    if op == 3:
        m = elems[rng.integers(len(elems))]
        return text[: m.start()] + text[m.end() :]
    return text[: rng.integers(len(text))]


@pytest.mark.parametrize("case", ["two_sets", "user_dms", "plate"])
def test_fuzzed_gama_files_give_a_network_or_one_config_error(case, tmp_path):
    """Seeded mutations of the reference files: each either loads (sim check passes) or is a
    one-line ConfigError naming network.gama_xml or another key; never another exception."""
    rng = np.random.default_rng(2024)
    text = (DATA / f"{case}.xml").read_text()
    base = tmp_path / "s.toml"
    path = tmp_path / "m.xml"
    base.write_text(
        f'study = "network"\ntrials = 200\nchunk = 10\n[network]\ngama_xml = "{path}"\n'
    )
    outcomes = {"ok": 0, "refused": 0}
    for _ in range(60):
        path.write_text(_mutate(text, rng))
        try:
            load_study(base)
            outcomes["ok"] += 1
        except ConfigError as e:
            assert "\n" not in str(e) and e.key, str(e)
            outcomes["refused"] += 1
    assert outcomes["refused"] > 0


LAUGHS = (
    '<?xml version="1.0"?><!DOCTYPE l [<!ENTITY a "aaaaaaaaaa">'
    + "".join(f'<!ENTITY {c} "{("&" + p + ";") * 10}">' for p, c in zip("abcdefg", "bcdefgh"))
    + "]><gama-local><network><description>&h;</description></network></gama-local>"
)


@pytest.mark.parametrize(
    "text,msg",
    [
        (LAUGHS, "declares the entity &a;"),  # refused before it expands (doors31x)
        # an encoding gama-local does not know over bytes beyond ASCII (an ASCII file is read)
        ('<?xml version="1.0" encoding="foo"?><gama-local id="\u00e9"/>', "does not know"),
        ("", "is not XML"),
        ("<other/>", "not <gama-local>"),
        ("<gama-local><network/><network/></gama-local>", "2 <network> elements"),
        ("<gama-local>junk<network/></gama-local>", "unexpected text"),
    ],
)
def test_hostile_gama_files_are_one_line(text, msg, tmp_path):
    path = tmp_path / "h.xml"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(ConfigError, match=msg):
        read_gama(path)


def test_field_networks_in_metres_equal_the_same_in_mm():
    """Issue 25 item 7: x_m, spacing_m, origin_m (metres) give the same network as mm."""
    cfg = load_study(ROOT / "studies/network_testfield.toml")[1]
    assert "x_m" in cfg["network.points"][0]
    mm = {
        **cfg,
        "network.points": [
            {"name": p["name"], "x_mm": p["x_m"] * 1000, "y_mm": p["y_m"] * 1000, "role": p["role"]}
            for p in cfg["network.points"]
        ],
        "network.grids": [
            {
                "prefix": "N",
                "nx": 4,
                "ny": 3,
                "spacing_mm": 25000.0,
                "origin_mm": [12500.0, 15000.0],
            }
        ],
    }
    a, b = build(cfg), build(mm)
    assert a.names == b.names and np.array_equal(a.xy, b.xy)
    bad = [{"name": "A", "x_m": 1.0, "x_mm": 1000.0, "y_m": 0.0}]
    with pytest.raises(ConfigError, match="x_mm or x_m, not both"):
        build({**cfg, "network.points": bad})
    with pytest.raises(ConfigError, match="missing"):
        build({**cfg, "network.points": [{"name": "A", "y_m": 0.0}]})


def test_figures_label_field_networks_in_metres():
    assert natural_unit(build(study("testfield")).xy) == ("m", 1000.0)
    assert natural_unit(build(study("plate")).xy) == ("mm", 1.0)
