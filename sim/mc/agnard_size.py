"""agnard_block's size for the work and memory estimate (:mod:`sim.mc.estimate`).

A block adjustment's reduced normals are 7 x 7 blocks of its models coupled to a few
neighbours: its work grows with the models (:data:`AGNARD_MODEL_UNITS` a model) and, through
the image observations it forms and the points it eliminates, with the ground and pass
points (:data:`AGNARD_POINT_UNITS` a ground point); a snooped one faster than its models
(:data:`AGNARD_CUBE_UNITS`). These were measured on the paper's geometry (a base of 90 mm on
the 230 mm format, four pass rows a strip); a point seen by more models (a shorter base, more
pass rows, a wider sidelap or usable area) costs more: every solve is weighed by the block's
model observations over those of the paper's geometry at its size (:func:`geometry_factor`).
Sizes in models and points, work in unit adjustments, memory in bytes; see
:func:`agnard_estimate`.
"""

from __future__ import annotations

import math
from collections import Counter
from typing import Mapping

from sim.mc.workunits import COPIES, F8, REGION_MAX_NEW, grid_count, region_points
from sim.mc.workunits import n_of as _n

__all__ = [
    "agnard_estimate",
    "agnard_units",
    "AGNARD_MODEL_UNITS",
    "AGNARD_POINT_UNITS",
    "AGNARD_CUBE_UNITS",
    "geometry_factor",
    "geometry_keys",
    "model_observations",
]

#: unit adjustments one block adjustment costs per model of the block (its reduced normals are
#: 7 x 7 blocks coupled to a few neighbours: the work grows with the models). Measured from
#: tiny runs' CPU time (20 trials, 3,800 counted adjustments): 2 x 8 models 43 units an
#: adjustment, 4 x 25 models 350 (8x the time for 6x the models, the same count before)
AGNARD_MODEL_UNITS = 3.5
#: unit adjustments a ground point more than the paper's adds to each of a trial's layout
#: adjustments, its snooping included (measured, one core, the 2 x 8 block's main chunk: 0.10
#: s a trial at 178 ground points, 1.3 s at 20,000, 9.1 s at 100,000). Counted by the models alone, 100,000
#: ground points were estimated 17 times under their time: the study's 500 trials, 76
#: minutes of the main part alone, passed as 4 minutes
AGNARD_POINT_UNITS = 0.25
#: block solves (:data:`AGNARD_MODEL_UNITS` a model, and the ground points') one scanner
#: vector of the Table 1 region costs a trial (its 21- and 5-control layouts, snooped on
#: the configured scanner's blocks; measured, one core, the 2 x 8 block: 31 ms a vector and
#: trial, 20 trials x 16 vectors). Not counted, ``table1.trials = 10000`` and
#: ``table1.points = 256`` passed ``sim check`` with the estimate of the defaults
AGNARD_VECTOR_SOLVES = 11.0
#: the paper's ground points, with which :data:`AGNARD_MODEL_UNITS` was measured
AGNARD_PAPER_POINTS = 178
#: unit adjustments a snooped block adjustment costs per model cubed: the work of a trial of
#: the main chunk grows faster than its models (measured, one core, 2,000 ground points: 2 x
#: 8 models 3,800 units a trial, 4 x 25 75,000, 6 x 30 405,000; counted by the models alone,
#: the 6 x 30 block was 3.3 times its estimate and a 12 x 60 one about 60 times)
AGNARD_CUBE_UNITS = 3.7e-4

#: the power of the observations ratio a block solve's work grows with, a pass point's
#: observation counted :data:`AGNARD_TIE_WEIGHT` of a signalised point's (measured, one core,
#: the 2 x 8 block's main trial with snooping: 0.082 s at the paper's 431 model observations,
#: 251 of them of signalised points; 0.27 s at 1,104 (base 45 mm), 0.16 s at 1,083 (20 pass
#: rows), 0.76 s at 2,571 (base 10 mm), 1.24 s at 4,475 (base 10 mm, 10 rows), 1.9 s at 7,739
#: (base 10 mm, 20 rows): the weighed ratio to the power 1.2 is within 0.85 and 1.18 of each.
#: Counted by the models alone, the tiny run at ``block.base_mm = 10`` took 49-61 s of CPU
#: where ``sim check`` said 6.5 s)
AGNARD_OBS_POWER = 1.2
#: a pass point's model observation in the work, as a share of a signalised point's
AGNARD_TIE_WEIGHT = 0.5
#: the paper's geometry, at which the units above were measured (base and format in mm)
PAPER_GEOMETRY = {"base": 90.0, "format": 230.0, "usable": 0.92, "sidelap": 0.3, "rows": 4}


