"""Scoring of ``wolf_polynomial``'s claims (the claim book ``claims.toml`` holds the paper's
words and numbers; this module only supplies what the simulation and the recomputation from
the paper's own printed data produced, as a table ``{claim id: Sim}`` that
:func:`sim.claims.table.claim_rows` scores). Wolf & Pearsall 1976, seed
``000_668e60e68f004f98.txt``. Discrepancies in um.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from sim.claims.book import ClaimBook
from sim.claims.family import family_row
from sim.claims.intervals import bootstrap_ci
from sim.claims.table import Sim, claim_rows, exact, plates
from sim.mc.runner import chunk_rng
from sim.studies.wolf.tables import STATS, recomputation, summary
from sim.studies.wolf.wording import amplitudes, photograph, polynomial

BOOK = Path(__file__).with_name("claims.toml")
AXES = ("x", "y")

#: claim-id prefix -> the per-trial statistic of the main experiment it is scored on
SIMULATED = {
    "wolf.before.": "before",
    "wolf.after.": "after",
    "wolf.repeatability.": "repeat",
    "wolf.table2.": "mono",
}
HEADLINE = "wolf.headline.mean_vs_mono_um"
#: the cubic against the other degrees of the trade-off
CUBIC = "wolf.degree.cubic_excess_pct"
#: the printed inputs of the calibration, scored as exact ``input`` rows: a run that changes one
#: is not a test of the paper (sim.claims.rules.off_paper makes its predictions findings)
PRINTED_INPUTS = ("reading.n", "calib.n_sets", "calib.degree", "plate.spacing_mm", "reduce.ab_mm")
#: Table 2 decided as one statement (Holm over its 24 one-plate rows)
JOINT = "wolf.table2.joint_holm"


def load_book() -> ClaimBook:
    return ClaimBook.load(BOOK)


def stat_key(cid: str) -> str | None:
    """The per-trial column (``<experiment>.<stat>_<axis>_um``) a simulated claim is scored on."""
    if cid == JOINT:
        return None
    for pre, exp in SIMULATED.items():
        if cid.startswith(pre):
            return f"{exp}.{cid.rsplit('.', 1)[1]}"
    return None


def simulated(cid: str, stats: dict, n_inst: int, note: str = "") -> Sim:
    """What the main experiment gave for one simulated claim, from the per-trial statistics
    ``stats`` (one per instrument)."""
    return plates(stats[stat_key(cid)], note)


def is_mean_row(cid: str) -> bool:
    """One of Table 2's eight plate means (``wolf.table2.p00N.setK.mean_<axis>_um``): the
    family the headline is decided on."""
    return cid.startswith("wolf.table2.p") and ".mean_" in cid


def _simulated_notes(cfg: dict) -> dict[str, str]:
    """Claim-id prefix -> the note of its simulated rows."""
    T, S = cfg["trials"], cfg["calib.n_sets"]
    return {
        "wolf.before.": f"over the pooled {S} calibration sets after the non-redundant two-point "
        f"reduction; distribution over {T} simulated instruments. {amplitudes(cfg)}; "
        "these rows constrain the consistent region (consistent_region.parquet)",
        "wolf.after.": f"residuals of the {polynomial(cfg['calib.degree'], True)} fitted to "
        f"the {S} pooled sets; "
        f"distribution over {T} instruments",
        "wolf.repeatability.": f"{cfg['repeat.n_points']} points of a simulated "
        f"{photograph(cfg['repeat.format_mm'])} photograph "
        f"read {cfg['repeat.gap_weeks']:g} week(s) apart, each set "
        "corrected and fitted to its four fiducials; the default pointing "
        "sigma was chosen from these; they constrain the consistent region",
        "wolf.table2.": "Set 1 of the simulated photograph against a monocomparator reading "
        f"(sigma {cfg['mono.sigma_um']:g} um per coordinate, not printed), both "
        "fitted to the fiducials; every plate and set has the same simulated "
        "distribution",
    }


def _plate_stats(main: dict, T: int) -> dict[str, Sim]:
    """The independent plate and the calibration plate after (and before) the correction,
    and the similarity and affine fits of the uncorrected sets."""
    table = {
        f"wolf.{pre}.{s}_{ax}_um": plates(
            main[f"{pre}.{s}_{ax}_um"],
            f"{s} over the points; distribution over {T} instruments",
        )
        for pre in ("check_after", "plate_after", "plate_before")
        for s in ("max", "rms")
        for ax in AXES
    }
    for kind in ("similarity", "affine"):
        for ax in AXES:
            table[f"wolf.before_{kind}.rms_{ax}_um"] = plates(
                main[f"before_{kind}.rms_{ax}_um"],
                f"each set fitted to all grid points by a least-squares "
                f"{kind}, pooled sets; the fit absorbs part of the systematic "
                "error the paper wanted to preserve",
            )
    return table


def rows(cfg: dict, main: dict, t1: dict, t3: dict, degt: dict, book: ClaimBook) -> list[dict]:
    """Every claim of the book, scored: the simulated rows in the book's order, Table 2 as one
    statement (it reads their p values), the paper-checks, the plate statistics, the cubic."""
    T = cfg["trials"]
    notes = _simulated_notes(cfg)
    out = claim_rows(
        book,
        {
            cid: simulated(
                cid, main, T, next((v for k, v in notes.items() if cid.startswith(k)), "")
            )
            for cid in book.specs
            if stat_key(cid) is not None
        },
    )
    table2 = [r for r in out if r["claim"].startswith("wolf.table2.")]
    means = [r for r in table2 if is_mean_row(r["claim"])]
    families = [family_row(book, HEADLINE, means, n=T), family_row(book, JOINT, table2, n=T)]
    return (
        out
        + families
        + claim_rows(
            book,
            {
                **_table_checks(t1, t3),
                **_plate_stats(main, T),
                CUBIC: _cubic_excess(cfg, degt),
                **{
                    f"wolf.input.{k}": exact(float(cfg[k]), "the configuration")
                    for k in PRINTED_INPUTS
                },
            },
        )
    )


def scored_ids(cfg: dict, book: ClaimBook) -> list[str]:
    """The ids :func:`rows` scores, from the constants it loops over (no trial run, no table
    read: the tables' plates and photographs are named here, their rows only selected): the
    book's simulated rows whose statistic the experiment gives, the two families, the
    paper-checks of Tables 1-3, the plate statistics, the cubic and the printed inputs."""
    stats = {f"{s}_{ax}_um" for s in STATS for ax in AXES}
    return [
        *(c for c in book.specs if stat_key(c) is not None and c.rsplit(".", 1)[1] in stats),
        HEADLINE,
        JOINT,
        *(f"wolf.table1.p{p}.{s}_{ax}_um" for p in ("003", "005") for s in STATS for ax in AXES),
        *(
            f"wolf.table2_check.p{p}.set{st}.{s}_{ax}_um"
            for p in ("003", "005")
            for ax in AXES
            for st in (1, 2)
            for s in STATS
        ),
        *(f"wolf.table2_check.overall_{s}_um" for s in STATS),
        *(
            f"wolf.table3_check.p{p}.{s}_{ax}_um"
            for p in ("501", "505")
            for ax in AXES
            for s in STATS
        ),
        "wolf.summary.mean_range_check",
        *(
            f"wolf.{pre}.{s}_{ax}_um"
            for pre in ("check_after", "plate_after", "plate_before")
            for s in ("max", "rms")
            for ax in AXES
        ),
        *(f"wolf.before_{k}.rms_{ax}_um" for k in ("similarity", "affine") for ax in AXES),
        CUBIC,
        *(f"wolf.input.{k}" for k in PRINTED_INPUTS),
    ]


def _table_checks(t1: dict, t3: dict) -> dict[str, Sim]:
    """Paper-check rows: the summary lines recomputed from the paper's own printed data
    (Tables 1, 2 and 3, then the range of every recomputed mean line)."""
    table, means = {}, []
    for part in (_table1_checks(t1), _table2_checks(t1), _table3_checks(t3)):
        table |= part[0]
        means += part[1]
    m = np.array(means)
    table["wolf.summary.mean_range_check"] = Sim(
        interval="exact",
        elems=(m, m),
        note=f"the {m.size} mean lines of Tables 1-3 recomputed from the "
        f"paper's own data range from {m.min():.2f} to {m.max():.2f} um",
    )
    return table


def _table1_checks(t1: dict) -> tuple[dict[str, Sim], list[float]]:
    """Table 1's summary lines from its Set 1 and Set 2 coordinates; and its mean lines."""
    table, means = {}, []
    for plate in ("003", "005"):
        sel = t1["plate"] == plate
        for s in STATS:
            for ax in AXES:
                d = t1[f"d{ax}_sets_um"][sel]
                table[f"wolf.table1.p{plate}.{s}_{ax}_um"] = exact(
                    summary(d)[s],
                    "recomputed from Table 1's Set 1 and Set 2 coordinates: " + recomputation(d, s),
                )
        means += [summary(t1[f"d{ax}_sets_um"][sel])["mean"] for ax in AXES]
    return table, means


def _table2_checks(t1: dict) -> tuple[dict[str, Sim], list[float]]:
    """Table 2's summary lines (each Set minus the Foster coordinates) and the text's overall
    averages of them; and its mean lines."""
    table, means = {}, []
    line = {s: [] for s in STATS}
    for plate in ("003", "005"):
        sel = t1["plate"] == plate
        for ax in AXES:
            for st in (1, 2):
                d = t1[f"d{ax}_set{st}_foster_um"][sel]
                sm = summary(d)
                for s in STATS:
                    line[s].append(sm[s])
                    table[f"wolf.table2_check.p{plate}.set{st}.{s}_{ax}_um"] = exact(
                        sm[s],
                        f"recomputed from Set {st} (Table 1) minus the Foster coordinates "
                        "(Table 2): " + recomputation(d, s),
                    )
                means.append(sm["mean"])
    for s in STATS:
        v = line[s]
        table[f"wolf.table2_check.overall_{s}_um"] = exact(
            np.mean(v),
            f"mean of the {len(v)} recomputed {s} values "
            + ", ".join(f"{x:.2f}" for x in v)
            + f" = {np.mean(v):.3f}",
        )
    return table, means


def _table3_checks(t3: dict) -> tuple[dict[str, Sim], list[float]]:
    """Table 3's summary lines from its printed differences (the points where the coordinates
    disagree with them named); and its mean lines."""
    table, means = {}, []
    for ph in ("501", "505"):
        sel = t3["photo"] == ph
        for ax in AXES:
            d = t3[f"d{ax}_printed_um"][sel]
            dc = np.abs(t3[f"d{ax}_coord_um"][sel])
            odd = [
                f"point {p}: {a} from the coordinates, {b} printed"
                for p, a, b in zip(t3["point"][sel], dc, d)
                if a != b
            ]
            extra = ". The coordinates disagree with the printed difference at " + "; ".join(odd)
            for s in STATS:
                table[f"wolf.table3_check.p{ph}.{s}_{ax}_um"] = exact(
                    summary(d)[s],
                    "recomputed from Table 3's printed differences: "
                    + recomputation(d, s)
                    + (extra if odd else ""),
                )
            means.append(summary(d)["mean"])
    return table, means


def _cubic_excess(cfg: dict, degt: dict) -> Sim | None:
    """Excess (%) of the cubic's mean independent-plate rms over the best degree tried; None
    (no row: nothing compared) when the trade-off has no other degree the plate can estimate
    beside the cubic at the study's spacing and sets (a degree of more terms than the grid's
    points is dropped: 4 and 5 at 25 mm left the cubic alone, scored 0 % over itself)."""
    sp, ns = cfg["plate.spacing_mm"], cfg["calib.n_sets"]
    sel = (degt["spacing_mm"] == sp) & (degt["n_sets"] == ns)
    degs = np.unique(degt["degree"][sel]) if sel.any() else np.array([])
    if 3 not in degs:
        return None
    mat = np.stack([degt["check_rms_um"][sel & (degt["degree"] == d)] for d in degs], 1)
    ok = np.isfinite(mat).all(0)
    mat, dd = mat[:, ok], degs[ok]
    if 3 not in dd or len(dd) < 2:
        return None
    k3 = int(np.flatnonzero(dd == 3)[0])
    stat = lambda a: float((a[:, k3].mean() / a.mean(0).min() - 1) * 100)  # noqa: E731
    v, ci = bootstrap_ci(stat, mat, chunk_rng(cfg["seed"], 98, 0))
    m = mat.mean(0)
    return Sim(
        v,
        ci,
        note=(
            f"excess of the cubic's mean rms on an independent plate over the best degree tried "
            f"({sp:g} mm grid, {ns} sets, {cfg['trade.trials']} trials, bootstrap CI); mean rms by "
            "degree: "
            + ", ".join(f"{int(d)}: {x:.2f}" for d, x in zip(dd, m))
            + " um. The ranking "
            "depends on the assumed field families (inputs)"
        ),
    )
