"""The network kind's size for the work and memory estimate (:mod:`sim.mc.estimate`): points
and observations counted from the declaration, and the memory of the path its size takes
(the sparse or the dense engine, :mod:`sim.lsq.size`). Sizes in points and unknowns, memory in
bytes; see :func:`network_estimate`."""

from __future__ import annotations

import fnmatch
import math
import os
import re
from typing import Mapping

from sim.lsq.size import SPARSE_MIN_UNKNOWNS
from sim.mc.workunits import COPIES, F8
from sim.mc.workunits import dense_units as _dense

__all__ = ["network_estimate", "NAME_SAMPLE", "NETWORK_SPARSE_FROM"]


#: unknowns from which the network kind takes the sparse path (the engine's size rule)
NETWORK_SPARSE_FROM = SPARSE_MIN_UNKNOWNS
#: nonzeros of the sparse factor (as :func:`network_estimate` counts them) worth one unit
#: adjustment of a trial's work. Measured (CPU of 400 against 40 trials, chunk 20): the
#: 50 x 50 grid plate of ``studies/network_gridplate_2500.toml`` (3.8e6 nonzeros) 1.9 ms a
#: trial, 37 units; a 100 x 100 grid plate (1.7e7) 12 ms, 237 units
SPARSE_NNZ_PER_UNIT = 1e5


#: a set of more points than this is matched against a pattern through this many evenly
#: spaced names (each standing for its share of the set): the estimate of a network of
#: millions of points takes a fraction of a second, not a minute of name matching
NAME_SAMPLE = 20_000


def _network_names(c: Mapping) -> list[tuple[list[str], float]]:
    """The point names a network config declares, as ``(names, weight)`` groups: the listed
    points (weight 1), then each grid and random set by prefix (``P1`` ... ``Pk``): all its
    names when there are at most :data:`NAME_SAMPLE`, else that many evenly spaced ones, each
    of weight k / NAME_SAMPLE."""
    groups = [
        ([str(p.get("name", "")) for p in c.get("network.points", []) if isinstance(p, dict)], 1.0)
    ]
    for key, count in (("network.grids", ("nx", "ny")), ("network.random", ("n",))):
        for rec in c.get(key, []):
            if not isinstance(rec, dict):
                continue
            k = math.prod(int(rec.get(f, 1)) for f in count)
            pre = rec.get("prefix", "")
            if k <= NAME_SAMPLE:
                groups.append(([f"{pre}{b + 1}" for b in range(k)], 1.0))
            else:
                picks = dict.fromkeys(
                    round(1 + i * (k - 1) / (NAME_SAMPLE - 1)) for i in range(NAME_SAMPLE)
                )
                groups.append(([f"{pre}{b}" for b in picks], k / len(picks)))
    return groups


def network_estimate(c: Mapping) -> tuple:
    """A network: points and observations counted from the declaration (patterns matched
    against the names; ``nearest`` bounds each generated set), then the memory of the path
    the size takes -- the sparse one counts nonzeros (Jacobian slots per observation, the
    factor ~ nnz(N) log2(unknowns) / 3, its selected inverse), the dense one trials x
    observations x unknowns."""
    T, ch = c["trials"], min(c["chunk"], c["trials"])
    gama = c.get("network.gama_xml", "")
    if gama:  # an imported file: about 80 bytes per observation, 4 observations a point
        m = os.path.getsize(gama) / 80 if os.path.isfile(gama) else 1e3
        n = m / 4
    else:
        groups = _network_names(c)
        n = sum(len(names) * w for names, w in groups)

        def count(pats) -> float:
            pats = [pats] if isinstance(pats, str) else list(pats or [])
            rx = [re.compile(fnmatch.translate(str(p))).match for p in pats]  # = fnmatchcase
            return sum(w * sum(1 for nm in names if any(m(nm) for m in rx)) for names, w in groups)

        m = float(len(c.get("network.observations", [])))
        for g in c.get("network.generate", []):
            if isinstance(g, dict):
                k = int(g.get("nearest", 0) or 0)
                fr, to = count(g.get("from", [])), count(g.get("to", []))
                m += fr * (min(k, to) if k else to)  # nearest=1e300: every target, not 1e300
        m += 2 * sum(
            rec.get("role") == "observed"
            for rec in c.get("network.points", [])
            if isinstance(rec, dict)
        )
        m += 2 * sum(
            math.prod(int(rec.get(f, 1)) for f in ("nx", "ny"))
            for rec in c.get("network.grids", [])
            if isinstance(rec, dict) and rec.get("role") == "observed"
        )
    U = 2 * n + n / 4 + 2  # coordinates, orientations (at most a quarter), constant, scale
    if U >= NETWORK_SPARSE_FROM:
        s = 6.0  # Jacobian slots of a distance or direction row
        # N's nonzeros: the pairs of unknowns a row joins, 8 a row (a pair of points, as most
        # are seen from both ends, or a direction's point and orientation) and a 2 x 2 block a
        # point, not the rows' slot pairs m s^2 (measured, nearest-8 trilateration grids of
        # 10,000 and 50,000 points: 4.5 m; m s^2 made the factor 11 times its real size)
        lg = max(math.log2(max(U, 2)), 1.0)
        nnz_l = (8 * m + 2 * U) * lg / 3 + 4 * U
        b = 3 * F8 * (ch * m * (s + 3) + 3 * ch * U) + 3 * 16 * nnz_l
        # the sparse path: a trial's work grows with the factor's nonzeros, as its memory
        # (one unit per SPARSE_NNZ_PER_UNIT of them; it was one unit whatever the size),
        # counted from the slot pairs m s^2 the unit was measured with
        w = max(1.0, (m * s * s * lg / 3 + 4 * U) / SPARSE_NNZ_PER_UNIT)
    else:
        b = ch * m * (U + 1) * F8 * COPIES
        w = _dense(m, U)  # the dense path: m U^2 + U^3 a trial
    return T, T * w + 2, int(U), b