def _seen(x: float, step: float, w: float, n: int, span: int) -> int:
    """Models (``span = 1``: photos ``m`` and ``m + 1``) or strips (``span = 0``) of ``n``,
    ``step`` apart, that see a point at ``x``: each photo's centre within ``w`` of it."""
    lo = max(math.ceil((x - w) / step - 1e-9), 0)
    hi = min(math.floor((x + w) / step - span + 1e-9), n - 1)
    return max(hi - lo + 1, 0)


def model_observations(c: Mapping, tie_weight: float = 1.0, **geometry) -> float:
    """A block's model observations (a model seeing a point, as
    :func:`sim.instruments.block.layout.make_block` lays them out, relief left out): the
    signalised points spread evenly over the block, each seen by the models along its strip
    times the strips across, and the pass points kept where two models or more see them.
    ``geometry`` (``base``, ``format``, ``usable``, ``sidelap``, ``rows``) overrides the
    config's; the pass points' observations are counted ``tie_weight`` each."""
    S, M = c.get("block.strips", 2), c.get("block.models", 8)
    B = geometry.get("base", c.get("block.base_mm", 90.0))
    fmt = geometry.get("format", c.get("block.format_mm", 230.0))
    w = 0.5 * fmt * geometry.get("usable", c.get("block.usable", 0.92))
    D = fmt * (1.0 - geometry.get("sidelap", c.get("block.sidelap", 0.3)))
    rows = geometry.get("rows", c.get("block.pass_rows", 4))
    n = 2000  # samples of the block's extent, along and across
    x0, x1, y1 = B - w, (M - 1) * B + w, (S - 1) * D + w
    along = sum(_seen(x0 + (x1 - x0) * (i + 0.5) / n, B, w, M, 1) for i in range(n)) / n
    across = sum(_seen(-w + (y1 + w) * (i + 0.5) / n, D, w, S, 0) for i in range(n)) / n
    cols = Counter(_seen(k * B / 2, B, w, M, 1) for k in range(2 * M + 1))
    lines = Counter(
        _seen(s * D + 0.85 * w * (2 * r / (rows - 1) - 1), D, w, S, 0)
        for s in range(S)
        for r in range(rows)
    )
    tie = sum(a * b * na * nb for a, na in cols.items() for b, nb in lines.items() if a * b >= 2)
    return c.get("block.ground_points", 178) * along * across + tie_weight * tie


def geometry_factor(c: Mapping) -> float:
    """The work of a block solve over that of the paper's geometry at the block's size (its
    strips, models and ground points): its model observations (a pass point's weighed
    :data:`AGNARD_TIE_WEIGHT`) over those of the paper's geometry (:data:`PAPER_GEOMETRY`), to
    the power :data:`AGNARD_OBS_POWER`; 1 at the paper's geometry (the committed studies'
    estimate is unchanged) and never below (a geometry of fewer observations, measured at
    none, keeps the paper's work: the models' share of it remains)."""
    ref = model_observations(c, AGNARD_TIE_WEIGHT, **PAPER_GEOMETRY)
    k = model_observations(c, AGNARD_TIE_WEIGHT)
    return max((k / ref) ** AGNARD_OBS_POWER, 1.0) if ref > 0 else 1.0


#: the keys of :data:`PAPER_GEOMETRY`, as a refusal over the work limit names them
GEOMETRY_KEYS = {
    "base": "block.base_mm",
    "rows": "block.pass_rows",
    "sidelap": "block.sidelap",
    "usable": "block.usable",
    "format": "block.format_mm",
}


