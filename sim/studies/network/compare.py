"""The compared parameterisation (``compare.fix``): the network adjusted again with these
points known, and each point's dilution (%) between the two, both in a datum that holding
those points holds (the study's own, or the inner datum over them by S-transformation).
:func:`check_compare` is its ``sim check`` rule. Lengths in mm.
"""

from __future__ import annotations

import numpy as np

from sim.mc.config import ConfigError, StudyError
from sim.studies.network.analysis import check_inner, held_defect, in_datum, match_points
from sim.studies.network.definition import Network
from sim.studies.network.model import datum
from sim.studies.network.rank_defect import refuse_defect
from sim.studies.network.sparse_analysis import in_datum_sparse, pre_analysis
from sim.studies.network.validate import name_index, select

__all__ = ["check_compare", "compare_points", "dilution", "held_by"]


def check_compare(net, full: dict, fix: list, sparse: bool) -> None:
    """``compare.fix``: the compared datum leaves something to estimate and covers the defects,
    and, where the dilution is stated in the inner datum over its points (:func:`held_by`),
    those points can hold that datum (not one point against a rotation)."""
    extra = match_points(net, "compare.fix", fix)
    if all(net.role[e] == 1 for e in extra):
        raise ConfigError("compare.fix", "names only fixed points: the compared datum is this one")
    if set(np.flatnonzero(net.role != 1)) <= set(extra):
        raise ConfigError("compare.fix", "fixes every estimated point: nothing to compare")
    an2 = pre_analysis(net, datum(net, full, tuple(extra)), 0.001, 0.8)
    if not an2.ok and sparse:
        raise ConfigError("compare.fix", f"{an2.factor.message} in the compared datum")
    if not an2.ok:
        refuse_defect(net, datum(net, full, tuple(extra)), "compare.fix")
    dt = datum(net, full)
    if not held_by(net, dt, extra):
        # the dilution moves the study's sigmas to the inner datum over these points: one
        # point against a rotation printed +25 % to +251 % from a singular S-transformation
        try:
            check_inner(net, held_defect(net, dt.free_index(net.q)), extra, "compare.fix")
        except ConfigError as e:
            raise ConfigError(
                "compare.fix",
                f"{str(e)[len(e.key) + 2 :]} (the study's datum is not one that holding them "
                "holds, so the dilution compares both in the inner datum over them)",
            ) from None


def compare_points(net: Network, cfg: dict) -> list[int]:
    """The points ``compare.fix`` names (patterns), each once, in the order named."""
    return select("compare.fix", cfg["compare.fix"], net.names, name_index(net.names))


def _rms_sigma(cov: np.ndarray) -> np.ndarray:
    return np.sqrt((cov[:, 0, 0] + cov[:, 1, 1]) / 2)


def dilution(net: Network, an, full: dict, cfg: dict, pts: list[int]) -> np.ndarray:
    """Per point, how much larger (%) its rms sigma is than with the ``compare.fix`` points
    known as well (NaN without ``compare.fix`` or where the compared sigma is 0). Both sigmas
    are in a datum that holding those points holds: the study's own when its constraints touch
    only their coordinates (``fixed``; Brown's x1 = x3 = 0, y4 = -y2 against the stations
    known), else the inner datum over them (S-transformation: :func:`held_by`)."""
    dil = np.full(len(pts), np.nan)
    extra = compare_points(net, cfg)
    if extra:
        an2 = pre_analysis(net, datum(net, full, tuple(extra)), 0.001, 0.8)
        if not an2.ok:
            raise StudyError("compare.fix: the compared parameterisation is singular")
        cov = an.cov
        dt = datum(net, full)
        if not held_by(net, dt, extra):
            # the defects the study's fixed points leave (one fixed point: the rotation about
            # it), not a free network's: its translations over one compared point were singular
            H = held_defect(net, dt.free_index(net.q))
            cov = (
                in_datum_sparse(net, an, extra, H) if an.Q is None else in_datum(net, an, extra, H)
            )
        s1, s2 = _rms_sigma(cov[pts]), _rms_sigma(an2.cov[pts])
        with np.errstate(divide="ignore", invalid="ignore"):
            dil = np.where(s2 > 0, 100 * (s1 / s2 - 1), np.nan)
    return dil


def held_by(net: Network, dt, extra: list[int]) -> bool:
    """Whether the ``extra`` points known hold the datum ``dt`` too (every constraint touches
    only their coordinates): else its sigmas are of another datum than the compared ones, and
    their ratio no dilution (an inner datum over every point against two of them known: the
    other points' sigmas -45 % "diluted", the smaller in the inner datum)."""
    C = dt.constraint_matrix(net.theta_true()[None])
    if C is None:
        return True
    g = dt.free_index(net.q)[np.abs(C[0]).sum(1) > 0]
    return bool(np.all((g < 2 * net.n) & np.isin(g // 2, extra)))
