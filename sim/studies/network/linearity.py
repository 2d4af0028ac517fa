"""Why a network's adjustment does not converge from its true coordinates: the sight that is
shortest against the a-priori precision of its ends.

The Monte Carlo solves every trial by Gauss-Newton from the true coordinates; a distance,
direction or angle is linear in the coordinates only over a small share of its sight's
length. Where the a-priori standard deviation of a sight's two ends (mm, the pre-analysis's
point covariances, ``sqrt(tr C_i + tr C_j)``) is a sizeable share of its length (mm), a trial's
noise moves the ends by that share and the iteration diverges (a 10,000-point random
trilateration in a 100 m square: the closest pair 13 mm apart, its ends' sigma 2.3 mm, 17 %:
no trial converged, every chunk was computed and the run then refused, naming
``solver.max_iter``, which no limit helps). Coordinate differences and coordinates are linear
and are never named. A gross ``bias`` on an observation is the other cause: named first.
"""

from __future__ import annotations

import numpy as np

from sim.studies.network.definition import Network
from sim.studies.network.validate import KINDS

__all__ = ["weakest_sight", "why_not_converged", "biased", "row_key"]


def weakest_sight(net: Network, cov: np.ndarray) -> tuple[int, int, int, float, float] | None:
    """``(row, a, b, length_mm, sigma_mm)`` of the sight (a distance, a direction, either leg
    of an angle) whose ends' a-priori sigma ``sqrt(tr C_a + tr C_b)`` (``cov``: (n, 2, 2) point
    covariances, mm^2) is the largest share of its length; None without such sights."""
    rows = np.flatnonzero(np.isin(net.kind, (0, 1, 2)))
    if not rows.size:
        return None
    legs = [(rows, net.i[rows], net.j[rows])]
    ang = rows[net.kind[rows] == 2]
    legs.append((ang, net.i[ang], net.k[ang]))
    r, a, b = (np.concatenate(x) for x in zip(*legs))
    d = np.hypot(*(net.xy[b] - net.xy[a]).T)
    tr = np.trace(cov, axis1=1, axis2=2)
    s = np.sqrt(np.maximum(tr[a] + tr[b], 0.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        share = np.where(d > 0, s / d, np.inf)
    w = int(np.argmax(share))
    return int(r[w]), int(a[w]), int(b[w]), float(d[w]), float(s[w])


def row_key(cfg: dict, r: int) -> str:
    """The key that declares row ``r`` of a network built from ``cfg``."""
    if cfg.get("network.gama_xml"):
        return "network.gama_xml"
    return "network.observations" if r < len(cfg["network.observations"]) else "network.generate"


def why_not_converged(net: Network, cov: np.ndarray, cfg: dict, what: str) -> tuple[str, str]:
    """``(key, message)`` for a network none of whose trials converges (``what``: which
    trials, e.g. "none of 16 probe trials converged within solver.max_iter = 20"): the sight
    shortest against its ends' sigma, named by its points and the key that declares it."""
    w = weakest_sight(net, cov)
    if w is None:
        return "solver.max_iter", f"{what}: the network does not converge from its true coordinates"
    r, a, b, d, s = w
    if net.kind[r] == 2:
        sight = f"the angle at {net.names[a]!r}, its sight to {net.names[b]!r}"
    else:
        sight = f"the {KINDS[int(net.kind[r])]} from {net.names[a]!r} to {net.names[b]!r}"
    return row_key(cfg, r), (
        f"{what} from the true coordinates: the network is too far from linear for its noise; "
        f"its weakest sight, {sight}, is {d:.4g} mm long while the a-priori sigma of its ends is {s:.3g} mm ({100 * s / d:.3g} "
        "% of it): place the points further apart, leave such sights out, or make the "
        "observations more precise"
    )


def largest_bias(net: Network) -> tuple[int, str, float, str]:
    """The observation of ``net`` with the largest bias in its sigmas: its row, the bias's
    unit and factor from radians or mm (``arcsec`` or ``mm``) and its words (``the distance
    at 'A' to 'P'``)."""
    r = int(np.argmax(np.abs(net.bias) / net.sigma))
    ang = int(net.kind[r]) in (1, 2)
    unit, f = ("arcsec", 648000 / np.pi) if ang else ("mm", 1.0)
    obs = f"the {KINDS[int(net.kind[r])]} at {net.names[net.i[r]]!r}"
    obs += f" from {net.names[net.j[r]]!r}" if net.kind[r] == 2 else ""
    to = net.k[r] if net.kind[r] == 2 else net.j[r]
    obs += f" to {net.names[to]!r}" if to >= 0 else ""
    return r, unit, f, obs


def biased(net: Network, cfg: dict, what: str) -> tuple[str, str] | None:
    """``(key, message)`` for a network whose trials do not converge (``what``: which) when an
    observation carries a bias, a gross error unknown to the adjustment: the largest, in its
    sigmas, named by the key that declares it (a ``network.generate`` bias was named
    ``network.observations``, a key the study did not set); None when none has a bias."""
    if not np.any(net.bias):
        return None
    r, unit, f, obs = largest_bias(net)
    return row_key(cfg, r), (
        f"{what}: the bias of {net.bias[r] * f:g} {unit} on {obs} is a gross error the "
        "adjustment cannot absorb (a bias is unknown to it): make it smaller"
    )
