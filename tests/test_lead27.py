"""The lead's items of the session of 2026-11-28 (issue 26), one case each; each failed on the
code before its fix.

* a network whose sigmas make the normals singular was refused as "condition number 7.4e10,
  too large to solve in double precision": double precision solves that; the refusal is the
  engine's rule (the normals scaled to unit diagonal, a reciprocal condition number under
  :data:`sim.lsq.normals.RCOND`), and the line now states that rule and its number;
"""

import re
from pathlib import Path

from oneline import one_line

from sim.cli import main
from sim.lsq.normals import RCOND

ROOT = Path(__file__).resolve().parent.parent
PLATE = str(ROOT / "studies" / "network_plate.toml")


def test_a_network_singular_from_its_weights_states_the_engines_rule(capsys):
    """Weighted coordinates (1 m) beside differences of 2 um: the scaled normals' reciprocal
    condition number is printed, and it is under the engine's limit it names."""
    grid = '[{prefix="G",nx=5,ny=5,spacing_mm=40.0,role="observed",sigma_mm=1e3}]'
    err = one_line(
        capsys,
        main(["check", PLATE, "--set", f"network.grids={grid}"]),
        "from its weights",
        "scaled to unit diagonal",
        f"limit of {RCOND:g}",
    )
    assert "double precision" not in err
    rc = float(re.search(r"condition number of ([0-9.e+-]+),", err).group(1))
    assert 0 < rc < RCOND
