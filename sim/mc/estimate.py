"""Work and memory a study file asks for, estimated before the run.

From the resolved configuration alone (no model code runs): the Monte-Carlo trials over all
parts of a study (the progress bar's total), the number of least-squares adjustments, the
unknowns of the largest adjustment and the bytes of the largest working set one chunk needs
(times the workers that hold a chunk at once). One estimator per study kind; each is an
order-of-magnitude model of the study's arrays (observations x unknowns x trials in a chunk,
with a safety factor for copies), meant to stop a run that would hang or be killed for want
of memory, not to predict its time.

The work is counted in adjustments. The unit, :data:`ADJUSTMENT_S` seconds of one core of the
2-core reference machine, is one adjustment of the kind the Monte-Carlo parts solve (a third of
a trial of brown_design's check on the paper's plate, 57 unknowns). A part whose one step costs
far more than that unit is counted in adjustment-equivalents (its measured seconds over
:data:`ADJUSTMENT_S`): brown_design's analytic design grid, whose cofactor of an n-point grid
costs ~(2n)^3 per geometry (~k^6 for a k x k grid, :func:`design_grid_equivalents`); a dense
adjustment larger than the unit (Wolf's polynomial fit, the network's dense path) as m U^2 +
U^3 against the unit's (:func:`sim.mc.workunits.dense_units`); an Agnard block adjustment per model of its block
(:data:`sim.mc.agnard_size.AGNARD_MODEL_UNITS`, with its points). Each was measured on the reference machine. Such an
analytic part runs before the first progress bar and cannot be resumed, so it may take at most
:data:`ANALYTIC_SHARE` of the work limit (by default about 25 s on one core); over that the
run stops naming the key that sets its size (``design.grids``) and its minutes.

Limits: ``--max-memory-gb`` (env ``SIM_MAX_MEMORY_GB``, default 8 GiB: a third of a 24 GiB
machine) and ``--max-adjustments`` (env ``SIM_MAX_ADJUSTMENTS``, default 5e8: hours on two
cores). A run over a limit stops at once with the estimate in the message (exit 2). Sweeps are
bounded too: at most :data:`MAX_CELLS` cells times replicates.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from numbers import Integral
from typing import Any, Callable, Container, Mapping

from sim.mc.agnard_size import agnard_estimate as _agnard
from sim.mc.brown_size import brown_estimate as _brown
from sim.mc.config import ConfigError
from sim.mc.gridplate_size import gridplate_estimate as _gridplate
from sim.mc.memory_limit import DEFAULT_MAX_MEMORY_GB
from sim.mc.memory_limit import limit_value as _limit
from sim.mc.network_size import network_estimate as _network
from sim.mc.salsig_size import salsig_estimate as _salsig
from sim.mc.sweep import MAX_CELLS, cell_values, expand
from sim.mc.toml_text import toml_value
from sim.mc.workunits import (
    ADJUSTMENT_S,
    COPIES,
    F8,
    design_grid_equivalents,
    grid_count,
)
from sim.mc.workunits import dense_units as _dense
from sim.mc.workunits import design_estimate as _design
from sim.mc.workunits import max_of as _max
from sim.mc.workunits import n_of as _n

__all__ = [
    "Estimate",
    "estimate",
    "check_limits",
    "MAX_CELLS",
    "DEFAULT_MAX_MEMORY_GB",
    "DEFAULT_MAX_ADJUSTMENTS",
    "ADJUSTMENT_S",
    "ANALYTIC_SHARE",
    "CHUNK_UNITS",
    "CELL_UNITS",
    "CHUNK_NOTE_S",
    "chunk_note",
    "design_grid_equivalents",
]

#: unit adjustments a chunk costs besides its trials (its streams, tables and its file
#: written and read back): 6 ms of CPU, measured on a 13-unknown network in chunks of 1
#: against chunks of 100 (2,000 trials). 100,000 chunks of one trial are about ten minutes,
#: which a count of trials alone took for five seconds
CHUNK_UNITS = 100.0
#: unit adjustments a sweep cell costs besides its trials (its config, claims, tables and
#: README): about 0.8 s of CPU, measured on network_plate at 40 trials in chunks of 2, one
#: cell against eight (0.96 s a cell on the loaded 2-core machine). Without it 10,000 cells
#: of 4,000 trials were estimated at 4.7e8 (under the limit) and measured at about 16 hours
CELL_UNITS = 1.5e4
DEFAULT_MAX_ADJUSTMENTS = 5e8
#: an analytic part (no progress bar, nothing to resume) may take at most this share of the
#: work limit: 5e5 adjustment-equivalents, about 25 s on one core, at the default 5e8
ANALYTIC_SHARE = 1e-3


@dataclass(frozen=True)
class Estimate:
    """What a run will need (orders of magnitude)."""

    study: str
    trials: int  # Monte-Carlo trials over all parts (and sweep cells)
    adjustments: float  # least-squares adjustments (solves), every trial and part
    unknowns: int  # unknowns of the largest adjustment
    bytes: float  # largest working set of one chunk, bytes
    cells: int = 1  # sweep cells x replicates
    largest: str = ""  # the part whose chunk (or analytic stack) needs ``bytes``, if named
    analytic: float = 0.0  # adjustment-equivalents of the largest analytic part (one cell)
    analytic_key: str = ""  # the key that sets that part's size (``design.grids``)
    analytic_part: str = ""  # that part, named
    memory_keys: tuple = ()  # the keys that set ``bytes`` (the refusal names them), if known
    cell: str = ""  # a sweep's: the swept values of the cell that needs ``bytes`` (if cells differ)
    work: float = 0.0  # unit adjustments of the ``trials`` (the progress bar fills by them)
    work_keys: tuple = ()  # keys besides the trials that make each trial costly (named if over)

    def describe(self, workers: int = 1) -> str:
        """One line: trials, adjustments (analytic parts in adjustment-equivalents, each
        :data:`ADJUSTMENT_S` s of one core), unknowns and the memory of ``workers``
        processes."""
        if isinstance(workers, bool) or not isinstance(workers, Integral) or workers < 1:
            raise ConfigError("workers", f"must be a whole number >= 1 (got {workers!r})")
        cells = f" in {self.cells} sweep cells" if self.cells > 1 else ""
        eq = (
            f" (with {self.analytic:.3g} adjustment-equivalents of analytic work)"
            if self.analytic >= 1
            else ""
        )
        return (
            f"{self.trials:,} trials{cells}, about {self.adjustments:.3g} adjustments{eq} of up "
            f"to {self.unknowns:,} unknowns, about {_gib(self.bytes * max(workers, 1))} of "
            "memory"
        )

    def core_time(self) -> str:
        """The work as time: ``about 2.5 min of one core`` (:data:`ADJUSTMENT_S` seconds an
        adjustment on the reference machine; seconds under a minute)."""
        s = self.adjustments * ADJUSTMENT_S
        t = f"{s:.2g} s" if math.isfinite(s) and s < 60 else _minutes(s)
        return f"about {t} of one core of the reference machine"

    def memory_advice(self) -> str:
        """The keys that set the run's memory (:attr:`memory_keys`), as advice (``chunk,
        trials or plate.grid``); without them, the words that cover every study."""
        return keys_advice(self.memory_keys)


def keys_advice(keys) -> str:
    """Keys that set a run's memory as advice (``chunk, trials or plate.grid``); without
    them, the words that cover every study."""
    keys = tuple(keys or ())
    if not keys:
        return "chunk, trials or the sizes in the study file"
    return keys[0] if len(keys) == 1 else f"{', '.join(keys[:-1])} or {keys[-1]}"


def _gib(b: float) -> str:
    return f"{b / 2**30:.3g} GiB" if b >= 2**27 else f"{b / 2**20:.3g} MiB"


def _min(v, default=1.0) -> float:
    return min((float(x) for x in v), default=default) if isinstance(v, (list, tuple)) else default


# ---- one estimator per study kind: (trials, adjustments, unknowns, bytes) -------------------


#: the main experiment's trial, measured (one core, chunks of 100): each of its sets + 2 fits
#: costs :data:`WOLF_FIT_UNITS` besides its dense units (:func:`sim.mc.workunits.dense_units`,
#: within a factor 2 of a 20,301-point fit of degree 8: ``tests/test_design_work.py``); each simulated
#: reading (points x sets x readings x 2 coordinates) :data:`WOLF_READING_UNITS` and each
#: point of the independent plate :data:`WOLF_CHECK_UNITS`. From 20 units a trial at the
#: paper's setup to 117 at ``reading.n = 100``, 312 at ``calib.n_sets = 30`` and 99 at
#: ``check.n_points = 2000`` (estimated 20, 117, 192 and 97); counted as the fits alone (6, 6,
#: 101, 6) a run of a million trials at 100 readings was 20 times its estimate
WOLF_FIT_UNITS, WOLF_READING_UNITS, WOLF_CHECK_UNITS = 1.9, 2.5e-3, 0.04


def wolf_draws(n: float, sets: float, rd: float, c: Mapping) -> float:
    """Unit adjustments of a main trial's simulated readings and independent points."""
    return WOLF_READING_UNITS * n * sets * rd * 2 + WOLF_CHECK_UNITS * c.get("check.n_points", 0)


