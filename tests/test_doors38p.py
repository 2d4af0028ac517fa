"""The classes of the sweep doors38p (brief P38: the network's datum after session 38's
inner-datum refusal, tried over fixed points, weighted coordinates, observation kinds,
``datum.points``, GNU Gama files, sweeps and ``output.inner_over``), one case each; each failed
on the code before its fix.

* a legitimate inner datum refused: a network of directions alone (translations, rotation and
  scale: four defects) with ``datum.kind = "inner"`` over two points, which the inner
  constraints then hold whole. Their covariance blocks are rounding noise (1e-18 mm^2) whose
  determinant relative to their own trace is noise too, so they were taken for estimated
  points and the run refused, "network.points: point 'E' lies 0.05 km from the network's
  origin ... over 0.1 of its smallest sigma (0 mm)". A point whose variance is rounding noise
  beside the network's is held, as a fixed point (:func:`estimated_points`); the run runs.
* ``datum.kind = "inner"`` asked of a ``gama-local`` file with two fixed points or more (the
  study file, ``--set datum.kind=inner``, a sweep cell of ``datum.kind``): the refusal of an
  inner datum with nothing to constrain skipped every ``network.gama_xml``, so it ran the fixed
  datum, said as ``datum `inner` (0 constraints)``, and a sweep over ``datum.kind`` gave two
  cells of one datum. Refused as in a study file, naming ``datum.kind`` (not the file's
  ``adj="XY"`` points, which are no ``datum.points`` the user set); the datum a file with
  fewer fixed points resolves to inner (its own) still runs.
* a ``gama-local`` file with ``adj="XY"`` points whose ``<coordinates>`` (observed, weighted)
  hold the datum, no point fixed: its datum resolved to inner, which had nothing to constrain
  (run and reported as ``datum `inner` (0 constraints)``), and ``datum.kind = "fixed"`` was
  refused, "net.xml has 0 fixed points (a fixed datum needs two or more)". Two points fixed
  or observed keep the file's datum fixed (:func:`sim.studies.network.gama.merge_gama`); an
  inner datum asked of it is refused naming the weighted coordinates.
* inner ``datum.points`` that cannot fix the rotation about an observed (weighted) point
  (``datum.points = ["C"]``, C weighted, no point fixed): the refusal called the defect "1
  motions of the whole network" (the weighted point's rows of the defect are rounding noise,
  not zero as a fixed point's); it says "a rotation about the fixed or weighted points".
* an inner datum on a network with a fixed point and a part no observation ties to it (the
  fixed datum's refusal names that part): the inner datum was taken to hold the largest loose
  part, as in a network no point holds, so nothing was named and the line said "a rank defect
  of 3 ... that the datum (0 constraints) does not cover". With points held the inner datum
  removes only the defect they leave; the part is named (:mod:`sim.studies.network.singular`).
"""

from __future__ import annotations

import pytest

import sim

DIRECTIONS = """\
study = "network"
trials = 40
chunk = 2
seed = 1
[network]
name = "directions"
points = [
  { name = "A", x_m = 0.0, y_m = 0.0 }, { name = "B", x_m = 100.0, y_m = 0.0 },
  { name = "C", x_m = 100.0, y_m = 80.0 }, { name = "D", x_m = 0.0, y_m = 80.0 },
  { name = "E", x_m = 50.0, y_m = 40.0 }, { name = "F", x_m = 30.0, y_m = 60.0 },
]
generate = [ { kind = "direction", from = "*", to = "*", sigma_arcsec = 1.0 } ]
[datum]
kind = "inner"
points = ["E", "F"]
"""


def test_an_inner_datum_over_two_points_of_a_direction_network_runs(tmp_path):
    f = tmp_path / "directions.toml"
    f.write_text(DIRECTIONS, encoding="utf-8")
    st = sim.load(f)  # was: network.points: point 'E' ... its smallest sigma (0 mm)
    assert st.config["datum.kind"] == "inner" and st.config["datum.points"] == ["E", "F"]


def _gama(fixed: int, seen: str = "") -> str:
    xy = {"A": (0.0, 0.0), "B": (100.0, 0.0), "C": (100.0, 80.0), "D": (0.0, 80.0)}
    xy |= {"E": (50.0, 40.0), "F": (30.0, 60.0)}
    pts = [
        f'<point id="{n}" x="{x}" y="{y}" '
        + ('fix="xy"' if i < fixed else 'adj="XY"' if n in "EF" else 'adj="xy"')
        + " />"
        for i, (n, (x, y)) in enumerate(xy.items())
    ]
    obs = []
    for a, (xa, ya) in xy.items():
        d = [
            f'<distance to="{b}" val="{((xb - xa) ** 2 + (yb - ya) ** 2) ** 0.5}" stdev="1" />'
            for b, (xb, yb) in xy.items()
            if b > a
        ]
        obs += [f'<obs from="{a}">{"".join(d)}</obs>'] if d else []
    return (
        '<?xml version="1.0" ?>\n<gama-local xmlns="http://www.gnu.org/software/gama/gama-local">'
        '<network axes-xy="ne" angles="left-handed"><parameters sigma-apr="1" '
        'sigma-act="apriori" /><points-observations>'
        + "".join(pts + obs)
        + _coordinates(xy, seen)
        + "</points-observations></network></gama-local>\n"
    )


