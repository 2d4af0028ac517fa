"""The unprinted inputs of a paper, inferred jointly from its printed statements (issue 21).

A paper leaves inputs unprinted (Brown: how far out the comparator's stations stand, the
plate's closure sigma0 to more than two digits, the second station coordinate beta). Each such
input gets a *physically possible range* -- what the paper's own hardware allows (the 261 mm
scale, the plate format, the station layout) -- and the paper's printed statements constrain
them. This module finds the **consistent region**: the input vectors for which no printed
statement is contradicted.

Declaration (data, once per paper; :mod:`sim.claims.declaration`)
=================================================================
A TOML file with an ``[inputs]`` table (one sub-table per input: ``low``, ``high`` in the
unit its name ends with, ``why``: the hardware or text that bounds it) and a ``[statements]``
table (one sub-table per printed statement: ``paper`` (the words), ``source``, ``form``,
``ref``, ``decimals``, ``tol`` -- the forms and decision zones of :mod:`sim.claims.book`:
a printed number stands for its rounding, widened by ``tol``).

Method: space-filling design plus boundary refinement, acceptance at each printed rounding
=========================================================================================
The inputs are explored *jointly*, never one at a time: a scrambled Sobol design (a
low-discrepancy, space-filling sample) of ``n`` points over the box of possible ranges, then
``rounds`` refinement rounds that sample new points in boxes of half the previous spacing
around every point whose neighbourhood holds both accepted and rejected points (the region's
boundary). This is ABC-style acceptance with a zero-width kernel on each printed number's own
rounding interval: a point is *accepted* when, for every statement, the model's value (or
its Monte-Carlo interval) meets the statement's decision zone. We chose it over a likelihood
because the papers print rounded numbers and words ("about", "as large as"), not sampling
distributions: the rounding interval is the only error model the paper states, and
acceptance gives a region (what is possible), not a posterior (what is probable) that would
depend on a prior over hardware nobody printed.

Monte-Carlo noise is part of the decision. The model returns, per statement, either an exact
value (an analytic covariance: no noise; use it wherever the statement is about precision) or
an interval at the stated ``level`` (e.g. :func:`interval_from_se`), or for a one-plate
statistic the probability ``p`` of a plate at least as extreme. A statement is
*contradicted* at a point when its interval misses the zone wholly (for elements: some
element's interval does; one-plate: ``p < 1 - level``), *holds* when it lies inside the zone,
and is *undecided* otherwise. A point is in the region (``accepted``) when no statement is
contradicted, and ``confirmed`` when every statement holds. The per-point tests are not
corrected for multiplicity: the region is the set of inputs the evidence does not exclude at
``level``, read point by point.

The region's *resolution* is the design spacing per input: the Sobol spacing
``(high - low) n^(-1/d)`` in the interior and that halved per refinement round at the
boundary (a face of the box of possible ranges is resolved to the interior spacing,
a corner of the region more coarsely). When the region is empty, :attr:`Region.conflicts` names the statements that
conflict: each one contradicted alone (by every possible input), else a minimal set of
statements whose non-contradicted sets do not meet (found by deletion).
A conflicting statement that the study then reads as *not comparable* (the simulated
hardware is not the set-up that printed it) says nothing about the inputs:
:meth:`Region.without` sets it aside and gives what the other statements leave on the same
explored points.

Arrays in, arrays out: the model takes a dict ``{input name: (N,) array}`` and returns a dict
``{statement id: evidence}`` with a leading point axis. Verdicts of predictions over the
region: :mod:`sim.claims.region`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Callable, Mapping, Sequence

import numpy as np
from scipy import special
from scipy.spatial import cKDTree

from sim.claims.declaration import FORMS, Input, Statement, load_declaration, parse_declaration
from sim.claims.rules import MIN_PLATES
from sim.lsq.sobol import sobol_base2

__all__ = [
    "Input",
    "Statement",
    "Region",
    "load_declaration",
    "explore",
    "evaluate",
    "interval_from_se",
    "HOLDS",
    "FAILS",
    "UNDECIDED",
    "FORMS",
    "parse_declaration",
]

HOLDS, UNDECIDED, FAILS = 1, 0, -1


def interval_from_se(value, se, level: float = 0.95) -> dict[str, np.ndarray]:
    """Evidence for a Monte-Carlo estimate: ``value +- z se`` at two-sided ``level``."""
    v, s = np.asarray(value, float), np.asarray(se, float)
    z = special.ndtri(0.5 + level / 2)  # the normal quantile (scipy.stats.norm.ppf)
    return {"value": v, "low": v - z * s, "high": v + z * s}


def _evidence(sid: str, ev: Any, n: int):
    """(low, high, p, plates) with a leading point axis; low/high may carry an element axis;
    ``plates`` (or None) the simulated plates per point behind a spread and its ``p``."""
    plates = None
    if isinstance(ev, Mapping):
        v = np.asarray(ev["value"], float) if "value" in ev else None
        lo = np.asarray(ev.get("low", v), float)
        hi = np.asarray(ev.get("high", v), float)
        p = None if ev.get("p") is None else np.asarray(ev["p"], float)
        if ev.get("plates") is not None:
            plates = np.broadcast_to(np.asarray(ev["plates"]), (n,))
    else:
        lo = hi = np.asarray(ev, float)
        p = None
    if lo.shape[:1] != (n,) or hi.shape != lo.shape:
        raise ValueError(f"statement {sid}: evidence must have a leading axis of {n} points")
    return lo, hi, p, plates


def status(st: Statement, ev: Any, n: int, level: float = 0.95) -> np.ndarray:
    """Per point: HOLDS (interval inside the zone), FAILS (misses it wholly; for elements:
    some element does) or UNDECIDED. NaN evidence is UNDECIDED. With a one-plate ``p`` the
    fail test is ``p < 1 - level`` alone, replacing the interval's miss (the book's one-plate
    rule, :func:`sim.claims.rules.decide`): a spread wholly outside the zone is the raw p again
    and would undo any adjustment of ``p`` (the printed rounding, Holm's correction)."""
    lo, hi, p, plates = _evidence(st.id, ev, n)
    zl, zh = st.zone
    lo2, hi2 = lo.reshape(n, -1), hi.reshape(n, -1)
    nan = np.isnan(lo2).any(axis=1) | np.isnan(hi2).any(axis=1)
    inside = ((lo2 >= zl) & (hi2 <= zh)).all(axis=1)
    if p is None:
        miss = ((hi2 < zl) | (lo2 > zh)).any(axis=1)
    else:  # 1 - 0.95 is 0.05000000000000004 in binary: round so that p = 0.05 passes, as in the book
        miss = p < round(1 - level, 12)
    out = np.where(miss, FAILS, np.where(inside, HOLDS, UNDECIDED)).astype(np.int8)
    out[nan] = UNDECIDED
    if plates is not None:  # too few plates to decide (sim.claims.rules.MIN_PLATES)
        out[plates < MIN_PLATES] = UNDECIDED
    return out


def evaluate(
    statements: Sequence[Statement], model_out: Mapping[str, Any], n: int, level: float = 0.95
) -> np.ndarray:
    """The (n, S) status matrix of the statements at n points."""
    missing = [s.id for s in statements if s.id not in model_out]
    if missing:
        raise ValueError(f"the model gave no evidence for: {', '.join(missing)}")
    if not statements:
        return np.zeros((n, 0), np.int8)
    return np.stack([status(s, model_out[s.id], n, level) for s in statements], axis=1)


@dataclass
class Region:
    """The explored points and the consistent region among them.

    ``x``: every evaluated input vector (dict of (N,) arrays); ``status``: (N, S) per
    statement; ``accepted``: no statement contradicted; ``confirmed``: every statement holds;
    ``resolution``: per input the (interior, boundary) spacing; ``conflicts``: when nothing
    is accepted, the conflicting statement sets (ids); ``outputs``: the model's evidence at
    every point (for the predictions evaluated with the same model).
    """

    inputs: list[Input]
    statements: list[Statement]
    x: dict[str, np.ndarray]
    status: np.ndarray
    level: float
    resolution: dict[str, tuple[float, float]]
    outputs: dict[str, Any] = field(default_factory=dict)

    @property
    def n(self) -> int:
        return len(next(iter(self.x.values())))

    @property
    def accepted(self) -> np.ndarray:
        return (self.status != FAILS).all(axis=1)

    @property
    def confirmed(self) -> np.ndarray:
        return (self.status == HOLDS).all(axis=1)

    @property
    def empty(self) -> bool:
        return not self.accepted.any()

    def points(self, mask: np.ndarray | None = None) -> dict[str, np.ndarray]:
        """The accepted input vectors (or those of ``mask``), one array per input."""
        m = self.accepted if mask is None else mask
        return {k: v[m] for k, v in self.x.items()}

    def bounds(self, mask: np.ndarray | None = None) -> dict[str, tuple[float, float]]:
        """Per input, the projection [min, max] of the accepted points (or of ``mask``)."""
        m = self.accepted if mask is None else mask
        if not m.any():
            return {k: (math.nan, math.nan) for k in self.x}
        return {k: (float(v[m].min()), float(v[m].max())) for k, v in self.x.items()}

    def describe(self, mask: np.ndarray | None = None, digits: int = 3) -> str:
        """'offset_mm 12.5-30.1, sigma0_um 1.55-1.65' for the accepted points (or ``mask``)."""
        b = self.bounds(mask)
        if any(math.isnan(lo) for lo, _ in b.values()):
            return "nowhere"
        return ", ".join(
            f"{k} {_g(lo, digits)}" + ("" if lo == hi else f"-{_g(hi, digits)}")
            for k, (lo, hi) in b.items()
            if not self._fixed(k)
        )

    def without(self, ids: Sequence[str]) -> "Region":
        """The region the other statements leave when ``ids`` are set aside (a statement
        found not comparable, e.g. because it alone empties the region, says nothing about
        the simulated inputs): the same explored points, outputs and resolution."""
        keep = [j for j, s in enumerate(self.statements) if s.id not in set(ids)]
        return Region(
            self.inputs,
            [self.statements[j] for j in keep],
            self.x,
            self.status[:, keep],
            self.level,
            self.resolution,
            self.outputs,
        )

    def _fixed(self, name: str) -> bool:
        return any(i.name == name and i.low == i.high for i in self.inputs)

    @property
    def conflicts(self) -> list[tuple[str, ...]]:
        """Empty unless the region is: then each statement contradicted by every explored
        input alone, else one minimal set of statements that cannot hold together."""
        if not self.empty:
            return []
        ok = self.status != FAILS
        ids = [s.id for s in self.statements]
        alone = [(ids[j],) for j in range(len(ids)) if not ok[:, j].any()]
        if alone:
            return alone
        keep = list(range(len(ids)))
        for j in list(keep):  # deletion: drop every statement the conflict does not need
            trial = [k for k in keep if k != j]
            if trial and not ok[:, trial].all(axis=1).any():
                keep = trial
        return [tuple(ids[k] for k in keep)]


def _g(x: float, digits: int) -> str:
    return f"{x:.{digits}g}"


def _scale(inputs: Sequence[Input], u: np.ndarray) -> dict[str, np.ndarray]:
    return {i.name: i.low + (i.high - i.low) * u[:, k] for k, i in enumerate(inputs)}


def _boundary(u: np.ndarray, label: np.ndarray, radius: float) -> np.ndarray:
    """Points with a neighbour (within ``radius`` in the unit cube) of another label."""
    if (label == label[0]).all():
        return np.zeros(len(u), bool)
    tree = cKDTree(u)
    nb = tree.query_ball_point(u, r=radius)
    return np.array([(label[j] != label[j[0]]).any() for j in nb])


def explore(
    inputs: Sequence[Input],
    statements: Sequence[Statement],
    model: Callable[[dict[str, np.ndarray]], Mapping[str, Any]],
    rng: np.random.Generator,
    *,
    n: int = 1024,
    rounds: int = 3,
    per_point: int = 4,
    max_new: int = 4096,
    level: float = 0.95,
    refine_on: Sequence[Statement] = (),
) -> Region:
    """The consistent region of ``inputs`` under ``statements`` (see the module doc).

    ``model(x)`` takes ``{input name: (N,) array}`` and returns ``{statement id: evidence}``
    (exact (N,) or (N, m) values, or a dict with ``value``/``low``/``high``/``p``); it may
    return more keys (predictions), kept in :attr:`Region.outputs`. ``rng`` seeds the
    scrambled design and the refinement. Inputs with ``low == high`` are fixed.
    ``refine_on``: predictions (evaluated by the same model) whose holds/not-holds boundary
    inside the region is refined as well, so that "holds for a-b" is resolved like the region.
    """
    if n < 2 or rounds < 0 or per_point < 1 or not 0 < level < 1:
        raise ValueError("explore: need n >= 2, rounds >= 0, per_point >= 1, 0 < level < 1")
    inputs = list(inputs)
    free = [k for k, i in enumerate(inputs) if i.high > i.low]
    d = max(len(free), 1)
    m = int(math.ceil(math.log2(n)))
    u = np.full((2**m, len(inputs)), 0.5)
    if free:  # scipy.stats.qmc.Sobol's points, without importing scipy.stats
        u[:, free] = sobol_base2(len(free), m, rng)
    h0 = (2**m) ** (-1.0 / d)
    h = h0
    x = _scale(inputs, u)
    out = dict(model(x))
    st = evaluate(statements, out, len(u), level)
    for _ in range(rounds if free else 0):
        acc = (st != FAILS).all(axis=1)
        label = acc.astype(np.int64)
        for k, p in enumerate(refine_on):
            label += (2 << k) * (acc & (status(p, out[p.id], len(u), level) == HOLDS))
        edge = np.flatnonzero(_boundary(u[:, free], label, 1.5 * h * math.sqrt(d)))
        if edge.size == 0:
            break
        if edge.size * per_point > max_new:
            edge = rng.choice(edge, max_new // per_point, replace=False)
        h /= 2
        new = np.repeat(u[edge], per_point, axis=0)
        new[:, free] += rng.uniform(-h, h, size=(len(new), len(free)))
        new[:, free] = np.clip(new[:, free], 0.0, 1.0)
        xn = _scale(inputs, new)
        on = dict(model(xn))
        st = np.concatenate([st, evaluate(statements, on, len(new), level)])
        u = np.concatenate([u, new])
        out = _concat(out, on)
        x = {k: np.concatenate([x[k], xn[k]]) for k in x}
    res = {i.name: ((i.high - i.low) * h0, (i.high - i.low) * h) for i in inputs}
    return Region(inputs, list(statements), x, st, level, res, out)


def _concat(a: Mapping[str, Any], b: Mapping[str, Any]) -> dict[str, Any]:
    out = {}
    for k in a:
        if isinstance(a[k], Mapping):
            out[k] = {
                j: None if a[k][j] is None else np.concatenate([a[k][j], b[k][j]]) for j in a[k]
            }
        else:
            out[k] = np.concatenate([np.asarray(a[k]), np.asarray(b[k])])
    return out
