"""What one adjustment costs, measured, for the work estimate (:mod:`sim.mc.estimate`).

The unit (:data:`ADJUSTMENT_S` s of one core of the 2-core reference machine) is one
adjustment of the kind the Monte-Carlo parts solve; :func:`dense_units` weighs a dense
adjustment larger than the unit (m U^2 + U^3 against the unit's); brown_design's analytic
design grid is counted in adjustment-equivalents by a cost law fitted to serial timings
(:func:`design_grid_equivalents`, ~(2n)^3 a geometry, ~k^6 for a k x k grid), and
:func:`design_estimate` is brown_design's estimator (Brown 1968, seed ``004``). Sizes are in
points and unknowns, times in seconds, memory in bytes.
"""

from __future__ import annotations

import math
from typing import Any, Mapping

__all__ = [
    "ADJUSTMENT_S",
    "F8",
    "COPIES",
    "UNIT_WORK",
    "n_of",
    "grid_count",
    "max_of",
    "dense_units",
    "design_grid_equivalents",
    "design_chunk_bytes",
    "design_estimate",
    "design_bar_units",
    "DESIGN_UNITS",
    "affine_units",
    "chain_units",
]

F8 = 8.0  # bytes of a float64
COPIES = 6.0  # working copies of the largest array (residuals, Jacobian, ...)

#: CPU seconds of the unit adjustment on one core of the 2-core reference machine (one BLAS
#: thread, best of 5 rounds of 500 trials): a third of a trial of brown_design's Monte-Carlo
#: check on the paper's plate (P-position solver, 4 positions x 25 points, 57 unknowns),
#: counted as 3 adjustments. The default limit of 5e8 is then about 7 hours on one core.
ADJUSTMENT_S = 5.1e-5
#: points a region's boundary refinement adds at most each round
#: (``sim.claims.inference.explore``'s ``max_new``)
REGION_MAX_NEW = 4096


def region_points(c: Mapping, n_key: str = "region.points", rounds_key: str = "region.rounds"):
    """Input vectors a region evaluates at most: its Sobol design and, each refinement round,
    up to :data:`REGION_MAX_NEW` more at its boundaries."""
    return c.get(n_key, 0) + REGION_MAX_NEW * c.get(rounds_key, 0)


def grid_count(span: float, step: float) -> float:
    """Nodes of a grid of ``step`` over ``span`` (infinite for a step of 0 or less)."""
    return math.floor(abs(span) / step) + 1 if step > 0 else math.inf


def n_of(v: Any) -> float:
    try:
        return float(len(v)) if isinstance(v, (list, tuple)) else float(v)
    except (TypeError, ValueError):
        return 0.0


def max_of(v, default=0.0) -> float:
    return max((float(x) for x in v), default=default) if isinstance(v, (list, tuple)) else default


#: the unit adjustment's dense work: normal equations m U^2 and their factor U^3 of its 100
#: ranges and 57 unknowns (:data:`ADJUSTMENT_S`)
UNIT_WORK = 100.0 * 57**2 + 57.0**3


def dense_units(m: float, U: float) -> float:
    """Unit adjustments one dense adjustment of ``m`` observations and ``U`` unknowns costs
    (m U^2 + U^3 against :data:`UNIT_WORK`), at least 1: an adjustment no larger than the
    unit counts as one, as every adjustment did before; a larger one in proportion (Wolf's
    polynomial fit at 1 mm spacing and degree 8: 1,900 units by this model, 1,200 measured
    from a run's CPU time)."""
    return max(1.0, (m * U * U + U**3) / UNIT_WORK)


#: float64 values a brown_design Monte-Carlo chunk holds per range of a trial (measured with
#: tracemalloc: about 30-100 for the P-position solver and 50-100 for the 4-station one)
DESIGN_RANGE_VALUES = 128
#: copies of the (geometries, 2n, 2n) cofactor stack the analytic design grid holds at its
#: peak (measured: 4.07 x for grids of 10 and 15 points per side, any number of positions)
DESIGN_COFACTOR_COPIES = 5.0