def _coordinates(xy: dict, seen: str) -> str:
    """Observed (weighted) coordinates of the points ``seen``, 5 mm each."""
    if not seen:
        return ""
    pts = "".join(f'<point id="{n}" x="{xy[n][0]}" y="{xy[n][1]}" />' for n in seen)
    cov = " 25.0" * 2 * len(seen)
    return (
        f'<coordinates>{pts}<cov-mat dim="{2 * len(seen)}" band="0">{cov}</cov-mat></coordinates>'
    )


def _study(tmp_path, fixed: int, datum: str = "", seen: str = "") -> str:
    (tmp_path / "net.xml").write_text(_gama(fixed, seen), encoding="utf-8")
    f = tmp_path / "g.toml"
    f.write_text(
        'study = "network"\ntrials = 40\nchunk = 2\nseed = 1\n[network]\n'
        f'gama_xml = "{(tmp_path / "net.xml").as_posix()}"\n{datum}',
        encoding="utf-8",
    )
    return str(f)


def test_an_inner_datum_asked_of_a_gama_file_its_fixed_points_hold_is_refused(tmp_path):
    f = _study(tmp_path, 2, '[datum]\nkind = "inner"\n')
    words = "^datum.kind: .*nothing to constrain: the fixed points A, B already fix"
    with pytest.raises(sim.ConfigError, match=words):
        sim.load(f)
    with pytest.raises(sim.ConfigError, match=words):
        sim.load(_study(tmp_path, 2), datum__kind="inner")  # as --set and a sweep cell
    sim.load(_study(tmp_path, 2))  # the file's own datum: fixed
    sim.load(_study(tmp_path, 1))  # one fixed point: the file's adj="XY" resolve it inner


def test_a_gama_file_whose_observed_coordinates_hold_the_datum_keeps_it_fixed(tmp_path):
    f = _study(tmp_path, 0, seen="AC")  # adj="XY" on E, F; A and C weighted, none fixed
    sim.load(f, datum__kind="fixed")  # was: "fixed" cannot hold: net.xml has 0 fixed points
    with pytest.raises(sim.ConfigError, match="^datum.kind: .*coordinates of A, C already fix"):
        sim.load(f, datum__kind="inner")  # was: resolved inner, run as `inner` (0 constraints)


WEIGHTED = """\
study = "network"
trials = 40
chunk = 2
seed = 1
[network]
name = "weighted"
points = [
  { name = "A", x_m = 0.0, y_m = 0.0 }, { name = "B", x_m = 100.0, y_m = 0.0 },
  { name = "C", x_m = 100.0, y_m = 80.0, role = "observed", sigma_mm = 5.0 },
  { name = "D", x_m = 0.0, y_m = 80.0 }, { name = "E", x_m = 50.0, y_m = 40.0 },
]
generate = [ { kind = "distance", from = "*", to = "*", sigma_mm = 1.0 } ]
[datum]
kind = "inner"
points = ["C"]
"""


def test_inner_points_against_the_rotation_about_a_weighted_point_say_so(tmp_path):
    f = tmp_path / "weighted.toml"
    f.write_text(WEIGHTED, encoding="utf-8")
    words = r"^datum.points: the points C cannot fix the network's 1 datum defect \(a rotation "
    with pytest.raises(sim.ConfigError, match=words + r"about the fixed or weighted points\)"):
        sim.load(f)  # was: (1 motions of the whole network)


DETACHED = """\
study = "network"
trials = 40
chunk = 2
seed = 1
[network]
name = "detached"
points = [
  { name = "A", x_m = 0.0, y_m = 0.0, role = "fixed" }, { name = "B", x_m = 100.0, y_m = 0.0 },
  { name = "C", x_m = 100.0, y_m = 80.0 }, { name = "D", x_m = 0.0, y_m = 80.0 },
  { name = "E", x_m = 300.0, y_m = 40.0 }, { name = "F", x_m = 330.0, y_m = 60.0 },
  { name = "G", x_m = 310.0, y_m = 90.0 },
]
generate = [
  { kind = "distance", from = ["A", "B", "C", "D"], to = ["A", "B", "C", "D"], sigma_mm = 1.0 },
  { kind = "distance", from = ["E", "F", "G"], to = ["E", "F", "G"], sigma_mm = 1.0 },
]
[datum]
kind = "inner"
"""


def test_an_inner_datum_names_a_part_no_fixed_point_holds(tmp_path):
    f = tmp_path / "detached.toml"
    f.write_text(DETACHED, encoding="utf-8")
    words = r"^datum.kind: the normal matrix is singular: points 'E', 'F', 'G' are tied to the"
    with pytest.raises(sim.ConfigError, match=words):
        sim.load(f)  # was: a rank defect of 3 ... the datum (0 constraints) does not cover
