"""The consistent regions of ``agnard_block``'s unprinted inputs (seed 003): the lost
five-point layout, over which (with the scanner) the 5-control predictions are decided, and the scanner,
constrained by Table 1 (issue 21, :mod:`sim.claims.inference`).

Figure 5, the layout of the five control points of the third pass, is lost. ``region.toml``
declares the layout by one number, how far the four outer points stand inwards from the block
corners, over the range the block allows, and the program's option of carrying each model's
projection centres as model points (``centres_1``, explored at 0 and 1,
:mod:`sim.instruments.block.centres`: the paper's program, SPACE-M, carries them, so the
predictions are decided at 1 and the points at 0 decide findings); nothing the
paper prints constrains them (its Table's numbers are the predictions), so the region is the
whole range and each 5-control row is decided over it: holds / fails everywhere, depends
(with the insets and option where it holds), or undecidable, over joint points of this
region and the scanner's (:mod:`sim.studies.agnard.joint`). The model adjusts the same
``region.trials`` simulated blocks once per layout (:func:`sim.studies.agnard.chunks.sweep_chunk`, on the runner's workers); each
statistic is evidence with the claim book's rules
(:func:`sim.claims.book_region.sample_evidence`).

The scanner (``scanner.toml``): the paper prints its peaks (+-20 / +-40 um, to which every
simulated field is scaled) but not the shape of its deformation (the stepper drive's share
and period), its calibration grid or its centring errors. These five inputs are explored
jointly over their possible ranges (a scrambled Sobol design of ``table1.points`` vectors),
each vector adjusting the same ``table1.trials`` simulated blocks (common random numbers,
:func:`sim.studies.agnard.chunks.table1_chunk`, on the runner's workers) without and with
the grid correction; Table 1's eight printed rms are the constraints, one-block statistics
decided by the book's one-plate rule. When no vector is consistent the region is empty and
:attr:`~sim.claims.inference.Region.conflicts` names the statements that conflict: Table 1
is then not comparable because of that (``claims.toml`` says so in the paper's words).
Set aside, Table 1 leaves every explored vector, and the 21-control predictions (Tables 2-3
and the acceptance limits) are decided over them all: each vector's blocks are paired with
the configured scanner's on the same seeds, and a row's evidence at the vector is the
configured scanner's main blocks moved by the paired shift (:mod:`sim.studies.agnard.paired`,
:func:`shift_table`); the pass points digital pugging's data snooping removes, a count with
many zeros, by its distribution function with the configured scanner's as a control variate
(:mod:`sim.studies.agnard.paired_count`). The same paired blocks also run the 5-control pass
at the joint design's layout points (:mod:`sim.studies.agnard.joint`).
"""

from __future__ import annotations

from functools import partial
from pathlib import Path
from typing import Callable

import numpy as np

from sim.claims.book import ClaimBook
from sim.claims.book_region import load_declaration, plate_ref, sample_evidence
from sim.claims.inference import Input, Region, explore
from sim.instruments.block.layout import Block
from sim.mc.agnard_size import agnard_units
from sim.mc.config import Field
from sim.mc.runner import chunk_rng
from sim.studies.agnard import chunks as ch
from sim.studies.agnard.paired import paired_evidence, paired_shift
from sim.studies.agnard.paired_count import count_evidence

DECLARATION = Path(__file__).with_name("region.toml")
#: the region's option: the program's models with (1) or without (0) projection centres
CENTRES = "centres_1"
SCANNER = Path(__file__).with_name("scanner.toml")
#: the scanner region's inputs and the config keys they set
SCANNER_KEYS = {
    "stepper_share_1": "scan.stepper_share",
    "wavelength_mm": "scan.wavelength_mm",
    "grid_mm": "scan.grid_mm",
    "grid_sigma_px": "scan.grid_sigma_px",
    "fiducial_sigma_px": "scan.fiducial_sigma_px",
}
#: the bounds of the five-point layout's inset, which reaches no config key (its code,
#: :func:`sim.studies.agnard.schema.five_targets`, takes them; :func:`sim.studies.data_check`)
INSET = Field(
    0.0,
    "float",
    "beyond 0.5 the outer points cross the block's middle (the layouts of 1 - inset again), "
    "below 0 they leave the block (its corners again)",
    lo=0.0,
    hi=0.5,
)
#: the runner's stream of the scanner region's blocks (apart from every trade-off part) and
#: of its design
SCANNER_PART = 800
#: key prefix of the configured scanner's statistics on a vector's blocks
CONFIGURED = "configured:"
#: the count decided over the scanner's inputs: pass points removed from one block
REJECTED = "agnard.pass_rejections.digital"
#: predictions that are counts with many zeros (:mod:`sim.studies.agnard.paired_count`)
COUNTS = frozenset({REJECTED})