#: CPU seconds of one geometry of the analytic design grid (both models' (2n, 2n) cofactors in
#: the inner datum, :func:`sim.studies.design.cells.geometry_eval`) of n points: a (2n)^3 +
#: b (2n)^2, fitted (relative least squares) to serial timings on the reference machine at
#: k = 10, 14, 18, 22, 26 and 29 points a side, 3, 4 and 8 positions (the same within 2 %),
#: the study's 8 offsets x 2 betas; every timing within 9 % of the law. From 10 to 29 points
#: a side the time grows as k^5.45 (k^6.03 from 18 on: the cube dominates); 29 x 29 takes
#: 0.60-0.65 s a geometry, about 2 minutes for the study's 4 positions x 3 extents.
DESIGN_CUBE_S = 1.11e-10
DESIGN_SQUARE_S = 2.41e-8


def design_grid_equivalents(
    grids, positions: float = 1, extents: float = 1, geometries: float = 1
) -> float:
    """Adjustment-equivalents (:data:`ADJUSTMENT_S` s each) of brown_design's analytic design
    grid: every grid of ``grids`` (points per side) for each of ``positions`` x ``extents``,
    ``geometries`` (offsets x betas) batched, at :data:`DESIGN_CUBE_S` (2n)^3 +
    :data:`DESIGN_SQUARE_S` (2n)^2 seconds a geometry, n = k^2."""
    per = sum(
        DESIGN_CUBE_S * (2.0 * k * k) ** 3 + DESIGN_SQUARE_S * (2.0 * k * k) ** 2 for k in grids
    )
    return positions * extents * geometries * per / ADJUSTMENT_S


#: unit adjustments of one walker's step of one chain, both posteriors (Brown's 7 globals
#: and the two plates' twice as many steps of a cheaper posterior) together: measured, one
#: core, 32 walkers x 5,000 steps x 4 chains, 20 s each. Counted as 2 a walker's step
#: without the chains, the posteriors' time was 2.5 times the estimate at 4 chains and 40
#: times at the 64 the schema allows
BAYES_UNITS = 1.25
#: bytes the posteriors hold a walker's step of a chain (every chain's samples kept, one
#: chain's whole run with its autocorrelation's copies; measured 316 for Brown's and 514 at
#: the two plates' peak, 32 walkers x 5,000 steps x 4 chains). Not counted, ``bayes.steps =
#: 1e6`` passed ``sim check`` at 49 MiB for a run of about 60 GiB
BAYES_BYTES = 600.0


#: brown_design's error-budget rows (sim.studies.design.errbudget.BUDGET_ROWS), each an
#: adaptive run of up to budget.max_trials, and its emcee posteriors (Brown's, the two
#: plates' flat and certificate), each bayes.chains chunks of one chain
DESIGN_BUDGET_ROWS = 11
DESIGN_POSTERIORS = 3

#: unit adjustments a trial of brown_design's Monte-Carlo parts costs, for its progress bar
#: (measured, one core, chunks of 20): the check and an error-budget row solve the paper's
#: plate (3.0 to 3.4), a coverage case Brown's 4 stations (1.1 to 3.2; 6 at 10 mm of noise);
#: the shares of :data:`BAYES_UNITS` of a chain of Brown's posterior and of each two-plate
#: one (0.45 and 0.18 a walker's step measured: 5,713 and 2,300 units a chain of 32 x 400; at
#: 32 x 2,000, 0.65 and 0.37: the two-plate share raised to 0.32, 0.575 of Brown's, as there)
DESIGN_UNITS = {"check": 3.0, "budget": 3.0, "coverage": 2.0, "brown": 0.55, "twoplate": 0.32}
#: an affine coverage trial (a linear fit of the grid's points) costs little beside its
#: chunk's: measured, one core, the study's 4,000 + 1,000 trials (25 and 4 points) at 6.0
#: units a trial in chunks of 20 and 0.39 in chunks of 500 (the study's). Counted 28 and 7 a
#: trial whatever the chunk, the coverage's 294,000 units stood for about 2,000: the bar's time
#: left was 2.8 times the real one at 90 % of a run
AFFINE_TRIAL_UNITS, AFFINE_CHUNK_UNITS = 0.16, 117.0


