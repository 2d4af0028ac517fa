"""The network kind at real sizes (brief M47); each test failed on the code before its change.

* A network whose datum is held by many fixed points (a 100 x 100 grid of ``role = "fixed"``
  control with 50 new points observed to their nearest six) took 6.4 GB of memory and 54 s in
  ``sim check`` where the estimate said 37 MiB: the datum's defect basis took the full SVD of
  the similarity transformations at the held coordinates, whose ``U`` is (2 x fixed points)
  squared (3.2 GB at 10,000 fixed points; a 70 x 70 grid 1.6 GB). Only ``V`` is wanted: the
  thin SVD from four rows on (the same ``V``, bit for bit, so no study's numbers change).
  Now 0.29 GB; the test loads the network at two sizes of its fixed grid and asserts the
  memory grows by the points' state, not by their square.
* Many observations of few points (the dense path, under 400 unknowns: 198 points with every
  other one observed, 39,006 distances) asked for 11.3 GiB in ``sim check``: the
  pre-analysis formed the whole (m, m) hat matrix for its diagonal, the redundancy numbers.
  Its diagonal is formed 2,048 rows at a time now (the same numbers, bit for bit, on the
  committed networks and a 9,900-row one).
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


DENSE_ROWS = """study = "network"
trials = 40
chunk = 2
[network]
random = [ { prefix = "R", n = 100, half_extent_m = 500.0 } ]
generate = [ { kind = "distance", from = "R*", to = "R*", nearest = 50, sigma_mm = 1.0 } ]
[datum]
kind = "inner"
"""


def test_many_observations_on_the_dense_path_cost_no_square_of_them(tmp_path):
    """Many observations of few points (the dense path: 100 points, 5,000 distances): the
    pre-analysis formed the whole (m, m) hat matrix for its diagonal (200 MB here; 11.3 GiB
    for 198 points with every other one observed, refused only by the machine's memory); its
    diagonal is taken a block of rows at a time now (at most 2,048 x 2,048)."""
    from sim.studies.network.analysis import analyse
    from sim.studies.network.definition import build
    from sim.studies.network.model import datum

    p = tmp_path / "dense.toml"
    p.write_text(DENSE_ROWS)
    cfg = sim.load(p).config
    net = build(cfg)
    dt = datum(net, cfg)
    assert net.m == 5000 and net.q < 400  # the dense path
    tracemalloc.start()
    try:
        an = analyse(net, dt, 0.001, 0.8)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 120e6, f"{peak / 1e6:.0f} MB for {net.m} observations"
    assert abs(an.redundancy.sum() - an.dof) < 1e-6 * an.dof  # the numbers sum to the dof