def five_samples(sw: dict, i: int, pre: str = "") -> dict[str, np.ndarray]:
    """Per-block statistics (cm) of layout ``i`` keyed by claim id (``pre``: ``"centres."``
    for the layout with the projection centres, :func:`sim.studies.agnard.chunks.sweep_chunk`)."""
    return five_of(sw, f"{pre}inset{i}")


def five_of(sw: dict, pre: str) -> dict[str, np.ndarray]:
    """Per-block statistics (cm) of one 5-control pass, keys ``<pre>.<ctrl|check>_<axis>_m``
    of ``sw``, keyed by claim id."""
    out = {}
    for w in ("ctrl", "check"):
        for c in ("x", "y", "z"):  # XY is the paper-check of their quadrature, not simulated
            out[f"agnard.control_5.{w}_{c}_cm"] = 100 * np.asarray(sw[f"{pre}.{w}_{c}_m"])
    for c in ("xy", "z"):  # the acceptance limit applies to the control rms
        out[f"agnard.max_residual.control_5_{c}_cm"] = 100 * np.asarray(sw[f"{pre}.ctrl_{c}_m"])
    return out


def explore_region(
    cfg: dict, block: Block, book: ClaimBook, runner: Callable[..., dict], part: int
) -> tuple[Region, list[str], list[dict]]:
    """The region, its predictions, and the per-layout statistics of every explored layout
    (``runner(fn, trials, part, label)`` runs one part through the runner). The layouts are
    one Sobol design of ``region.points`` insets, explored once without and once with the
    projection centres (``centres_1`` 0 and 1, the same insets, on the same blocks: one run
    of the runner gives both); the region is their union."""
    dec = load_declaration(DECLARATION, book)
    stats: list[dict] = []
    both: dict[tuple, dict] = {}  # the half without centres computes the other half as well

    def run(insets: tuple, options: tuple) -> dict:
        return runner(
            partial(ch.sweep_chunk, cfg, block, insets, centres=options),
            cfg["region.trials"],
            part + len(stats),
            "five-point layouts"
            + (", with and without projection centres" if len(options) > 1 else ""),
            units=agnard_units(cfg)["region"] * len(options) / 2,
        )

    def model(x: dict[str, np.ndarray]) -> dict:
        insets = tuple(float(u) for u in x["five_inset_1"])
        if x[CENTRES][0] > 0.5:  # the same blocks as the half without (common random numbers)
            sw, pre = both.pop(insets, None) or run(insets, (True,)), "centres."
        else:
            sw = both[insets] = run(insets, (False, True))
            pre = ""
        per = [five_samples(sw, i, pre) for i in range(len(insets))]
        stats.extend(per)
        return {
            c: sample_evidence(np.stack([p[c] for p in per]), *plate_ref(book.spec(c)))
            for c in dec.predictions
        }

    halves = [
        explore(
            [Input(i.name, v, v, i.why) if i.name == CENTRES else i for i in dec.inputs],
            dec.statements,
            model,
            chunk_rng(cfg["region.seed"], 900, 0),
            n=cfg["region.points"],
            rounds=0,
        )
        for v in (0.0, 1.0)
    ]
    return union(halves, dec.inputs), dec.predictions, stats