def affine_units(chunk: float) -> float:
    """Unit adjustments of one affine coverage trial in chunks of ``chunk`` trials."""
    return AFFINE_TRIAL_UNITS + AFFINE_CHUNK_UNITS / max(chunk, 1)


def chain_units(walkers: float, steps: float, posterior: str) -> float:
    """Unit adjustments of one chain (one trial on the bar) of ``posterior`` (``brown``,
    ``twoplate``) of ``walkers`` x ``steps`` (Brown's steps; the two plates run twice as
    many of a cheaper posterior)."""
    return BAYES_UNITS * walkers * steps * DESIGN_UNITS[posterior]


def design_bar_units(c: Mapping) -> float:
    """The unit adjustments of the trials brown_design's bar counts (each part's trials at
    its :data:`DESIGN_UNITS`): 1,343 to 2,476 hours were left on a bar that counted a chain
    of 18 s as one trial among 274,012 of a millisecond."""
    u = DESIGN_UNITS
    cov = c.get("coverage.trials", 0)
    sweep = c.get("coverage.sweep_trials", 0)
    cases = n_of(c.get("coverage.noise_um", []))
    cases += n_of(c.get("coverage.grids", [])) + n_of(c.get("coverage.betas_mm", []))
    chains = c.get("bayes.chains", 0)
    walker_steps = c.get("bayes.walkers", 0) * c.get("bayes.steps", 0)
    return (
        c["trials"] * u["check"]
        + DESIGN_BUDGET_ROWS * c.get("budget.max_trials", 0) * u["budget"]
        + (cov + sweep * cases) * u["coverage"]
        + cov * affine_units(min(c["chunk"], cov or 1))
        + sweep * affine_units(min(c["chunk"], sweep or 1))
        + chains * BAYES_UNITS * walker_steps * (u["brown"] + 2 * u["twoplate"])
    )


def design_chunk_bytes(ch: float, P: float, n: float) -> float:
    """Bytes of one Monte-Carlo chunk of ``ch`` trials of ``n`` points seen from ``P``
    positions: the per-range arrays of every trial, and the (2n, 2n) inner-datum matrix and
    its product, once per chunk."""
    return ch * P * n * DESIGN_RANGE_VALUES * F8 + 2 * (2 * n) ** 2 * F8


