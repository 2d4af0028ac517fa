"""The network kind's size for the work and memory estimate (:mod:`sim.mc.estimate`): points
and observations counted from the declaration, and the memory of the path its size takes
(the sparse or the dense engine, :mod:`sim.lsq.size`). Sizes in points and unknowns, memory in
bytes; see :func:`network_estimate`."""

from __future__ import annotations

import fnmatch
import math
import os
import re
from typing import Mapping, NamedTuple

from sim.lsq.size import SPARSE_MIN_UNKNOWNS
from sim.lsq.sparse import factor_nonzeros
from sim.mc.gama_count import GamaCounts, gama_counts
from sim.mc.workunits import COPIES, F8

__all__ = [
    "network_estimate",
    "network_counts",
    "Counts",
    "NAME_SAMPLE",
    "NETWORK_SPARSE_FROM",
    "state_bytes",
    "sparse_chunk_bytes",
]


#: unknowns from which the network kind takes the sparse path (the engine's size rule)
NETWORK_SPARSE_FROM = SPARSE_MIN_UNKNOWNS
#: Gauss-Newton iterations a trial takes, counted by the run (``rows.iterations``; fixed
#: seeds, 2 mm / 1 arcsec networks of 16 to 50,176 points): on the sparse path, whose one
#: factor of the nominal normals serves every iteration, one for observations linear in the
#: unknowns (coordinate differences and coordinates: the first step is the solution) and three
#: with a distance, direction or angle; on the dense path, re-linearised at each step, two
#: (the step and the one that confirms it) and three with a non-linear kind
SPARSE_ITERATIONS = {False: 1, True: 3}
DENSE_ITERATIONS = {False: 2, True: 3}
#: the observation kinds not linear in the unknowns
NONLINEAR_KINDS = ("distance", "direction", "angle")
#: nonzeros of the normals ``N`` (both triangles) a row of each kind adds: the distinct pairs
#: of unknowns it joins, a pair of points seen from both ends counted once (measured with
#: :func:`sim.lsq.sparse.normals_nonzeros`: a nearest-8 trilateration grid 4.5 a distance; a
#: coordinate difference joins two unknowns, 1 a row; a direction adds its station's
#: orientation, an angle a third point); each point adds its 2 x 2 block
NNZ_PER_ROW = {"distance": 4.5, "direction": 8.5, "angle": 12.0, "dx": 1.0, "dy": 1.0}
#: unit adjustments of the sparse path's work (measured, CPU of 20 to 40 trials after a
#: warm-up chunk, 1,024 to 10,000 points): one iteration of a trial solves with the factor,
#: ~5e-9 s a nonzero (:func:`sim.lsq.sparse.factor_nonzeros`), and evaluates the residuals
#: and gradient, ~2e-8 s a row, once more after the last step; the pre-analysis (factor,
#: selected inverse, reliability) ~2e-6 s a factor nonzero (4 s at 10,000 points)
SPARSE_NNZ_PER_UNIT = 1.0e4
SPARSE_ROWS_PER_UNIT = 2.5e3
SPARSE_SETUP_UNITS_PER_NNZ = 0.04
#: unit adjustments per observation of the outputs, once a run (the tables, the figures, the
#: gama-local export): measured, a 10,000-point trilateration grid (80,000 distances), 9.5 s
OUTPUT_UNITS_PER_ROW = 2.5
#: a dense network adjustment's iteration, in unit adjustments: DENSE_ITERATION_UNITS (the
#: batch's steps, amortised over a chunk) plus m U over DENSE_ROWS_COLS_PER_UNIT (the Jacobian
#: and the trial's tables) plus m U^2 + U^3 over DENSE_WORK_PER_UNIT (the normals and their
#: solve). Measured with single-threaded BLAS, as ``sim`` runs: 4 points (11 x 13, chunk
#: 5,000) 0.4 an iteration; the test field (133 x 38) 3.4; Brown's comparator (100 x 60) 9.7;
#: a 13 x 13 plate (674 x 340) 441; a 196-point trilateration grid (1,568 x 394) 930. It was
#: one unit a trial whatever the size: the test field's 100,000 trials took 4 times that
DENSE_ITERATION_UNITS = 0.5
DENSE_ROWS_COLS_PER_UNIT = 2.0e3
DENSE_WORK_PER_UNIT = 2.8e5