def union(parts: list[Region], inputs: list[Input]) -> Region:
    """One region of the explored points of ``parts`` (the same statements, each explored
    at one value of an input that is an option, fixed there): ``inputs`` as declared, the
    resolution of the first part and 1 (both values) for the option."""
    first = parts[0]
    cat = lambda a: np.concatenate([np.asarray(v) for v in a])  # noqa: E731
    outputs = {
        k: (
            {j: None if v[j] is None else cat([p.outputs[k][j] for p in parts]) for j in v}
            if isinstance(v, dict)
            else cat([p.outputs[k] for p in parts])
        )
        for k, v in first.outputs.items()
    }
    return Region(
        inputs,
        first.statements,
        {k: cat([p.x[k] for p in parts]) for k in first.x},
        np.concatenate([p.status for p in parts]),
        first.level,
        {i.name: first.resolution[i.name] if i.name != CENTRES else (1.0, 1.0) for i in inputs},
        outputs,
    )


def many_samples(sw: dict, pre: str) -> dict[str, np.ndarray]:
    """Per-block statistics (cm) of the 21-control pass keyed by claim id (``pre``: ``s<i>``
    for scanner vector ``i``, ``cfg`` for the configured scanner on the same blocks, or
    ``layout_<control.many>`` of the main blocks); the acceptance limits apply to the control
    rms."""
    out = {
        f"agnard.control_21.{w}_{c}_cm": 100 * np.asarray(sw[f"{pre}.{w}_{c}_m"])
        for w in ("ctrl", "check")
        for c in ("x", "y", "xy", "z")
    }
    for c in ("xy", "z"):
        out[f"agnard.max_residual.control_21_{c}_cm"] = out[f"agnard.control_21.ctrl_{c}_cm"]
    return out


def first_samples(sw: dict, pre: str = "") -> dict[str, np.ndarray]:
    """Per-block pass-point rms (cm) of the first pass (weak control) keyed by claim id
    (``pre``: ``s<i>`` for scanner vector ``i``, ``cfg`` for the configured scanner on the
    same blocks, ``""`` for the main blocks)."""
    p = f"{pre}." if pre else ""
    return {
        f"agnard.first_pass.pass_{c}_cm": 100 * np.asarray(sw[f"{p}first.pass_{c}_m"])
        for c in ("xy", "z")
    }


def table1_samples(sw: dict, i: int) -> dict[str, np.ndarray]:
    """Per-block statistics of scanner vector ``i`` keyed by claim id: Table 1's rms (m) and
    the 21-control and first passes' (cm, :func:`many_samples`, :func:`first_samples`)."""
    out = {
        f"agnard.table1.{tag}_{w}_{c}_m": np.asarray(sw[f"s{i}.{tag}.{w}_{c}_m"])
        for tag in ("without", "with")
        for w in ("ctrl", "check")
        for c in ("x", "y")
    }
    return {**out, **many_samples(sw, f"s{i}.many"), **first_samples(sw, f"s{i}")}


def explore_scanner(
    cfg: dict,
    block: Block,
    book: ClaimBook,
    runner: Callable[..., dict],
    base: dict,
    five: tuple = (),
    pairs: Callable[[int], tuple[int, ...]] | None = None,
) -> tuple[Region, list[str], list[dict]]:
    """The scanner region under Table 1, the predictions decided over the scanner's inputs
    (``scanner.toml``) and the per-vector statistics of every explored vector, with the
    configured scanner's on the same blocks (keys ``CONFIGURED + claim id``; ``runner(fn,
    trials, part, label)`` runs one part through the runner). Table 1's statements are decided on
    each vector's own blocks; the predictions by :func:`sim.studies.agnard.paired.
    paired_evidence`: ``base`` (claim id: the configured scanner's per-block statistic over
    the main blocks) shifted by each vector's paired shift from the configured scanner; a
    count (:data:`COUNTS`) by :func:`sim.studies.agnard.paired_count.count_evidence`. With
    ``five`` (layout points of the 5-control pass, :mod:`.joint`) the same blocks also give
    the 5-control statistics, the configured scanner's at every point and vector ``j``'s at
    ``pairs(j)`` (keys ``five<l>:<claim id>``, configured ``CONFIGURED + five<l>:<claim id>``)."""
    dec = load_declaration(SCANNER, book)
    stats: list[dict] = []

    def model(x: dict[str, np.ndarray]) -> dict:
        n = len(next(iter(x.values())))
        scanners = tuple(
            {key: float(x[name][j]) for name, key in SCANNER_KEYS.items()} for j in range(n)
        )
        pj = tuple(pairs(len(stats) + j) if pairs else () for j in range(n))
        sw = runner(
            partial(ch.table1_chunk, cfg, block, scanners, five=five, pairs=pj, rejections=True),
            cfg["table1.trials"],
            SCANNER_PART + len(stats),
            "scanner vectors (Table 1), each paired with the configured scanner",
            units=agnard_units(cfg)["table1"](n),
        )
        c, per = _vector_stats(sw, len(five), pj)
        stats.extend(per)
        ev = {
            s.id: sample_evidence(np.stack([p[s.id] for p in per]), s.ref[0])
            for s in dec.statements
        }
        for cid in dec.predictions:
            v = np.stack([p[cid] for p in per])
            how = count_evidence if cid in COUNTS else paired_evidence
            ev[cid] = how(base[cid], c[cid], v, *plate_ref(book.spec(cid)))
        return ev

    region = explore(
        dec.inputs,
        dec.statements,
        model,
        chunk_rng(cfg["region.seed"], SCANNER_PART - 1, 0),
        n=cfg["table1.points"],
        rounds=cfg["table1.rounds"],
    )
    return region, dec.predictions, stats


