"""Scoring of ``salsig_encoders``: the claim book ``claims.toml`` plus what the run made.

The paper-checks recompute Salsig's printed numbers from his own printed data
(:mod:`.printed`); the simulation rows only supply simulated values. Verdicts follow from the
claim book's rules (:mod:`sim.claims.book`)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from sim.claims.book import ClaimBook
from sim.claims.intervals import share_ci, spread, std_ci
from sim.claims.table import Sim, claim_rows, exact, plates
from sim.instruments import transforms2d as t2
from sim.studies.salsig import printed as pr
from sim.studies.salsig.wording import b8_printed, correction, level_text, sigma_set

BOOK = Path(__file__).with_name("claims.toml")


def load_book() -> ClaimBook:
    return ClaimBook.load(BOOK)


def s0_from_residuals(res, n_points: int = pr.N_POINTS) -> tuple[float, float, float]:
    """Unit-weight error sqrt(sum(v^2)/(2n - 6)) from printed residual magnitudes, and its
    range under their rounding (each |v| within half a unit of the last printed digit). Rows
    missing from the table are taken at the mean square of the printed ones (bounds: 0 and
    the largest printed magnitude)."""
    a = np.asarray(res, float) * pr.RES_UNIT
    h = 0.5 * pr.RES_UNIT
    miss = n_points - a.shape[0]
    dof = 2 * n_points - 6

    def s(v, fill):
        return math.sqrt((np.sum(v**2) + 2 * miss * fill) / dof)

    mid = s(a, np.mean(a**2))
    lo = s(np.maximum(a - h, 0.0), 0.0)
    hi = s(a + h, (a.max() + h) ** 2)
    return mid, lo, hi


def marks_layout() -> dict:
    """Similarity fit of a nominal 5 x 5 array (unit spacing) to FIG. 2's marks: the spacing
    (mm) and the rms placement per coordinate about the fitted array (mm)."""
    xy = np.asarray(pr.MARKS_XY)
    m = np.arange(xy.shape[0])
    nom = np.column_stack([m % 5 - 2.0, m // 5 - 2.0])  # 801-805 the bottom row, x increasing
    f = t2.fit_similarity(nom[None], xy[None])
    a, b = f.params[0, 0], f.params[0, 1]
    rms = math.sqrt(float((f.residuals**2).sum()) / (2 * xy.shape[0] - 4))
    ext = float(max(np.ptp(xy[:, 0]), np.ptp(xy[:, 1])))
    return {"spacing_mm": float(math.hypot(a, b)), "placement_rms_mm": rms, "extent_mm": ext}


def scored_ids(cfg: dict, book: ClaimBook) -> list[str]:
    """The ids :func:`score` builds: SX, SY, E of FIG. 2 (the grid) and FIG. 3 (the B8) from
    :func:`_decompositions`, and the vertical rms before and after the correction."""
    return [
        *(f"salsig.decompose_{f}.{q}" for f in ("grid", "b8") for q in ("SX", "SY", "E")),
        *(f"salsig.vertical_halved.rms_z_{tag}_um" for tag in ("before", "after")),
    ]


def _decompositions(dec: dict) -> dict[str, Sim]:
    """SX, SY, E of FIG. 2 and FIG. 3 recomputed from the printed A-F (``dec``: the rows of
    ``decompositions.parquet``)."""
    table = {}
    for i in range(len(dec["figure"])):
        f, q = dec["figure"][i], dec["quantity"][i]
        cid = ("salsig.decompose_grid." if f == "FIG. 2" else "salsig.decompose_b8.") + q.replace(
            "_arcsec", ""
        )
        v, lo, hi = dec["value"][i], dec["lo"][i], dec["hi"][i]
        dig = 3 if q == "E_arcsec" else 10
        table[cid] = exact(
            v,
            f"recomputed from the printed A-F: {v:.{dig}f} (printed "
            f"{dec['printed'][i]}); the 9-decimal rounding of A-F allows "
            f"{lo:.{dig}f} to {hi:.{dig}f}. SX = sqrt(A^2 + D^2), SY = sqrt(B^2 + E^2), "
            "E = pi/2 - (atan2(E, B) - atan2(D, A)), D taken negative (its sign is "
            "lost in the OCR).",
        )
    return table


def _printed_data(book: ClaimBook, cfg: dict) -> dict[str, Sim]:
    """The paper's printed residuals and marks recomputed: unit-weight errors, the marks'
    spacing, extent and placement, the digit in inches."""
    table = {}
    for cid, res, n_rows in (
        ("salsig.paper_check.s0_fig2_from_residuals", pr.FIG2_RES, 25),
        ("salsig.paper_check.s0_fig3_from_residuals", pr.FIG3_RES, 24),
    ):
        m, lo, hi = s0_from_residuals(res)
        table[cid] = exact(
            m,
            f"recomputed sqrt(sum(VX2^2 + VY2^2)/(2 x 25 - 6)) = {m:.5f} from the "
            f"{n_rows} printed rows"
            + ("" if n_rows == 25 else " (the missing row at their mean square)")
            + f"; their rounding allows {lo:.5f} to {hi:.5f}.",
        )
    lay = marks_layout()
    sx_printed = book.spec("salsig.recovery.SX")["ref"]
    table |= {
        "salsig.paper_check.mark_spacing_mm": exact(
            lay["spacing_mm"],
            "scale of a similarity fit of a regular 5 x 5 array to FIG. 2's "
            "coordinates of 801-825; tol: 'approximately' read as 5 %.",
        ),
        "salsig.paper_check.marks_inside_9in_mm": exact(
            lay["extent_mm"],
            f"largest extent of FIG. 2's marks in x or y; 9 in = {9 * pr.INCH_MM:.1f} mm.",
        ),
        "salsig.paper_check.digit_half_inch": exact(
            sx_printed / pr.INCH_MM,
            f"{sx_printed:.3f} mm / {pr.INCH_MM} mm per inch = {sx_printed / pr.INCH_MM:.6f} in.",
        ),
        "salsig.marks.placement_rms_mm": exact(
            lay["placement_rms_mm"],
            "rms per coordinate of FIG. 2's marks about the fitted regular array "
            f"(2n - 4 degrees of freedom): what the printed data support for the "
            f"unprinted input marks.placement_sd_mm (run: {cfg['marks.placement_sd_mm']:g} mm).",
        ),
    }
    return table


def _recovery(cfg: dict, rec: dict) -> dict[str, Sim]:
    """SX, SY, E and the unit-weight errors recovered over simulated calibrations, the
    detection power of E and SX - SY, and their Monte-Carlo sd."""
    design = (
        f"{cfg['marks.grid'] ** 2} marks, B8 error {cfg['b8.sigma_um']:g} um, comparator "
        f"{cfg['comparator.sigma_um']:g} um"
    )
    truth = "printed FIG. 3" if b8_printed(cfg) else "run's b8.*"
    table = {
        cid: plates(
            rec[key],
            f"recovered over simulated calibrations ({design}); the truth is the "
            f"{truth} value (input), so this shows the spread of one calibration: "
            f"sd {np.std(rec[key], ddof=1):.3g}.",
        )
        for cid, key in (
            ("salsig.recovery.SX", "SX"),
            ("salsig.recovery.SY", "SY"),
            ("salsig.recovery.E_arcsec", "E_arcsec"),
        )
    }
    table["salsig.recovery.s0_fig3_digits"] = plates(
        rec["s0_fig3_digits"],
        "a-posteriori unit-weight error of the B8 -> grid affine in the units of "
        "the observed system X2 (B8 digits), as the program's residuals VX2, VY2 "
        f"are ({design}); {sigma_set(cfg, 'b8.sigma_um', '.002')}.",
    )
    table["salsig.recovery.s0_fig2_mm"] = plates(
        rec["s0_fig2_mm"],
        "unit-weight error of the comparator -> grid affine (mm); "
        f"{sigma_set(cfg, 'comparator.sigma_um', '.003')}.",
    )
    for cid, key, what in (
        ("salsig.recovery.power_E", "detect_E", "E"),
        ("salsig.recovery.power_scale_diff", "detect_scale", "SY - SX"),
    ):
        m, ci = share_ci(rec[key])
        table[cid] = Sim(
            m,
            ci,
            note=f"share of simulated calibrations in which {what} "
            f"differs from zero at the {level_text(cfg)} level "
            f"({design}); see power.png.",
        )
    for cid, key in (
        ("salsig.recovery.sd_E_arcsec", "E_arcsec"),
        ("salsig.recovery.sd_scale_diff_ppm", "scale_diff_ppm"),
    ):
        s, lo, hi = std_ci(rec[key])
        table[cid] = Sim(
            float(s),
            (float(lo), float(hi)),
            note=f"Monte-Carlo sd over calibrations; the fit's own a-posteriori sd "
            f"(rms) is {np.sqrt(np.mean(rec['sd_' + key] ** 2)):.3g}, which ignores the "
            "error of the FIG. 2 transformation in the control coordinates.",
        )
    return table


def _zscale(cfg: dict, zs: dict) -> dict[str, Sim]:
    """The z encoder's scale fitted to the glass-scale elevations, and its standard error."""
    m, sp = spread(zs["se_S"] * 1e3)
    return {
        "salsig.z_scale.S": plates(
            zs["S"],
            f"H = S z + z0 fitted to {cfg['zscale.points']} elevations over "
            f"{cfg['zscale.range_mm']:g} mm with a {cfg['zscale.sigma_um']:g} um setting "
            "error (span and error not printed); the truth is an input.",
        ),
        "salsig.z_scale.se_S_um_per_digit": Sim(
            m,
            (float(sp[0]), float(sp[1])),
            "spread",
            note=f"standard error of S from the fit, um/digit ({cfg['zscale.points'] - 2} "
            f"degrees of freedom); the {cfg['zscale.s_mm_per_digit']:g} against "
            f"{cfg['b8.sx_mm_per_digit']:.4g} difference is "
            f"{abs(cfg['b8.sx_mm_per_digit'] - cfg['zscale.s_mm_per_digit']) * 1e3 / m:.0f} of them.",
        ),
    }


