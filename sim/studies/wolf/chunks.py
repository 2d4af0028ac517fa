"""Chunk functions of ``wolf_polynomial`` (picklable: module-level functions bound with
:func:`functools.partial` to plain arguments). Each takes ``(rng, T)`` and returns per-trial
arrays (leading axis ``T``). Wolf & Pearsall 1976 (seed ``000_668e60e68f004f98.txt``);
coordinates mm, discrepancies um.

The main experiment draws one set of instruments, placements and noise per chunk
(:func:`draw_main`) and reduces it for one or more *cells* (:func:`reduce_main`): a cell
overrides the pointing sigma, the readings per point, the approach, the monocomparator sigma
the restitution amplitude, the drifting share of the field or a common factor on the field
amplitudes. Cells of one chunk share their random numbers, so
the sweeps of the unprinted inputs and the readings trade-off compare like with like.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from sim.instruments.plotter import errorfields as ef
from sim.instruments.plotter import polynomial as pl
from sim.studies.wolf.grid import grid_nodes, mid_cells, node_index
from sim.studies.wolf.model import (
    Instrument,
    calib_dates,
    calibrate,
    correct_plate,
    ls_map,
    measure,
    measure_parts,
    photo_points,
    place,
    read_placed,
    stats_cols,
    true_plate,
)


def sub_chunk(trials: int, chunk: int) -> int:
    """Chunk size of the smaller parts (trade-offs, cells): at most ``chunk``, and at least
    four chunks, so they spread over the workers too."""
    return max(1, min(chunk, -(-trials // 4)))


#: the config keys a cell may override, and the field-amplitude factor
CELL_KEYS = (
    "reading.n",
    "reading.pointing_sigma_um",
    "reading.approach",
    "mono.sigma_um",
    "field.restitution_um",
    "field.drift_fraction",
    "field_scale",
    "noncubic_factor",
)
#: cell keys that are factors on the configured instrument (1 = as configured), not config keys
FACTORS = ("field_scale", "noncubic_factor")


def _dates(cfg: dict, later) -> tuple[np.ndarray, np.ndarray]:
    """Calibration dates then ``later`` dates (weeks); returns the sorted dates and the rank of
    each date in the given order."""
    t_cal = calib_dates(cfg, cfg["calib.n_sets"])
    dates = np.concatenate([t_cal, t_cal[-1] + np.asarray(later, float)])
    order = np.argsort(dates, kind="stable")
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    return dates[order], rank


def draw_main(cfg: dict, rng: np.random.Generator, T: int, nmax: int, full: bool = True) -> dict:
    """Everything random about the main experiment for ``T`` instruments: the calibration sets
    (grid and cell centres), an independent plate read ``check.age_weeks`` after the last set,
    a P-30 photograph read on two dates (Table 1) and its monocomparator noise (Table 2)."""
    area, s = cfg["plate.area_mm"], cfg["plate.spacing_mm"]
    G, Cm = grid_nodes(area, s), mid_cells(area, s)
    S = cfg["calib.n_sets"]
    age, gap = cfg["check.age_weeks"], cfg["repeat.gap_weeks"]
    dates, rank = _dates(cfg, [age, age, age + gap])
    inst = Instrument(cfg, rng, T, dates)
    gs = cfg["plate.grid_sigma_um"]
    rot, shift = cfg["plate.rotation_sigma_deg"], cfg["plate.shift_sigma_mm"]
    plate = true_plate(rng, np.concatenate([G, Cm]), T, gs)
    cal = [place(rng, inst, int(rank[j]), plate, rot, shift, nmax) for j in range(S)]
    m5 = 5.0  # margin so that the placed points stay (nearly) inside the calibrated area
    pk = rng.uniform(
        [area[0] + m5, area[2] + m5], [area[1] - m5, area[3] - m5], (T, cfg["check.n_points"], 2)
    )
    ptrue = pk + rng.normal(0.0, gs * 1e-3, pk.shape)
    chk = place(
        rng,
        inst,
        int(rank[S]),
        ptrue,
        cfg["check.rotation_sigma_deg"],
        cfg["check.shift_sigma_mm"],
        nmax,
    )
    ph = photo_points(rng, cfg, T)
    rep = [place(rng, inst, int(rank[j]), ph, rot, shift, nmax) for j in (S + 1, S + 2)]
    mono_z = rng.normal(size=ph.shape)
    comp_rms = {}
    if full:  # the components' rms on the grid (no random numbers drawn here)
        comp = ef.evaluate_components(inst.spec, inst.static, G)
        comp_rms = {
            k: math.sqrt(1 - inst.f) * np.sqrt((v**2).mean((1, 2))) for k, v in comp.items()
        }
    return {
        "G": G,
        "Cm": Cm,
        "cal": cal,
        "pk": pk,
        "chk": chk,
        "ph": ph,
        "rep": rep,
        "mono_z": mono_z,
        "comp_rms": comp_rms,
    }


def _reduce_readings(cfg: dict, D: dict, cell: dict, full: bool, keep_vectors: bool):
    """Everything of :func:`reduce_main` but the monocomparator comparison: the statistics up
    to the repeatability, set 1 of the photograph (um) and the fit's status (and vectors)."""
    G, Cm = D["G"], D["Cm"]
    nG, S = len(G), cfg["calib.n_sets"]
    ia, ib = node_index(G, (0, 0)), node_index(G, (cfg["reduce.ab_mm"], 0))
    terms = pl.WOLF_TERMS if cfg["calib.degree"] == 3 else None
    n, sg = cell["reading.n"], cell["reading.pointing_sigma_um"]
    appr, fs = cell["reading.approach"], cell["field_scale"]
    rd = functools.partial(
        read_placed,
        count_um=cfg["reading.count_um"],
        n=n,
        sigma_um=sg,
        backlash_um=cfg["reading.backlash_um"],
        approach=appr,
        field_scale=fs,
        drift_fraction=cell["field.drift_fraction"],
        restitution_um=cell["field.restitution_um"],
        noncubic_factor=cell["noncubic_factor"],
    )
    counts = [rd(p) for p in D["cal"]]
    red, tps, fit, mtp = calibrate(
        cfg, G, [c[:, :nG] for c in counts], ia, ib, cfg["calib.degree"], terms, corrected=True
    )
    out: dict = {}
    meas = red.transpose(1, 0, 2, 3).reshape(-1, S * nG, 2)  # pooled sets
    T = meas.shape[0]
    before = (meas - np.tile(G, (S, 1))) * 1000.0
    after = (fit.corrected_mm - np.tile(G, (S, 1))) * 1000.0  # apply_poly(fit, meas)
    stats_cols("before", before, out)
    stats_cols("after", after, out)
    # check points of the same sets (cell centres), reduced with each set's transform
    chk = np.concatenate([pl.apply_two_point(tp, c[:, nG:]) for tp, c in zip(tps, counts)], 1)
    kc = np.tile(Cm, (S, 1))
    stats_cols("check_before", (chk - kc) * 1000.0, out)
    stats_cols("check_after", (pl.apply_poly(fit, chk) - kc) * 1000.0, out)
    if full:  # least-squares similarity / affine reductions of the same sets (no correction)
        raw = [c[:, :nG] for c in counts]
        for kind in ("similarity", "affine"):
            d = [(ls_map(kind, c, G, c) - G) * 1000.0 for c in raw]
            stats_cols(f"before_{kind}", np.concatenate(d, 1), out)
    cnt = rd(D["chk"])
    stats_cols("plate_before", correct_plate(fit, mtp, cnt, D["pk"], use_poly=False), out)
    stats_cols("plate_after", correct_plate(fit, mtp, cnt, D["pk"]), out)
    # Table 1 analogue: one photograph read on two dates, each fitted to its four fiducials
    ph = D["ph"]
    rep = [correct_plate(fit, mtp, rd(p), ph, fiducials=slice(0, 4)) for p in D["rep"]]
    stats_cols("repeat", (rep[0] - rep[1])[:, 4:], out)
    tail = {"fit.ok": fit.ok}
    if keep_vectors:
        tail["vec.before"] = before.reshape(T, S, nG, 2)
        tail["vec.after"] = after.reshape(T, S, nG, 2)
    return out, rep[0], tail