def _vector_stats(sw: dict, n_five: int, pj: tuple) -> tuple[dict, list[dict]]:
    """The configured scanner's per-block statistics on one call's paired blocks (claim id;
    ``five<l>:`` + claim id at the ``n_five`` layout points) and each vector's, with the
    configured ones beside them (``CONFIGURED +`` key; vector ``j`` at layout points
    ``pj[j]``)."""
    c = {**many_samples(sw, "cfg.many"), **first_samples(sw, "cfg")}
    c[REJECTED] = np.asarray(sw["cfg.snoop.rejected"])
    for lay in range(n_five):
        c.update({f"five{lay}:{k}": v for k, v in five_of(sw, f"cfg.five{lay}").items()})
    per = []
    for j, lays in enumerate(pj):
        p = {**table1_samples(sw, j), **{CONFIGURED + k: v for k, v in c.items()}}
        p[REJECTED] = np.asarray(sw[f"s{j}.snoop.rejected"])
        for lay in lays:
            p.update({f"five{lay}:{k}": v for k, v in five_of(sw, f"s{j}.five{lay}").items()})
        per.append(p)
    return c, per


def shift_table(region: Region, preds: list[str], stats: list[dict]) -> dict[str, list]:
    """``scanner_shift.parquet``: per explored vector and prediction, the inputs, the paired
    log shift from the configured scanner and its standard error, the standard error the
    same blocks would give unpaired (independent blocks of the two scanners), the log scale
    of the spread and its error, the pairs' correlation and whether the map stretches
    (:mod:`sim.studies.agnard.paired`)."""
    cols: dict[str, list] = {k: [] for k in (*region.x, "claim", "delta_log", "delta_log_se")}
    cols.update({k: [] for k in ("unpaired_se", "log_beta", "log_beta_se", "rho", "stretched")})
    for cid in preds:
        c = stats[0][CONFIGURED + cid]  # every call of the model pairs its own blocks
        v = np.stack([p[cid] for p in stats])
        cs = np.stack([p[CONFIGURED + cid] for p in stats])
        sh = [paired_shift(cs[j], v[j : j + 1]) for j in range(len(stats))]
        k = c.size
        lu, lw = np.log(cs), np.log(v)
        unpaired = np.sqrt((lu.var(axis=1, ddof=1) + lw.var(axis=1, ddof=1)) / k)
        for name in region.x:
            cols[name].extend(np.asarray(region.x[name], float).tolist())
        cols["claim"].extend([cid] * len(stats))
        cols["delta_log"].extend(float(s.delta[0]) for s in sh)
        cols["delta_log_se"].extend(float(s.delta_se[0]) for s in sh)
        cols["unpaired_se"].extend(unpaired.tolist())
        cols["log_beta"].extend(float(s.log_beta[0]) for s in sh)
        cols["log_beta_se"].extend(float(s.log_beta_se[0]) for s in sh)
        cols["rho"].extend(float(s.rho[0]) for s in sh)
        cols["stretched"].extend(bool(s.stretched[0]) for s in sh)
    return cols
