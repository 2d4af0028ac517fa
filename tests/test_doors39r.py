"""The classes of the review R39 (a deeper reading of session 38's merges), one case each;
each failed on the code before its fix.

* a network whose points differ in precision by more than 1e7 in sigma (a point measured at
  0.1 um from two fixed points beside one placed to 1 m): P38's noise floor of the datum
  (a point's variance below 1e-14 of the largest is rounding noise, held by the datum) took the
  precise point for held. The run ended with exit 0, the point missing from ``points.parquet``
  and its README.md saying it was "held in part by the datum constraints" of a fixed datum of
  0 constraints. A variance is noise only where it is also far below what the point's own
  observations give it (``1 / N_ii``).
"""

from __future__ import annotations

from pathlib import Path

import pyarrow.parquet as pq

import sim

SPREAD = """\
study = "network"
trials = 40
chunk = 2
seed = 1

[network]
name = "spread"
points = [
  { name = "A", x_mm = 0.0, y_mm = 0.0, role = "fixed" },
  { name = "B", x_mm = 1000.0, y_mm = 0.0, role = "fixed" },
  { name = "C", x_mm = 10.0, y_mm = 10.0 },
  { name = "D", x_mm = 500.0, y_mm = 500.0 },
]
generate = [
  { kind = "dx", from = "A", to = "C", sigma_mm = 0.0001 },
  { kind = "dy", from = "A", to = "C", sigma_mm = 0.0001 },
  { kind = "dx", from = "B", to = "C", sigma_mm = 0.0001 },
  { kind = "dy", from = "B", to = "C", sigma_mm = 0.0001 },
  { kind = "dx", from = "A", to = "D", sigma_mm = 1000.0 },
  { kind = "dy", from = "A", to = "D", sigma_mm = 1000.0 },
  { kind = "dx", from = "B", to = "D", sigma_mm = 1000.0 },
  { kind = "dy", from = "B", to = "D", sigma_mm = 1000.0 },
]

[datum]
kind = "fixed"
"""


def test_a_precise_point_beside_a_loose_one_is_estimated(tmp_path):
    f = tmp_path / "spread.toml"
    f.write_text(SPREAD, encoding="utf-8")
    res = sim.load(f).run(out=tmp_path / "out", figures=False)
    points = pq.read_table(Path(res.path) / "points.parquet")
    assert points.column("point").to_pylist() == ["C", "D"]
    sx = dict(zip(points.column("point").to_pylist(), points.column("sigma_x_mm").to_pylist()))
    assert abs(sx["C"] - 0.0001 / 2**0.5) < 1e-9, sx  # two readings of 0.1 um each
    assert "held in part" not in (Path(res.path) / "README.md").read_text(encoding="utf-8")