def geometry_keys(c: Mapping) -> tuple:
    """The geometry keys off the paper's (:data:`PAPER_GEOMETRY`) when they make a block solve
    more than half as costly again (:func:`geometry_factor` over 1.5), for the refusal of a run
    over the work limit; else ``()``."""
    if not geometry_factor(c) > 1.5:
        return ()
    return tuple(
        key
        for g, key in GEOMETRY_KEYS.items()
        if c.get(key, PAPER_GEOMETRY[g]) != PAPER_GEOMETRY[g]
    )


def agnard_units(c: Mapping) -> dict:
    """A trial's unit adjustments in each part, as the run's bar counts them (the estimate's
    block solves, :func:`agnard_estimate`): ``main``, ``scanner`` (a resolution's), ``recentre``,
    ``size`` (``(strips, models)`` to its trial's), ``region`` (the five-point layouts') and
    ``table1`` (``n`` scanner vectors to a trial's, the configured scanner's blocks with them).
    Counted one a trial, a trial of the main blocks (10,468 units at the defaults) weighed as
    one of the region's (1,792) or of a block of 8 models (112): the bar's time left was the
    trials left over the main part's slow rate of trials."""
    M = c.get("block.strips", 2) * c.get("block.models", 8)
    snoop = 1 + c.get("snoop.max_reject", 0)
    g = geometry_factor(c)  # the models that see each point, over the paper's geometry's
    w = AGNARD_MODEL_UNITS * M * g
    p = AGNARD_POINT_UNITS * max(c.get("block.ground_points", 178) - AGNARD_PAPER_POINTS, 0) * g
    solve = snoop * (w + AGNARD_CUBE_UNITS * M**3) + p  # a snooped block solve
    return {
        "main": (3 + _n(c.get("tradeoff.layouts", []))) * solve,
        "scanner": 2 * solve,
        "recentre": solve,
        "size": lambda S, Mo: 2 * S * Mo * (AGNARD_MODEL_UNITS * g + p / max(M, 1)),
        "region": c.get("region.points", 0) * 2 * (w + p),
        "table1": lambda n: (n + 1) * AGNARD_VECTOR_SOLVES * (w + p),
    }


