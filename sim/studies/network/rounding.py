"""Double precision at the edge: a point whose sigma its coordinate's rounding swamps.

The Monte Carlo adjusts every trial's coordinates in double precision, taken from the
network's whole-kilometre origin (:func:`sim.studies.network.definition.build`). A coordinate
of magnitude X is held to ``spacing(X)`` (2.2e-16 X to 4.4e-16 X), so an adjusted point whose
analytic sigma is not well above that spacing scatters by its rounding as much as by its
readings: the Monte-Carlo sigmas, the ellipse coverage and the global test then measure
cancellation noise (a cluster 60 km from the origin with sigmas of 1e-9 mm covered 73 % in
its 95 % ellipse), and further out the adjustment no longer converges at all. The pre-analysis
itself is exact there (it is translation invariant to 1e-12), so the network is refused by ``sim check``
and before its Monte Carlo, naming the point, its distance from the origin and the rounding.

Units: those of the network (mm).
"""

from __future__ import annotations

import numpy as np

from sim.mc.config import ConfigError
from sim.studies.network.definition import Network

__all__ = ["ROUNDING_SHARE", "check_rounding"]

#: the largest rounding of an adjusted coordinate, as a share of its point's smallest sigma
#: (a uniform rounding of 0.1 sigma adds 0.08 % to the variance)
ROUNDING_SHARE = 0.1


def check_rounding(net: Network, cov: np.ndarray, pts: list[int]) -> None:
    """Refuse (one line) when a coordinate's double-precision spacing exceeds
    :data:`ROUNDING_SHARE` of its point's smallest analytic sigma (``cov`` (n, 2, 2))."""
    if not pts:
        return
    p = np.asarray(pts)
    spacing = np.spacing(np.abs(net.xy[p]).max(axis=1))
    c = cov[p]
    with np.errstate(invalid="ignore"):
        smallest = np.sqrt(np.clip(np.linalg.eigvalsh(c)[:, 0], 0.0, None))
        share = np.where(smallest > 0, spacing / smallest, np.inf)
    worst = int(np.argmax(np.nan_to_num(share, nan=0.0)))
    if not share[worst] > ROUNDING_SHARE:
        return
    a = int(p[worst])
    far = float(np.abs(net.xy[a]).max())
    raise ConfigError(
        "network.points",
        f"point {net.names[a]!r} lies {far / 1e6:.4g} km from the network's "
        f"origin, where double precision rounds a coordinate to {spacing[worst]:.2g} mm, over "
        f"{ROUNDING_SHARE:g} of its smallest sigma ({smallest[worst]:.2g} mm): the Monte Carlo "
        "would measure the rounding; make the smallest sigmas larger or the network smaller",
    )