def _mono(D: dict, rep0: np.ndarray, mono_sigma_um: float, out: dict) -> None:
    """Table 2 analogue: set 1 (``rep0``, um) against a monocomparator reading, also fitted to
    the fiducials."""
    ph = D["ph"]
    M = ph + mono_sigma_um * 1e-3 * D["mono_z"]
    mono = (ls_map("similarity", M[:, :4], ph[:, :4], M) - ph) * 1000.0
    stats_cols("mono", (rep0 - mono)[:, 4:], out)


def reduce_main(
    cfg: dict, D: dict, cell: dict, full: bool = True, keep_vectors: bool = False, _reduced=None
):
    """Read and reduce the drawn experiment ``D`` for one cell; per-trial statistics (um).
    ``_reduced``: the result of :func:`_reduce_readings` for this cell, when known."""
    out, rep0, tail = (
        _reduce_readings(cfg, D, cell, full, keep_vectors) if _reduced is None else _reduced
    )
    out = dict(out)
    _mono(D, rep0, cell["mono.sigma_um"], out)
    out.update(tail)
    return out


def _cell(cfg: dict, over) -> dict:
    cell = {k: cfg[k] for k in CELL_KEYS if k not in FACTORS}
    cell.update(dict.fromkeys(FACTORS, 1.0))
    cell.update(dict(over))
    return cell