def design_estimate(c: Mapping) -> tuple:
    """brown_design, each part with its own geometry: the Monte-Carlo check, the error budget
    and the posterior on the paper's plate (``paper.positions`` x ``paper.grid``), the
    coverage on 4 stations over ``coverage.grids`` and ``datum.grid``; the design grid
    (``design.*``) is analytic, one (geometries, 2n, 2n) cofactor stack per grid, the
    geometries its offsets x betas, not a chunk of trials."""
    lists = [
        c.get(f"design.{k}", [1])
        for k in (
            "positions",
            "offsets_mm",
            "grids",
            "extents_mm",
            "settings",
            "setting_sigma_um",
            "beta_mm",
        )
    ]
    cells = math.prod(max(len(v), 1) for v in lists)
    G = max_of(c.get("design.grids"), 5)
    n = G * G
    U = 2 * n + 7
    T, ch = c["trials"], min(c["chunk"], c["trials"])
    cov_T = c.get("coverage.trials", 0)
    sw_T = c.get("coverage.sweep_trials", 0) * (
        n_of(c.get("coverage.noise_um", []))
        + n_of(c.get("coverage.grids", []))
        + n_of(c.get("coverage.betas_mm", []))
    )
    # every budget row up to budget.max_trials at its unit, as the trials count them (6 rows of
    # one unit were counted: a run of up to 33 units a trial of max_trials was 5.5 times over)
    budget = DESIGN_BUDGET_ROWS * c.get("budget.max_trials", 0) * DESIGN_UNITS["budget"]
    walker_steps = c.get("bayes.walkers", 0) * c.get("bayes.steps", 0) * c.get("bayes.chains", 0)
    bayes = BAYES_UNITS * walker_steps
    # the trials the run's bar counts, at most: every budget row up to budget.max_trials, the
    # affine coverage case (coverage.trials and a sweep's), each posterior's chains (one chunk
    # a chain); 6 rows and no chains were counted and the bar passed its total with chunks to
    # come (an interrupt said every chunk was done: sim.mc.runner.RunContext.all_counted)
    posteriors = DESIGN_POSTERIORS * c.get("bayes.chains", 0)
    affine = cov_T + c.get("coverage.sweep_trials", 0)
    trials = T + cov_T + sw_T + DESIGN_BUDGET_ROWS * c.get("budget.max_trials", 0)
    trials += affine + posteriors
    adj = cells * 3 + T * 3 + cov_T * 2 + sw_T * 2 + budget + bayes
    n_paper = c.get("paper.grid", 5) ** 2
    nc = max(max_of(c.get("coverage.grids"), 5) ** 2, c.get("datum.grid", 5) ** 2)
    geometries = n_of(c.get("design.offsets_mm", [1])) * n_of(c.get("design.beta_mm", [1]))
    grids = [float(k) for k in c.get("design.grids", [5])]
    PE = n_of(c.get("design.positions", [1])) * n_of(c.get("design.extents_mm", [1]))
    eq = design_grid_equivalents(grids, PE, 1, geometries)
    adj += eq
    # the regions (measured, one core): the tolerance region 0.19 ms an input vector (9.5 s
    # for 16,384 points and 8 rounds, 49,152 vectors); the plate region 0.25 us a plate at each
    # of region.plate_points vectors (102 s for 1,024 x 400,000 plates) and 0.5 ms a vector
    adj += 3.8 * region_points(c) + c.get("region.plate_points", 0) * (
        10.0 + 4.9e-3 * c.get("unprinted.plates", 0)
    )
    analytic = (
        eq,
        "design.grids",
        f"the analytic design grid ({len(grids)} grids up to {int(G)} x {int(G)} points, each "
        f"for {int(PE)} positions x extents and {int(geometries)} offset x beta geometries)",
    )
    cov_key = "coverage.grids" if max_of(c.get("coverage.grids"), 5) ** 2 >= nc else "datum.grid"
    # each part's memory with the keys that set it (the refusal's advice: it said "chunk,
    # trials or the sizes in the study file" of a run whose chains were the cost)
    parts = {
        "the Monte-Carlo check on the paper's plate": (
            design_chunk_bytes(ch, c.get("paper.positions", 4), n_paper),
            ("chunk", "paper.grid", "paper.positions"),
        ),
        "the coverage": (design_chunk_bytes(ch, 4, nc), ("chunk", cov_key)),
        f"the analytic design grid ({int(geometries)} offset x beta geometries of {int(G)} x "
        f"{int(G)} points)": (
            DESIGN_COFACTOR_COPIES * geometries * (2 * n) ** 2 * F8,
            ("design.grids", "design.offsets_mm", "design.beta_mm"),
        ),
        # measured: 211 MB more for 100,000 plates at a vector, all of them held at once
        "the plate region (unprinted.plates plates at once)": (
            2.2e3 * c.get("unprinted.plates", 0),
            ("unprinted.plates",),
        ),
        "the posteriors' chains (bayes.walkers x bayes.steps x bayes.chains)": (
            BAYES_BYTES * walker_steps,
            ("bayes.steps", "bayes.walkers", "bayes.chains"),
        ),
    }
    what = max(parts, key=lambda k: parts[k][0])
    U = max(U, 2 * int(max(nc, n_paper)) + 7)
    nbytes, keys = parts[what]
    return trials, adj, U, nbytes, what, analytic, keys, design_bar_units(c)
