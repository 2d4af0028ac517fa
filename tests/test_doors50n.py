"""Helper n51: the network kind's keys in combination.

Combinations a designer would try (a free datum with fixed points too, constraints on fixed
points, grid patterns matching no point, ``--set`` on a grid list's element, directions
without a distance, distances alone under a free datum, a network in two unconnected parts,
a point observed once, observations only between fixed points, estimated constant or scale
without the observations that determine them, a sweep over ``compare.fix``); one case per
class found, each failing on the code before its fix.

* ``compare.fix`` naming one point of a network whose datum it does not hold (an inner
  datum, or constraints on other points): the dilution moves the study's sigmas into the
  inner datum over the ``compare.fix`` points by S-transformation, and one point cannot hold
  a rotation: the transformation's ``H' W H`` was singular to rounding and ``np.linalg.solve``
  gave numbers anyway: the run printed dilutions of +25 % to +251 % and a finding "largest
  dilution 251 %", exit 0 (``output.inner_over`` over the same point was refused). Refused
  now by ``sim check``, naming ``compare.fix`` and the defects the points cannot hold.
  With a fixed point in the network (one fixed, an inner datum over the others, one point
  compared) the transformation removed a free network's translations too, which the fixed
  point already holds: singular again, a dilution of -8 % printed (holding a point made
  another less precise). It removes the defects the fixed points leave now (the rotation
  about the fixed point), and every dilution is at least 0.
* Distances alone about one fixed point (the rotation undetermined), directions alone about
  one (rotation and scale): refused as "a rank defect of 1 (6 unknowns, rank 5) that the
  datum (0 constraints) does not cover", which motion left to the user to guess; the line now
  says it ("a rotation about the fixed points", "a rotation and a scale ...") where the
  defect is the datum's motions and no constraint is given.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from oneline import SIM_ERROR, one_line

import sim
from sim.cli import main
from sim.studies.network.analysis import estimated_points
from sim.studies.network.compare import dilution
from sim.studies.network.definition import build
from sim.studies.network.gama import merge_gama
from sim.studies.network.model import datum
from sim.studies.network.sparse_analysis import pre_analysis

FIVE = """study = "network"
trials = 40
chunk = 2
[network]
points = [ { name = "A", x_mm = 0.0, y_mm = 0.0 }, { name = "B", x_mm = 1000.0, y_mm = 0.0 },
           { name = "C", x_mm = 400.0, y_mm = 700.0 }, { name = "D", x_mm = 900.0, y_mm = 800.0 },
           { name = "E", x_mm = 500.0, y_mm = -600.0 } ]
generate = [ { kind = "distance", from = "*", to = "*", sigma_mm = 0.01 } ]
[datum]
kind = "inner"
"""


def _study(tmp_path: Path, text: str, name: str = "net") -> str:
    p = tmp_path / f"{name}.toml"
    p.write_text(text)
    return str(p)


def test_compare_fix_of_one_point_against_an_inner_datum_is_refused(tmp_path, capsys):
    """A compared parameterisation whose points cannot hold the study's datum (one point
    against a rotation, the study's datum inner): its dilution was an S-transformation
    through a singular matrix, +251 % printed as a finding, exit 0; two points hold it."""
    two = _study(tmp_path, FIVE + '[compare]\nfix = ["A", "B"]\n', "two")
    assert main(["check", two]) == 0
    capsys.readouterr()
    one = _study(tmp_path, FIVE + '[compare]\nfix = ["A"]\n', "one")
    line = one_line(capsys, main(["check", one]), "compare.fix", prefix=SIM_ERROR)
    assert "the points A cannot fix" in line and "a rotation" in line, line


def test_a_rank_defect_of_the_fixed_datum_says_which_motion_is_left(tmp_path, capsys):
    """Distances alone and one fixed point: the rotation about it is undetermined; the
    refusal gave the defect's size alone (1), not which motion of the network it is."""
    text = FIVE.replace(
        '"A", x_mm = 0.0, y_mm = 0.0 }', '"A", x_mm = 0.0, y_mm = 0.0, role = "fixed" }'
    )
    text = text.replace('kind = "inner"', 'kind = "fixed"')
    line = one_line(capsys, main(["check", _study(tmp_path, text)]), prefix=SIM_ERROR)
    assert line.startswith(SIM_ERROR + "datum.kind: the network has a rank defect of 1"), line
    assert "a rotation about the fixed points" in line, line


def _dilution(path: str):
    cfg = sim.load(path).config
    full = merge_gama(cfg)
    net = build(full)
    an = pre_analysis(net, datum(net, full), 0.001, 0.8)
    pts = estimated_points(net, an)
    return [net.names[p] for p in pts], dilution(net, an, full, cfg, pts)


def test_compare_fix_of_one_point_about_a_fixed_point_is_the_held_datum_s(tmp_path):
    """One fixed point A, an inner datum over the others, B compared: the dilution's
    S-transformation removed translations A holds (singular: C +25 %, and -8 % in a
    gama-local file's network). It is now the dilution of the datum that holding B holds
    about A, B's rotation about A (B.y = 0: B lies on A's x axis), written out as that
    minimal constraint."""
    text = FIVE.replace(
        '"A", x_mm = 0.0, y_mm = 0.0 }', '"A", x_mm = 0.0, y_mm = 0.0, role = "fixed" }'
    )
    text = text.replace(
        "generate = [",
        'generate = [ { kind = "direction", from = "*", to = "*", sigma_arcsec = 1.0 },',
    )
    cmp = '[compare]\nfix = ["B"]\n'
    names, inner = _dilution(_study(tmp_path, text + cmp, "inner"))
    held = text.replace('kind = "inner"', 'kind = "constraints"\nconstraints = [ { "B.y" = 1.0 } ]')
    names2, ref = _dilution(_study(tmp_path, held + cmp, "held"))
    assert names == ["B", "C", "D", "E"] and names2 == ["C", "D", "E"], (names, names2)
    np.testing.assert_allclose(inner[1:], ref, rtol=1e-6)
    assert min(ref) >= 0 and max(ref) > 0.01, ref