#: bytes the sparse path holds besides a chunk's arrays and the factor (measured: peak RSS
#: over a 300-point network's, dx/dy grids of 22,500 and 90,000 points and a 20,000-point
#: trilateration, chunks of 2): per point its arrays and Python name; per slot pair of the
#: Jacobian's rows (``m s^2``, s the pattern's width: 4 for coordinate differences and
#: coordinates alone, 7 with a distance, direction or angle) the normal equations assembled
#: from every row's slot pairs when the network is checked. The chunk model before counted a
#: Jacobian per trial the sparse path never forms and no assembly: a 90,000-point plate was
#: estimated at 0.22 GiB and took 0.49 GiB, a 2,500-point one 0.27 GiB for 0.04 GiB
STATE_BYTES_PER_POINT = 2048
STATE_BYTES_PER_SLOT_PAIR = 40
#: bytes a trial of a chunk holds per observation and per unknown (its simulated readings,
#: residuals and weights; its unknowns, gradient and step): measured 41 to 50 bytes per
#: observation at 2,500 and 20,000 points, chunks of 10 to 200
CHUNK_BYTES_PER_ROW, CHUNK_BYTES_PER_UNKNOWN = 48.0, 80.0


def slot_width(nonlinear: bool) -> int:
    """The Jacobian pattern's slots a row (the widest kind decides): 7 with a distance,
    direction or angle (two points, an orientation, the constant and the scale), else 4."""
    return 7 if nonlinear else 4


def state_bytes(points: float, rows: float, nonlinear: bool = True) -> float:
    """Bytes of a network's state on the sparse path (:data:`STATE_BYTES_PER_POINT`,
    :data:`STATE_BYTES_PER_SLOT_PAIR`): what the early check of the declaration
    (:func:`sim.studies.network.validate._fits`, every kind taken as non-linear) and the
    run's estimate both count, so that no refusal states more than ``sim check`` shows."""
    return points * STATE_BYTES_PER_POINT + rows * slot_width(nonlinear) ** 2 * (
        STATE_BYTES_PER_SLOT_PAIR
    )


def sparse_chunk_bytes(chunk: float, rows: float, unknowns: float, factor_nnz: float) -> float:
    """Bytes one Monte-Carlo chunk of the sparse path holds: its trials' arrays
    (:data:`CHUNK_BYTES_PER_ROW`, :data:`CHUNK_BYTES_PER_UNKNOWN`) and the factor with its
    selected inverse (three 16-byte entries a nonzero)."""
    per_trial = rows * CHUNK_BYTES_PER_ROW + unknowns * CHUNK_BYTES_PER_UNKNOWN
    return chunk * per_trial + 3 * 16 * factor_nnz


#: a set of more points than this is matched against a pattern through this many evenly
#: spaced names (each standing for its share of the set): the estimate of a network of
#: millions of points takes a fraction of a second, not a minute of name matching
NAME_SAMPLE = 20_000


def _network_names(c: Mapping) -> list[tuple[list[str], float]]:
    """The point names a network config declares, as ``(names, weight)`` groups: the listed
    points (weight 1), then each grid and random set by prefix (``P1`` ... ``Pk``): all its
    names when there are at most :data:`NAME_SAMPLE`, else that many evenly spaced ones, each
    of weight k / NAME_SAMPLE."""
    groups = [(_listed(c), 1.0)]
    for pre, k in _sets(c):
        if k <= NAME_SAMPLE:
            groups.append(([f"{pre}{b + 1}" for b in range(k)], 1.0))
        else:
            picks = dict.fromkeys(
                round(1 + i * (k - 1) / (NAME_SAMPLE - 1)) for i in range(NAME_SAMPLE)
            )
            groups.append(([f"{pre}{b}" for b in picks], k / len(picks)))
    return groups


def _listed(c: Mapping) -> list[str]:
    """The names of the points listed one by one (``network.points``)."""
    return [str(p.get("name", "")) for p in c.get("network.points", []) if isinstance(p, dict)]


def _sets(c: Mapping) -> list[tuple[str, int]]:
    """Each grid and random set as ``(prefix, k)``: its points are named ``prefix1`` ...
    ``prefixk``."""
    out = []
    for key, count in (("network.grids", ("nx", "ny")), ("network.random", ("n",))):
        for rec in c.get(key, []):
            if isinstance(rec, dict):
                out.append(
                    (str(rec.get("prefix", "")), math.prod(int(rec.get(f, 1)) for f in count))
                )
    return out