def _main_chunk_impl(cfg, cells, full, keep_vectors, rng: np.random.Generator, T: int) -> dict:
    """Chunk function of the main experiment; ``cells`` = ((tag, ((key, value), ...)), ...)."""
    cl = [(tag, _cell(cfg, over)) for tag, over in cells]
    D = draw_main(cfg, rng, T, max(c["reading.n"] for _, c in cl), full)
    out, done = {}, {}
    for tag, c in cl:
        # cells that differ only in the monocomparator sigma (or not at all) read and reduce
        # the same numbers: once
        key = tuple(sorted((k, v) for k, v in c.items() if k != "mono.sigma_um"))
        if key not in done:
            done[key] = _reduce_readings(cfg, D, c, full, keep_vectors)
        r = reduce_main(cfg, D, c, full, keep_vectors, _reduced=done[key])
        out.update({tag + k: v for k, v in r.items()})
    if full:
        for name, v in D["comp_rms"].items():
            out[f"component.{name}_rms_um"] = v
    return out


def main_chunk(cfg: dict, cells=(("", ()),), full: bool = True, keep_vectors: bool = False):
    """Picklable chunk function ``fn(rng, n)`` of the main experiment (see
    :func:`_main_chunk_impl`); ``cells`` as there (default: one cell, the config itself)."""
    cells = tuple((str(t), tuple((str(k), v) for k, v in dict(o).items())) for t, o in cells)
    return functools.partial(_main_chunk_impl, cfg, cells, bool(full), bool(keep_vectors))


# ----------------------------------------------------------------------------- trade-offs


def _degree_chunk_impl(cfg, spacing, rng: np.random.Generator, T: int) -> dict:
    """Degree x number of pooled sets at one grid spacing.

    Returns per trial the rms (um, both axes pooled) on the fitting data and on an independent
    plate of random points inside the grid's extent, read ``check.age_weeks`` after the last
    set and reduced like a photograph (calibration scale and centre cross, polynomial,
    least-squares similarity). NaN where the grid has fewer rows or columns than the degree
    needs (the polynomial is then not determined by the nominal grid).
    """
    area = cfg["plate.area_mm"]
    G = grid_nodes(area, spacing)
    nx, ny = len(np.unique(G[:, 0])), len(np.unique(G[:, 1]))
    ia, ib = node_index(G, (0, 0)), node_index(G, (cfg["reduce.ab_mm"], 0))
    nmax = max(cfg["trade.n_sets"])
    t_cal = calib_dates(cfg, nmax)
    dates = np.concatenate([t_cal, [t_cal[-1] + cfg["check.age_weeks"]]])
    lo, hi = G.min(0), G.max(0)
    m = cfg["trade.check_points"]

    inst = Instrument(cfg, rng, T, dates)
    plate = true_plate(rng, G, T, cfg["plate.grid_sigma_um"])
    counts = [
        measure(rng, inst, j, plate, cfg["plate.rotation_sigma_deg"], cfg["plate.shift_sigma_mm"])
        for j in range(nmax)
    ]
    ck = rng.uniform(lo, hi, (T, m, 2))
    ct = ck + rng.normal(0.0, cfg["plate.grid_sigma_um"] * 1e-3, ck.shape)
    cc = measure(rng, inst, nmax, ct, cfg["check.rotation_sigma_deg"], 0.0)
    out = {}
    for ns in cfg["trade.n_sets"]:
        for d in cfg["trade.degrees"]:
            red, _, fit, mtp = calibrate(cfg, G, counts[:ns], ia, ib, d)
            fr = np.sqrt((fit.rms_mm**2).mean(1)) * 1000.0
            cr = np.sqrt((correct_plate(fit, mtp, cc, ck) ** 2).mean((1, 2)))
            bad = ~fit.ok | (min(nx, ny) < d + 1)
            fr[bad] = np.nan
            cr[bad] = np.nan
            out[f"fit.{ns}.{d}"] = fr
            out[f"check.{ns}.{d}"] = cr
    return out


