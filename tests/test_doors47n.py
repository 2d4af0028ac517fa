"""The network kind at real sizes (brief M47); each test failed on the code before its change.

* A network whose datum is held by many fixed points (a 100 x 100 grid of ``role = "fixed"``
  control with 50 new points observed to their nearest six) took 6.4 GB of memory and 54 s in
  ``sim check`` where the estimate said 37 MiB: the datum's defect basis took the full SVD of
  the similarity transformations at the held coordinates, whose ``U`` is (2 x fixed points)
  squared (3.2 GB at 10,000 fixed points; a 70 x 70 grid 1.6 GB). Only ``V`` is wanted: the
  thin SVD from four rows on (the same ``V``, bit for bit, so no study's numbers change).
  Now 0.29 GB; the test loads the network at two sizes of its fixed grid and asserts the
  memory grows by the points' state, not by their square.
"""

from __future__ import annotations

import tracemalloc
from pathlib import Path

import sim

FIXED_GRID = """study = "network"
trials = 40
chunk = 2
[network]
grids = [ {{ prefix = "G", nx = {n}, ny = {n}, spacing_m = 20.0, role = "fixed" }} ]
random = [ {{ prefix = "R", n = 20, half_extent_m = {half}.0 }} ]
generate = [ {{ kind = "distance", from = "R*", to = "G*", nearest = 6, sigma_mm = 1.0 }},
             {{ kind = "direction", from = "R*", to = "G*", nearest = 6, sigma_arcsec = 1.0 }} ]
[datum]
kind = "fixed"
"""


def _load_peak(tmp_path: Path, n: int) -> int:
    """Peak bytes NumPy and Python allocate while ``sim.load`` checks a network of ``n x n``
    fixed points and 20 free ones (the check builds the network and its datum)."""
    p = tmp_path / f"fixed{n}.toml"
    p.write_text(FIXED_GRID.format(n=n, half=8 * n))
    tracemalloc.start()
    try:
        sim.load(p)
        return tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


def test_many_fixed_points_cost_their_state_not_their_square(tmp_path):
    """Many fixed points (the datum held by a large control grid): the check's memory grew
    with the square of the fixed points (a 45 x 45 grid: 130 MB more than a 20 x 20 one,
    the full SVD's U of 4,050 x 4,050); now by their state, a few MB."""
    _load_peak(tmp_path, 20)  # the first load compiles and imports: not counted
    small = _load_peak(tmp_path, 20)
    large = _load_peak(tmp_path, 45)
    grown = large - small
    assert grown < 16e6, f"{grown / 1e6:.1f} MB more for 1,625 more fixed points"