def _declares(name: str, listed: set[str], sets: list[tuple[str, int]]) -> bool:
    """Whether the network declares a point of this very name (listed, or ``prefix<b>`` of a
    set of k points, 1 <= b <= k): a name without wildcards is counted by this, not through
    :data:`NAME_SAMPLE`'s evenly spaced names, whose weight counted one named point of a
    90,000-point grid (``from = "G1"``) as 4.5 points: a 300 x 300 plate's memory was
    estimated at 1.98 GiB (it takes 0.49)."""
    if name in listed:
        return True
    for pre, k in sets:
        b = name[len(pre) :] if name.startswith(pre) else ""
        if b.isascii() and b.isdigit() and b[0] != "0" and int(b) <= k:
            return True
    return False


class Counts(NamedTuple):
    """What a network run does, counted from its declaration: ``unknowns`` (the engine's q),
    ``rows`` (observations), ``sparse`` (the path), ``iterations`` (a trial's Gauss-Newton
    steps), ``factor_nnz`` (the sparse factor's nonzeros, 0 on the dense path), ``points``,
    ``nonlinear`` (a distance, direction or angle among the rows)."""

    unknowns: float
    rows: float
    sparse: bool
    iterations: int
    factor_nnz: float
    points: float = 0.0
    nonlinear: bool = True


def network_counts(c: Mapping) -> Counts:
    """:class:`Counts` of the network ``c`` declares (points and observations counted from
    the declaration, patterns matched against the names, ``nearest`` bounding each generated
    set; an imported ``network.gama_xml`` by its elements, :func:`sim.mc.gama_count.
    gama_counts`, else by its size): the path its unknowns take (the
    engine's rule), a trial's iterations (:data:`SPARSE_ITERATIONS`,
    :data:`DENSE_ITERATIONS`, at most ``solver.max_iter``) and on the sparse path the
    factor's nonzeros from the normals' (:data:`NNZ_PER_ROW`,
    :func:`sim.lsq.sparse.factor_nonzeros`)."""
    gama = c.get("network.gama_xml", "")
    counted = gama_counts(gama) if gama else None
    if counted:  # an imported file: its elements counted (sim.mc.gama_count)
        n, m, orient, nnz_rows, nonlinear = _from_file(counted)
    elif gama:  # one not counted (not XML, ...): about 80 bytes an observation, 4 a point
        m = os.path.getsize(gama) / 80 if os.path.isfile(gama) else 1e3
        n, orient, nnz_rows, nonlinear = m / 4, m / 16, 6.0 * m, True
    else:
        n, m, orient, nnz_rows, nonlinear = _declared(c)
    U = 2 * n + orient + 2  # coordinates, orientations, constant, scale
    cap = max(int(c.get("solver.max_iter", 50) or 1), 1)
    if U >= NETWORK_SPARSE_FROM:
        free = max(U - 2 * (0.0 if gama else _fixed(c)), 1.0)  # the factor's: no fixed point
        nnz_l = factor_nonzeros(int(free), int(nnz_rows + 2 * free))
        return Counts(U, m, True, min(SPARSE_ITERATIONS[nonlinear], cap), nnz_l, n, nonlinear)
    return Counts(U, m, False, min(DENSE_ITERATIONS[nonlinear], cap), 0.0, n, nonlinear)


def network_estimate(c: Mapping) -> tuple:
    """A network's ``(trials, adjustments, unknowns, bytes)``: on the sparse path each
    iteration of a trial one solve with the factor (:data:`SPARSE_NNZ_PER_UNIT`) and one pass
    over the rows (:data:`SPARSE_ROWS_PER_UNIT`), one pass more after the last step, and the
    pre-analysis once (:data:`SPARSE_SETUP_UNITS_PER_NNZ`) and the outputs (:data:`OUTPUT_UNITS_PER_ROW`); its memory the Jacobian slots of a
    chunk and the factor with its selected inverse. On the dense path each iteration
    a constant, m U and m U^2 + U^3 (:data:`DENSE_WORK_PER_UNIT`), its memory trials x observations x
    unknowns."""
    T, ch = c["trials"], min(c["chunk"], c["trials"])
    k = network_counts(c)
    U, m, it, nnz_l = k.unknowns, k.rows, k.iterations, k.factor_nnz
    if k.sparse:
        b = sparse_chunk_bytes(ch, m, U, nnz_l) + state_bytes(k.points, m, k.nonlinear)
        b = max(b, state_bytes(k.points, m))  # never less than the declaration's check counts
        rows = m / SPARSE_ROWS_PER_UNIT
        w = it * (nnz_l / SPARSE_NNZ_PER_UNIT + rows) + rows
        setup = SPARSE_SETUP_UNITS_PER_NNZ * nnz_l
    else:
        b = ch * m * (U + 1) * F8 * COPIES
        w = it * (
            DENSE_ITERATION_UNITS
            + m * U / DENSE_ROWS_COLS_PER_UNIT
            + (m * U * U + U**3) / DENSE_WORK_PER_UNIT
        )
        setup = 0.0
    return T, T * w + setup + OUTPUT_UNITS_PER_ROW * m + 2, int(U), b