def degree_chunk(cfg: dict, spacing: float):
    """Picklable chunk function ``fn(rng, n)`` (see :func:`_degree_chunk_impl`)."""
    return functools.partial(_degree_chunk_impl, cfg, spacing)


def _age_reads(cfg, rng: np.random.Generator, inst, rank, ages, T: int) -> list:
    """Per age after the last set: an independent plate of ``check.n_points`` random points
    (5 mm inside the area), its true positions (mm) and its read parts."""
    S, area, gs, m5 = cfg["calib.n_sets"], cfg["plate.area_mm"], cfg["plate.grid_sigma_um"], 5.0
    checks = []
    for i in range(len(ages)):
        pk = rng.uniform(
            [area[0] + m5, area[2] + m5],
            [area[1] - m5, area[3] - m5],
            (T, cfg["check.n_points"], 2),
        )
        pt = pk + rng.normal(0.0, gs * 1e-3, pk.shape)
        checks.append(
            (
                pk,
                measure_parts(
                    rng,
                    inst,
                    int(rank[S + i]),
                    pt,
                    cfg["check.rotation_sigma_deg"],
                    cfg["check.shift_sigma_mm"],
                ),
            )
        )
    return checks


def _stability_chunk_impl(cfg, fractions, ages, rng: np.random.Generator, T: int) -> dict:
    """Calibrate on the first ``calib.n_sets`` dates, read an independent plate at each age after
    the last set, for each drifting share ``f``: rms (um, both axes) before and after."""
    S = cfg["calib.n_sets"]
    dates, rank = _dates(cfg, ages)
    G = grid_nodes(cfg["plate.area_mm"], cfg["plate.spacing_mm"])
    ia, ib = node_index(G, (0, 0)), node_index(G, (cfg["reduce.ab_mm"], 0))
    terms = pl.WOLF_TERMS if cfg["calib.degree"] == 3 else None
    # common random numbers: the same instruments, plates and readings for every drifting
    # share f (the draws do not depend on f), read once; only their mixture depends on f
    inst = Instrument(cfg, rng, T, dates)
    plate = true_plate(rng, G, T, cfg["plate.grid_sigma_um"])
    cal = [
        measure_parts(
            rng,
            inst,
            int(rank[j]),
            plate,
            cfg["plate.rotation_sigma_deg"],
            cfg["plate.shift_sigma_mm"],
        )
        for j in range(S)
    ]
    checks = _age_reads(cfg, rng, inst, rank, ages, T)
    out = {}
    for f in fractions:
        _, _, fit, mtp = calibrate(
            cfg, G, [r.counts(f) for r in cal], ia, ib, cfg["calib.degree"], terms
        )
        for i, (pk, r) in enumerate(checks):
            c = r.counts(f)
            for tag, use in (("before", False), ("after", True)):
                d = correct_plate(fit, mtp, c, pk, use_poly=use)
                out[f"{tag}.{f}.{i}"] = np.sqrt((d**2).mean((1, 2)))
    return out


def stability_chunk(cfg: dict, fractions, ages):
    """Picklable chunk function ``fn(rng, n)`` (see :func:`_stability_chunk_impl`)."""
    return functools.partial(_stability_chunk_impl, cfg, tuple(fractions), tuple(ages))
