"""agnard_block's size for the work and memory estimate (:mod:`sim.mc.estimate`).

A block adjustment's reduced normals are 7 x 7 blocks of its models coupled to a few
neighbours: its work grows with the models (:data:`AGNARD_MODEL_UNITS` a model) and, through
the image observations it forms and the points it eliminates, with the ground and pass
points (:data:`AGNARD_POINT_UNITS` a ground point); a snooped one faster than its models
(:data:`AGNARD_CUBE_UNITS`). Sizes in models and points, work in unit
adjustments, memory in bytes; see :func:`agnard_estimate`.
"""

from __future__ import annotations

from typing import Mapping

from sim.mc.workunits import COPIES, F8, REGION_MAX_NEW, grid_count, region_points
from sim.mc.workunits import n_of as _n

__all__ = [
    "agnard_estimate",
    "agnard_units",
    "AGNARD_MODEL_UNITS",
    "AGNARD_POINT_UNITS",
    "AGNARD_CUBE_UNITS",
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
    w = AGNARD_MODEL_UNITS * M
    p = AGNARD_POINT_UNITS * max(c.get("block.ground_points", 178) - AGNARD_PAPER_POINTS, 0)
    solve = snoop * (w + AGNARD_CUBE_UNITS * M**3) + p  # a snooped block solve
    return {
        "main": (3 + _n(c.get("tradeoff.layouts", []))) * solve,
        "scanner": 2 * solve,
        "recentre": solve,
        "size": lambda S, Mo: 2 * S * Mo * (AGNARD_MODEL_UNITS + p / max(M, 1)),
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
    w, wt = AGNARD_MODEL_UNITS * M, AGNARD_MODEL_UNITS * Mt  # unit adjustments a block solve
    ws = w + AGNARD_CUBE_UNITS * M**3  # a snooped one
    # and its ground points beyond the paper's (the model units were measured with them)
    p = AGNARD_POINT_UNITS * max(c.get("block.ground_points", 178) - AGNARD_PAPER_POINTS, 0)
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
    return trials, adj, int(max(U, Ut)), b, "", (0.0, "", ""), (), work
