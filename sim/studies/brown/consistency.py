"""The unprinted inputs of the Brown studies, swept: where does each claim hold?

The paper prints no station offset ("a short distance from the midsides") and, for the
Concept section, no point layout ("about 25 well-distributed points", "points near the
edges"). Both studies sweep the offset; ``brown_dilution`` also sweeps the half extent of
the points. Each geometry is scored with the study's claim book by the same rule as the
nominal run (analytic cofactors, :mod:`.values`). A geometry is *feasible* when every range
fits the paper's scale plus micrometer (261 + 1 mm); infeasible geometries are evaluated
and drawn as *idealised*, never used for a consistent set.

Outputs: ``sweep.parquet`` (long: one row per geometry and claim) and
``consistent_set.parquet``: per swept input and claim the interval of feasible values where
the claim holds (``holds_low``, ``holds_high``; NaN if nowhere; ``contiguous`` false when the
set has gaps, then the interval is its hull), where it is not contradicted (``ok_*``: holds
or inconclusive), and rows with claim ``ALL`` (every swept prediction holds) and
``ALL_SATISFIABLE`` (every swept prediction that holds somewhere), with the claims that hold
nowhere or pairwise exclude each other in ``conflicts``.
"""

from __future__ import annotations

import numpy as np

from sim.claims.book import ClaimBook
from sim.instruments.ranges import multilateration as ml
from sim.studies.brown import values as V
from sim.studies.brown.schema import sweep_offsets

CS_COLUMNS = [
    "input",
    "fixed",
    "claim",
    "holds_low",
    "holds_high",
    "contiguous",
    "ok_low",
    "ok_high",
    "swept_low",
    "swept_high",
    "feasible_high",
    "conflicts",
]
SWEEP_COLUMNS = [
    "half_extent_mm",
    "offset_mm",
    "feasible",
    "max_range_mm",
    "claim",
    "kind",
    "value",
    "ci_low",
    "ci_high",
    "p_plate",
    "verdict",
]


def fresh(book: ClaimBook) -> ClaimBook:
    """An unscored copy of ``book`` (each geometry scores every claim once)."""
    return ClaimBook(list(book.specs.values()), [], book.path)


def feasible(cfg: dict, P: np.ndarray, TH: np.ndarray):
    """(feasible (G,), longest range (G,)): every range on the scale plus micrometer."""
    r = ml.ranges(P, TH)
    rmax = r.max(axis=(1, 2))
    lim = cfg["comparator.scale_length_mm"] + cfg["comparator.micrometer_mm"]
    ok = r.min(axis=(1, 2)) >= 0
    if cfg["comparator.scale_length_mm"] > 0:
        ok &= rmax <= lim
    return ok, rmax


def _score_rows(book, args_list, ext, offs, ok, rmax, out):
    for g, args in enumerate(args_list):
        b = fresh(book)
        for cid, kw in args.items():
            r = b.score(cid, **kw)
            for k, v in (
                ("half_extent_mm", ext[g]),
                ("offset_mm", offs[g]),
                ("feasible", bool(ok[g])),
                ("max_range_mm", rmax[g]),
                ("claim", cid),
                ("kind", r["kind"]),
                ("value", r["value"]),
                ("ci_low", r["ci_low"]),
                ("ci_high", r["ci_high"]),
                ("p_plate", r["p_plate"]),
                ("verdict", r["verdict"] if r["kind"] != "input" else r["outcome"]),
            ):
                out[k].append(v)


def sweep_dilution(cfg: dict, book: ClaimBook, pts: np.ndarray) -> dict:
    """Score the Concept claims over half extents x offsets (the plate's pattern scaled)."""
    ext0 = float(np.abs(pts).max())
    exts = np.array(sorted(set(cfg["consistency.extents_mm"]) | {ext0}), float)
    offs = sweep_offsets(cfg)
    E, O = (a.ravel() for a in np.meshgrid(exts, offs, indexing="ij"))
    P = pts[None] * (E / ext0)[:, None, None]
    TH = V.thetas(cfg["plate.format_mm"], O, cfg["comparator.alpha_mm"], cfg["comparator.beta_mm"])
    ok, rmax = feasible(cfg, P, TH)
    sig = {m: V.sigmas(P, TH, m) for m in ("known", "stations", "pivot")}
    curve, _ = V.dilution_curve(cfg["plate.format_mm"], cfg["dilution.grids"], E, O, pivot=False)
    args = V.dilution_values(P, sig, V.monotone(curve))
    out = {c: [] for c in SWEEP_COLUMNS}
    _score_rows(book, args, E, O, ok, rmax, out)
    return out