def _vertical(book: ClaimBook, cfg: dict, vt: dict) -> dict[str, Sim]:
    """The vertical test: residuals before and after the 12.500/12.700 correction."""
    vdesc = (
        f"{cfg['vertical.control']} control points, relief {cfg['vertical.relief_mm']:g} mm "
        f"rms, z error {cfg['vertical.sigma_z_um']:g} um (model; none printed: an example, the region decides)"
    )
    table = {
        "salsig.vertical_halved.rms_ratio": plates(
            vt["ratio"],
            f"rms vertical residual after / before multiplying z by {correction(cfg)}, "
            f"7-parameter conformal fit per model; {vdesc}. The spread over models is the "
            "'one plate' question: the paper's data were some models.",
        )
    }
    for cid, key in (
        ("salsig.vertical_halved.dramatic_vertical", "z"),
        ("salsig.vertical_halved.dramatic_horizontal", "xy"),
    ):
        x = vt[f"rms_{key}_before_um"] / vt[f"rms_{key}_after_um"]
        med, (lo, hi) = spread(x)
        table[cid] = Sim(
            float(med),
            (float(lo), float(hi)),
            "spread",
            note=f"rms {'vertical' if key == 'z' else 'horizontal'} residual before / "
            f"after, median and 95 % range over models; {vdesc}. 'Dramatic' is read as "
            f"a factor of at least {book.spec(cid)['ref']:g}.",
        )
    for tag in ("before", "after"):
        med, (lo, hi) = spread(vt[f"rms_z_{tag}_um"])
        table[f"salsig.vertical_halved.rms_z_{tag}_um"] = Sim(
            float(med),
            (float(lo), float(hi)),
            "spread",
            note=f"rms vertical control residual {tag} the correction, "
            "model um, median and 95 % range over models.",
        )
    return table


def score(cfg: dict, dec: dict, rec: dict, zs: dict, vt: dict) -> tuple[list[dict], ClaimBook]:
    """The claims rows of the run: the paper's printed numbers recomputed (``dec``: the
    decompositions), the calibration chain (``rec``), the z scale (``zs``) and the vertical
    test (``vt``) at the configured inputs."""
    book = load_book()
    table = {
        **_decompositions(dec),
        **_printed_data(book, cfg),
        **_recovery(cfg, rec),
        **_zscale(cfg, zs),
        **_vertical(book, cfg, vt),
    }
    return claim_rows(book, table), book