def wolf_sub_chunk(trials: int, chunk: int) -> int:
    """The chunk of Wolf's smaller parts (trade-offs, cells), as the study takes it
    (:func:`sim.studies.wolf.chunks.sub_chunk`): at most ``chunk`` and at least four chunks.
    Counted as ``min(trade.trials, chunk)``, the paper's setup (400 trade trials, chunks of
    500) was estimated at 1.09 GiB for a run that peaks at 0.39 GiB (its chunks are of 100)."""
    return max(1, min(chunk, -(-trials // 4)))


def _wolf(c: Mapping) -> tuple:
    T, ch = c["trials"], min(c["chunk"], c["trials"])
    area = c.get("plate.area_mm", [-100.0, 100.0, -40.0, 60.0])
    ax = area[1] - area[0] if len(area) >= 4 else 200.0
    ay = area[3] - area[2] if len(area) >= 4 else 100.0

    def points(sp: float) -> float:
        return grid_count(ax, sp) * grid_count(ay, sp)

    d = c.get("calib.degree", 3)
    U = (d + 1) * (d + 2)
    sets, rd = c.get("calib.n_sets", 3), c.get("reading.n", 3)
    n = points(c.get("plate.spacing_mm", 20.0))
    chk = max(
        c.get("check.n_points", 0), c.get("repeat.n_points", 0), c.get("trade.check_points", 0)
    )
    Tt = c.get("trade.trials", 0)
    cht = wolf_sub_chunk(Tt or 1, c["chunk"])  # the trade-offs' chunks (4x too large before)
    dmax = _max(c.get("trade.degrees"), d)
    Ut = int((dmax + 1) * (dmax + 2))
    nt = points(_min(c.get("trade.spacings_mm"), c.get("plate.spacing_mm", 20.0)))
    nsets = _max(c.get("trade.n_sets"), sets)
    deg_cells = (
        _n(c.get("trade.spacings_mm", []))
        * _n(c.get("trade.n_sets", []))
        * _n(c.get("trade.degrees", []))
    )
    rd_cells = 2 * _n(c.get("trade.pointing_sigmas_um", [])) * _n(c.get("trade.readings", []))
    ages = _n(c.get("trade.ages_weeks", [])) * _n(c.get("trade.drift_fractions", []))
    # the unprinted inputs: every swept value re-reduces the same simulated instruments
    Tu = c.get("unprinted.trials", 0)
    u_cells = sum(
        _n(c.get(f"unprinted.{k}", []))
        for k in (
            "pointing_sigmas_um",
            "field_scales",
            "restitutions_um",
            "drift_fractions",
            "mono_sigmas_um",
        )
    )
    trials = T + Tt * (_n(c.get("trade.spacings_mm", [])) + rd_cells + 1) + Tu
    # each adjustment fits the pooled sets' points (x and y) with U (or Ut) unknowns
    w, wt = _dense(2 * n * sets, U), _dense(2 * nt * nsets, Ut)
    # the region: each input vector (region.points, a quarter more each round) is one cell
    # of the unprinted inputs' experiment on unprinted.trials instruments
    r_pts = c.get("region.points", 0) * (1 + c.get("region.rounds", 0) / 4)
    adj = (
        T * ((sets + 2) * (w + WOLF_FIT_UNITS) + wolf_draws(n, sets, rd, c))
        + Tt * (deg_cells + rd_cells * (sets + 2) + ages) * wt
        + Tu * (u_cells + r_pts) * (sets + 2) * w
    )
    b = (
        max(
            ch * (n * sets * rd * 2 + n * U) * F8,
            cht * nt * nsets * (2 + Ut) * F8,
            ch * chk * U * F8,
            cht * (n * _max(c.get("trade.readings"), rd) * 2) * F8,
        )
        * COPIES
    )
    return trials, adj, max(U, Ut), b


def _generic(c: Mapping) -> tuple:
    T, ch = c.get("trials", 1), min(c.get("chunk", 1), c.get("trials", 1))
    return T, T, 0, ch * 1e4


ESTIMATORS: dict[str, Callable[[Mapping], tuple]] = {
    "brown_dilution": _brown,
    "brown_table1": _brown,
    "brown_design": _design,
    "gridplate_two_plates": _gridplate,
    "salsig_encoders": _salsig,
    "wolf_polynomial": _wolf,
    "agnard_block": _agnard,
    "network": _network,
}


def _one(cfg: Mapping) -> tuple:
    """``(trials, adjustments, unknowns, bytes, the part needing the bytes or "", (analytic
    adjustment-equivalents, key, part), the keys that set the bytes, the unit adjustments of
    the trials, the keys besides the trials that make them costly)``; an estimator may leave
    out the last five (the trials: one unit each)."""
    fn = ESTIMATORS.get(cfg.get("study"), _generic)
    try:
        t, a, u, b, *rest = fn(cfg)
    except (TypeError, ValueError, KeyError, OverflowError, ZeroDivisionError):
        t, a, u, b, *rest = _generic(cfg)
    fix = lambda x: x if isinstance(x, (int, float)) and not math.isnan(x) else math.inf  # noqa: E731
    a = fix(a) + _chunk_units(cfg, fix(t))
    what = rest[0] if rest else ""
    eq, key, part = rest[1] if len(rest) > 1 else (0.0, "", "")
    keys = tuple(rest[2]) if len(rest) > 2 else ()
    work = fix(rest[3]) if len(rest) > 3 else fix(t)
    wkeys = tuple(rest[4]) if len(rest) > 4 else ()
    return fix(t), a, fix(u), fix(b), what, (fix(eq), key, part), keys, work, wkeys


def _chunk_units(cfg: Mapping, trials: float) -> float:
    """:data:`CHUNK_UNITS` for each chunk of the run's ``trials`` (every part's, in chunks of
    the study's ``chunk``): the cost of a run of many small chunks."""
    ch = cfg.get("chunk", 1)
    if isinstance(ch, bool) or not isinstance(ch, (int, float)) or not ch >= 1:
        return 0.0
    return math.ceil(trials / ch) * CHUNK_UNITS if math.isfinite(trials) else math.inf


def estimate(
    cfg: Mapping[str, Any], sweep: Mapping[str, Any] | None = None, skip: Container = ()
) -> Estimate:
    """The estimate of a run of ``cfg`` (and of every cell of its ``[sweep]`` table but those
    of the indices ``skip``: cells the study refuses, recorded and never run)."""
    cfgs = [cfg]
    reps = 1
    keys: list = []
    cell = ""  # the swept values of the cell that needs ``B``, when cells differ in it
    if sweep:
        keys, cells, reps, _ = expand(sweep)
        cells = [c for i, c in enumerate(cells) if i not in skip] or cells
        cfgs = [{**cfg, **cell_values(cfg, cell)} for cell in cells]  # a cell's chunk too
    parts = [_one(c) for c in cfgs]
    T = sum(p[0] for p in parts) * reps
    A = sum(p[1] for p in parts) * reps + (len(cfgs) * reps * CELL_UNITS if sweep else 0.0)
    U = max(p[2] for p in parts)
    B, what, mkeys = max((p[3], p[4], p[6]) for p in parts)
    if sweep and B > min(p[3] for p in parts):  # the swept values that set it, named
        at = next(c for c, p in zip(cells, parts) if p[3] == B)
        cell = ", ".join(f"{k} = {toml_value(at[k])}"[:120] for k in keys)
        mkeys = tuple(f"the values of sweep.{k}" if k in keys else k for k in mkeys) or tuple(
            f"the values of sweep.{k}" for k in keys
        )
    eq, key, part = max((p[5] for p in parts), key=lambda x: x[0])  # one cell's, not the sum
    W = sum(p[7] for p in parts) * reps
    wkeys = max(parts, key=lambda p: p[1])[8]  # the costliest cell's, a swept key as swept
    wkeys = tuple(f"the values of sweep.{k}" if k in keys else k for k in wkeys)
    big = lambda x: int(x) if math.isfinite(x) and x < 2**62 else 2**62  # noqa: E731
    return Estimate(
        str(cfg.get("study")),
        big(T),
        float(A),
        big(U),
        float(B),
        len(cfgs) * reps,
        what,
        float(eq),
        key,
        part,
        mkeys,
        cell,
        float(W) if math.isfinite(W) else 0.0,
        wkeys,
    )


def check_limits(
    est: Estimate,
    max_memory_gb: float | None = None,
    max_adjustments: float | None = None,
    workers: int = 1,
) -> None:
    """Stop (ConfigError, one line with the estimate) a run over the memory or work limit, or
    whose analytic part would run silently for more than :data:`ANALYTIC_SHARE` of the work
    limit (named by its key, in minutes on the reference machine)."""
    mem = _limit(max_memory_gb, "SIM_MAX_MEMORY_GB", DEFAULT_MAX_MEMORY_GB, "--max-memory-gb")
    adj = _limit(
        max_adjustments, "SIM_MAX_ADJUSTMENTS", DEFAULT_MAX_ADJUSTMENTS, "--max-adjustments"
    )
    need = est.bytes * max(workers, 1)
    if not need <= mem * 2**30:
        fit = int(mem * 2**30 // est.bytes) if est.bytes > 0 else workers
        each = f" ({_gib(est.bytes)} each of {workers} worker processes)" if workers > 1 else ""
        raise ConfigError(
            None,
            f"{est.study}: the run needs {est.describe(workers)}{each}, over the "
            f"{mem:g} GiB limit (--max-memory-gb or SIM_MAX_MEMORY_GB)"
            + (f", most of it for {est.largest}" if est.largest else "")
            + (f", in the sweep's cell of {est.cell}" if est.cell else "")
            + (f"; use --workers {fit}, or reduce" if 1 <= fit < workers else "; reduce")
            + f" {est.memory_advice()}",
        )
    if not est.adjustments <= adj:
        raise ConfigError(
            None,
            f"{est.study}: the run needs {est.describe(workers)}, over the "
            f"limit of {adj:.3g} adjustments (--max-adjustments or "
            "SIM_MAX_ADJUSTMENTS); "  # the keys that hold the work first, not after
            + (
                f"change {keys_advice(est.work_keys)}, which "
                f"{'hold' if len(est.work_keys) > 1 else 'holds'} most of it, or "
                if est.work_keys
                else ""
            )
            + "reduce trials or the lists in the study file",
        )
    if not est.analytic <= adj * ANALYTIC_SHARE:
        raise ConfigError(
            est.analytic_key or None,
            f"{est.study}: {est.analytic_part or 'an analytic part'} needs about "
            f"{est.analytic:.3g} adjustment-equivalents, about "
            f"{_minutes(est.analytic * ADJUSTMENT_S)} of one core of the reference machine "
            f"before the first progress bar, over the {adj * ANALYTIC_SHARE:.3g} an analytic "
            f"part may take ({ANALYTIC_SHARE:g} of the limit of {adj:.3g} adjustments, "
            "--max-adjustments or SIM_MAX_ADJUSTMENTS); use fewer points per side or fewer "
            "positions, extents, offsets or betas, or raise the limit",
        )


#: seconds of one core a chunk may take before the run says so: the progress bar moves once
#: a chunk, and a chunk of 50 trials of a 6 x 30 Agnard block (20 s a trial) left it at 0 %
#: for 17 minutes without a word
CHUNK_NOTE_S = 120.0


def chunk_note(est: Estimate, chunk: int) -> str:
    """One line when a chunk of ``chunk`` trials (the run's average trial, every part's work
    over its trials) takes more than :data:`CHUNK_NOTE_S` seconds of one core, else ``""``."""
    if not est.trials >= 1 or not math.isfinite(est.adjustments):
        return ""
    n = min(chunk, est.trials)
    s = est.adjustments / est.trials * n * ADJUSTMENT_S
    if not s > CHUNK_NOTE_S:
        return ""
    return (
        f"note: a chunk of {n:,} trials takes about {_minutes(s)} of one core of the reference "
        "machine (estimate) and the progress bar moves once a chunk; a smaller --chunk shows "
        "the progress more often"
    )


def _minutes(s: float) -> str:
    if not math.isfinite(s):
        return "forever"
    return f"{s / 60:.2g} min" if s < 3600 * 10 else f"{s / 3600:.3g} h"