def sweep_table1(cfg: dict, book: ClaimBook, pts: np.ndarray, range_sigma_um: float) -> dict:
    """Score the geometry-dependent Table-1 claims over the station offsets."""
    offs = sweep_offsets(cfg)
    P = np.broadcast_to(pts, (len(offs),) + pts.shape).copy()
    TH = V.thetas(
        cfg["plate.format_mm"], offs, cfg["comparator.alpha_mm"], cfg["comparator.beta_mm"]
    )
    ok, rmax = feasible(cfg, P, TH)
    dof = 4 * len(pts) - (2 * len(pts) + 7)
    args = V.table1_values(V.sigmas(P, TH, "pivot"), V.closure_quantiles(range_sigma_um, dof))
    out = {c: [] for c in SWEEP_COLUMNS}
    E = np.full(len(offs), float(np.abs(pts).max()))
    _score_rows(book, args, E, offs, ok, rmax, out)
    return out


def _hull(x: np.ndarray, mask: np.ndarray):
    if not mask.any():
        return np.nan, np.nan, False
    i = np.flatnonzero(mask)
    return float(x[i[0]]), float(x[i[-1]]), bool(i[-1] - i[0] + 1 == len(i))


def consistent_set(sw: dict, cfg: dict) -> dict:
    """Rows of ``consistent_set.parquet`` from the long sweep table (see the module doc)."""
    cols = {c: [] for c in CS_COLUMNS}
    ext = np.asarray(sw["half_extent_mm"], float)
    off = np.asarray(sw["offset_mm"], float)
    cl = np.asarray(sw["claim"])
    verdict = np.asarray(sw["verdict"])
    kind = np.asarray(sw["kind"])
    feas = np.asarray(sw["feasible"], bool)
    preds = [c for c in dict.fromkeys(cl) if (kind[cl == c] == "prediction").all()]
    exts = sorted(set(ext))
    multi = len(exts) > 1

    def add(inp, fixed, claim, x, hold, okm, fh, conflicts=""):
        lo, hi, cont = _hull(x, hold)
        olo, ohi, _ = _hull(x, okm)
        for k, v in (
            ("input", inp),
            ("fixed", fixed),
            ("claim", claim),
            ("holds_low", lo),
            ("holds_high", hi),
            ("contiguous", cont),
            ("ok_low", olo),
            ("ok_high", ohi),
            ("swept_low", float(x.min())),
            ("swept_high", float(x.max())),
            ("feasible_high", fh),
            ("conflicts", conflicts),
        ):
            cols[k].append(v)

    per_ext = {}
    for e in exts:
        sel = ext == e
        x = np.unique(off[sel])
        fx = np.array([feas[sel & (off == o)][0] for o in x])
        fh = float(x[fx].max()) if fx.any() else np.nan
        fixed = f"half extent of the points {e:g} mm" + ("" if multi else " (printed)")
        H, K = {}, {}
        for c in preds:
            s = sel & (cl == c)
            order = np.argsort(off[s])
            H[c] = (verdict[s][order] == "holds") & fx
            K[c] = np.isin(verdict[s][order], ("holds", "inconclusive")) & fx
            add("comparator.station_offset_mm", fixed, c, x, H[c], K[c], fh)
        nowhere = [c for c in preds if not H[c].any()]
        some = [c for c in preds if H[c].any()]
        pairs = [
            f"{a} / {b}"
            for i, a in enumerate(some)
            for b in some[i + 1 :]
            if not (H[a] & H[b]).any()
        ]
        conf = "; ".join(
            ([f"hold nowhere: {', '.join(nowhere)}"] if nowhere else [])
            + ([f"disjoint: {', '.join(pairs)}"] if pairs else [])
        )
        allh = np.logical_and.reduce([H[c] for c in preds])
        allk = np.logical_and.reduce([K[c] for c in preds])
        add("comparator.station_offset_mm", fixed, "ALL", x, allh, allk, fh, conf)
        sath = np.logical_and.reduce([H[c] for c in some]) if some else np.zeros_like(fx)
        satk = np.logical_and.reduce([K[c] for c in some]) if some else np.zeros_like(fx)
        add("comparator.station_offset_mm", fixed, "ALL_SATISFIABLE", x, sath, satk, fh, conf)
        per_ext[e] = (H, K, allh, sath, fx, allk, satk)
    if multi:  # the extent: where some feasible offset makes the claim (or all) hold
        xe = np.array(exts)
        fe = np.array([per_ext[e][4].any() for e in exts])
        fh = float(xe[fe].max()) if fe.any() else np.nan
        for c in preds:
            add(
                "plate.half_extent_mm",
                "some feasible station offset",
                c,
                xe,
                np.array([per_ext[e][0][c].any() for e in exts]),
                np.array([per_ext[e][1][c].any() for e in exts]),
                fh,
            )
        add(
            "plate.half_extent_mm",
            "some feasible station offset",
            "ALL",
            xe,
            np.array([per_ext[e][2].any() for e in exts]),
            np.array([per_ext[e][5].any() for e in exts]),
            fh,
        )
        add(
            "plate.half_extent_mm",
            "some feasible station offset",
            "ALL_SATISFIABLE",
            xe,
            np.array([per_ext[e][3].any() for e in exts]),
            np.array([per_ext[e][6].any() for e in exts]),
            fh,
        )
    return cols