def _from_file(k: GamaCounts) -> tuple[float, float, float, float, bool]:
    """:func:`_declared`'s counts of a ``gama-local`` file's :class:`GamaCounts`."""
    rows = {kind: float(v) for kind, v in k.rows.items() if kind in NNZ_PER_ROW}
    m = sum(rows.values()) + k.rows.get("coordinates", 0)
    nnz_rows = sum(NNZ_PER_ROW[kind] * v for kind, v in rows.items())
    nonlinear = any(rows.get(kind, 0) > 0 for kind in NONLINEAR_KINDS)
    return float(k.points), float(m), float(min(k.orientations, k.points)), nnz_rows, nonlinear


def _fixed(c: Mapping) -> float:
    """Fixed points a network config declares (``role = "fixed"``, listed, grids, random sets):
    held, not in the sparse factor. They were counted as its unknowns: a 100 x 100 fixed grid
    around 20 new points was estimated at a factor of 280,000 nonzeros over 20,062 unknowns
    (13 MiB of the 36 MiB estimated; the run's arrays peaked at 9 MiB), not one of 62."""
    fixed = sum(
        rec.get("role") == "fixed" for rec in c.get("network.points", []) if isinstance(rec, dict)
    )
    for key, count in (("network.grids", ("nx", "ny")), ("network.random", ("n",))):
        fixed += sum(
            math.prod(int(rec.get(f, 1)) for f in count)
            for rec in c.get(key, [])
            if isinstance(rec, dict) and rec.get("role") == "fixed"
        )
    return float(fixed)


def _declared(c: Mapping) -> tuple[float, float, float, float, bool]:
    """``(points, observations, orientation unknowns, N's nonzeros of the rows, any
    non-linear kind)`` counted from a declared network."""
    groups = _network_names(c)
    n = sum(len(names) * w for names, w in groups)

    listed, sets = set(_listed(c)), _sets(c)

    def count(pats) -> float:
        pats = [str(p) for p in ([pats] if isinstance(pats, str) else list(pats or []))]
        names = {p for p in pats if not any(ch in p for ch in "*?[")}  # a point by its name
        rx = [re.compile(fnmatch.translate(p)).match for p in pats if p not in names]
        n = sum(1.0 for nm in names if _declares(nm, listed, sets))
        return n + sum(
            w * sum(1 for nm in group if nm not in names and any(m(nm) for m in rx))
            for group, w in groups
        )

    obs = [o for o in c.get("network.observations", []) if isinstance(o, dict)]
    rows = {k: 0.0 for k in NNZ_PER_ROW}
    for o in obs:
        rows[o.get("kind")] = rows.get(o.get("kind"), 0.0) + 1
    orient = len(
        {(o.get("at", o.get("from")), o.get("set")) for o in obs if o.get("kind") == "direction"}
    )
    for g in c.get("network.generate", []):
        if isinstance(g, dict):
            k = int(g.get("nearest", 0) or 0)
            fr, to = count(g.get("from", [])), count(g.get("to", []))
            r = fr * (min(k, to) if k else to)  # nearest=1e300: every target, not 1e300
            rows[g.get("kind")] = rows.get(g.get("kind"), 0.0) + r
            orient += fr if g.get("kind") == "direction" else 0
    m = sum(rows.values())
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
    nnz_rows = sum(NNZ_PER_ROW.get(k, 8.0) * v for k, v in rows.items())
    nonlinear = any(rows.get(k, 0) > 0 for k in NONLINEAR_KINDS)
    return n, m, min(orient, n), nnz_rows, nonlinear