def agnard_estimate(c: Mapping) -> tuple:
    """agnard_block's ``(trials, adjustments, unknowns, bytes)``: every part's block solves
    (the main chunk's layouts with snooping, the scanner and re-centring trade-offs, the block
    sizes, the swept layout, the region), each :data:`AGNARD_MODEL_UNITS` a model with the
    snooping's maximum of re-adjustments (a snooped one :data:`AGNARD_CUBE_UNITS` a model
    cubed more), and :data:`AGNARD_POINT_UNITS` a ground point beyond the paper's once; the
    memory the reduced normals, the scan grid and the image observations of a chunk."""
    T, ch = c["trials"], min(c["chunk"], c["trials"])
    M = c.get("block.strips", 2) * c.get("block.models", 8)
    pts = c.get("block.ground_points", 178) + M * c.get("block.pass_rows", 4) * 3
    U = 7 * M + 3 * pts
    fmt, g = c.get("block.format_mm", 230.0), c.get("scan.grid_mm", 10.0)
    scan_nodes = grid_count(fmt, g) ** 2
    sizes = list(zip(c.get("tradeoff.block_strips", []), c.get("tradeoff.block_models", [])))
    Mt = max([S * Mo for S, Mo in sizes] + [M])
    pts_t = pts * Mt / max(M, 1)
    Ut = 7 * Mt + 3 * pts_t
    layouts = _n(c.get("tradeoff.layouts", []))
    tT, bT = c.get("tradeoff.trials", 0), c.get("tradeoff.block_trials", 0)
    dp, rc = _n(c.get("tradeoff.dpis", [])), _n(c.get("tradeoff.recentre_px", []))
    sT, s_cells = c.get("sweep.trials", 0), _n(c.get("sweep.five_inset", []))  # swept layout
    # the regions' runs on the bar: the five-point one's region.trials blocks once (its half
    # with the projection centres reuses them), the scanner region's table1.trials blocks its
    # design and each round: uncounted, the bar of the tiny run was "full" at 10 of its 48
    # trials and an interrupt said every chunk was done (sim.mc.runner.RunContext.all_counted)
    t1T, t1_rounds = c.get("table1.trials", 0), c.get("table1.rounds", 0)
    regions_T = c.get("region.trials", 0) + t1T * (1 + t1_rounds)
    trials = T + tT * (dp + rc) + bT * len(sizes) + sT * s_cells + regions_T
    snoop = 1 + c.get("snoop.max_reject", 0)
    g = geometry_factor(c)  # the models that see each point, over the paper's geometry's
    w, wt = AGNARD_MODEL_UNITS * M * g, AGNARD_MODEL_UNITS * Mt * g  # units a block solve
    ws = w + AGNARD_CUBE_UNITS * M**3  # a snooped one
    # and its ground points beyond the paper's (the model units were measured with them)
    p = AGNARD_POINT_UNITS * max(c.get("block.ground_points", 178) - AGNARD_PAPER_POINTS, 0) * g
    pt = p * Mt / max(M, 1)
    # the region: region.trials blocks adjusted once per layout of region.points, without
    # and with the projection centres, snooping rejecting few points (measured, one core, on
    # the 2 x 8 block: 4.3-4.9 ms a block and layout, 46.6 s for 16 x 600, about 95 units
    # against 2 w = 112; counted with the snooping's maximum, it was 30 times high)
    rT, r_pts = c.get("region.trials", 0), c.get("region.points", 0)
    adj = (
        T * (3 + layouts) * (snoop * ws + p)
        + tT * (2 * dp + rc) * (snoop * ws + p)
        + bT * len(sizes) * 2 * (wt + pt)
        + sT * s_cells * 3 * (snoop * ws + p)
        + rT * r_pts * 2 * (w + p)
        + t1T
        * (region_points(c, "table1.points", "table1.rounds") + 1)
        * AGNARD_VECTOR_SOLVES
        * (w + p)
    )
    # reduced normal equations of the models (7 x 7 blocks coupled through the points); the
    # block-size trade-off bounds its chunk by the pair blocks (4e6 floats)
    npair = Mt * 40.0
    ch_t = max(1.0, min(ch, bT or 1, 4e6 // (49 * npair)))
    b = max(
        COPIES * max(ch * (7 * M) ** 2 * F8, ch * scan_nodes * 2 * F8, ch * pts * M * 6 * F8),
        2 * (ch_t * (7 * Mt) ** 2 * F8 + 4e6 * F8),
    )
    # the bar: each part's trials at its units; the resolution and the re-centring error the
    # main blocks already have are not run (their trials were counted, and the bar ended short)
    u = agnard_units(c)
    own_dp = c.get("scan.dpi") in c.get("tradeoff.dpis", []) and c.get("control.table1") == c.get(
        "control.many"
    )
    own_rc = c.get("pugging.recentre_px") in c.get("tradeoff.recentre_px", [])
    trials -= tT * (own_dp + own_rc)
    work = (
        T * u["main"]
        + tT * ((dp - own_dp) * u["scanner"] + (rc - own_rc) * u["recentre"])
        + bT * sum(u["size"](S, Mo) for S, Mo in sizes)
        + sT * s_cells * 3 * (snoop * ws + p)
        + rT * u["region"]
        + t1T * (u["table1"](c.get("table1.points", 0)) + t1_rounds * u["table1"](REGION_MAX_NEW))
    )
    # the part that outweighs the rest named by its keys when the geometry is the paper's
    # (the region's 64 layouts of 1e6 blocks were told to "reduce trials or the lists in the
    # study file"); a costlier geometry makes every part costly, and is named alone
    region = rT * r_pts * 2 * (w + p)
    t1 = adj - region - T * (3 + layouts) * (snoop * ws + p)
    t1 -= tT * (2 * dp + rc) * (snoop * ws + p) + bT * len(sizes) * 2 * (wt + pt)
    t1 -= sT * s_cells * 3 * (snoop * ws + p)
    part = ()
    if region > adj / 2:
        part = ("region.points", "region.trials")
    elif t1 > adj / 2:
        part = ("table1.points", "table1.rounds", "table1.trials")
    return trials, adj, int(max(U, Ut)), b, "", (0.0, "", ""), (), work, geometry_keys(c) or part
