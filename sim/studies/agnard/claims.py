"""Scoring of ``agnard_block``'s claims (seed ``003_5ce730a990a7ebc5.txt``).

The claims are data (``claims.toml`` beside this module: the paper's words, forms, printed
references and deciding widths); this module only supplies what the simulation produced and
the recomputations from the paper's printed tables (paper-checks). The verdicts follow from
the rules of :mod:`sim.claims.book`. Notes are computed from the run, never typed conclusions.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from sim.claims.book import ClaimBook
from sim.claims.family import family_row
from sim.claims.inference import Region
from sim.claims.table import Sim, exact, mc, plates
from sim.claims.table import claim_rows as table_rows
from sim.instruments.block import scanner as sc
from sim.instruments.block.layout import Block
from sim.studies.agnard.schema import model_sigmas, parallax_words, pixel_ground_m, recentre_words
from sim.studies.agnard.table1_rows import table1_rows

BOOK = Path(__file__).with_name("claims.toml")
AXES = ("x", "y", "xy", "z")
#: per block of Tables 2-3, the headline: its check points' X and Y as one Holm family
JOINT = {b: f"agnard.{b}.check_xy_holm" for b in ("control_5", "control_21")}
#: the members of each family
MEMBERS = {j: [f"agnard.{b}.check_{c}_cm" for c in ("x", "y")] for b, j in JOINT.items()}
#: the 5-control rows decided over the paper's program (its models with the projection
#: centres, SPACE-M) whose result without them changes their meaning: the finding that keeps
#: that result (decided over the layout points without centres, sim.studies.agnard.decide)
WITHOUT_CENTRES = {
    "agnard.control_5.check_z_cm": "agnard.finding.control_5_check_z_without_centres_cm",
}


#: how the digital rejections' note begins its word on the pass-point count (82 printed)
PASS_82 = "The paper's first pass names 82 pass points"


def load_book() -> ClaimBook:
    return ClaimBook.load(BOOK)


def ref(book: ClaimBook, cid: str) -> float:
    return float(book.spec(cid)["ref"])


def _where(p: float, x: np.ndarray) -> str:
    """Where the paper's value ``p`` falls in the simulated distribution ``x``."""
    return f"{100 * np.mean(np.asarray(x) < p):.0f} % of the simulated blocks lie below the paper's value"


def scored_ids(cfg: dict, book: ClaimBook) -> list[str]:
    """The ids :func:`claim_rows` builds: the scanner's gains (:func:`scanner_rows`), the
    book's inputs that are config keys and the control counts (:func:`input_rows`), Tables
    2-3 with their acceptance rows and families (:func:`tables23_rows`, :data:`JOINT`), the
    first pass (:func:`first_pass_rows`) and Table 1 (:func:`table1_rows`)."""
    blocks, pre = ("control_5", "control_21"), "agnard.input."
    return [
        *(f"agnard.scanner.gain_{d:.0f}dpi_pct" for d in (300.0, 600.0)),
        *(c for c in book.specs if c.startswith(pre) and c[len(pre) :] in cfg),
        *(f"{pre}{b}{n}_n" for b in blocks for n in ("", "_check")),
        *(f"agnard.{b}.{w}_{c}_cm" for b in blocks for w in ("ctrl", "check") for c in AXES),
        *(f"agnard.max_residual.{b}_{c}_cm" for b in blocks for c in ("xy", "z")),
        *JOINT.values(),
        *(f"agnard.first_pass.pass_{q}_cm" for q in ("xy", "z")),
        *(
            f"agnard.table1.{tag}_{w}_{c}{unit}"
            for w in ("ctrl", "check")
            for c in ("x", "y")
            for tag, unit in (("with", "_m"), ("without", "_m"), ("ratio", ""))
        ),
    ]


def scanner_rows(scan_t: dict, n_many: int) -> dict[str, Sim]:
    """The calibration's gains at 300 and 600 DPI, on the ``n_many`` control points of the
    ``control.many`` pass (the paper's 21)."""
    rows = {}
    dpi = np.asarray(scan_t["dpi"])
    cal = np.asarray(scan_t["calibration"])
    for d in (300.0, 600.0):
        cid = f"agnard.scanner.gain_{d:.0f}dpi_pct"
        i = np.flatnonzero((dpi == d) & (cal == "corrected"))
        if i.size == 0:  # not in tradeoff.dpis: nothing simulated, no row (not a 0 % gain)
            rows[cid] = None
            continue
        rows[cid] = mc(
            scan_t["gain_xy_pct"][i[0]],
            scan_t["gain_xy_pct_se"][i[0]],
            f"reduction of the check-point XY rms by the grid calibration at {d:g} DPI "
            f"({n_many} control; mean over {scan_t['trials'][i[0]]} blocks of the per-block relative "
            "gain, the same measurements with and without; 95 % confidence interval)",
        )
    return rows


def input_rows(book: ClaimBook, cfg: dict, block: Block, c5, c21) -> dict[str, Sim]:
    rows = {}
    for cid in book.specs:
        if cid.startswith("agnard.input.") and cid[len("agnard.input.") :] in cfg:
            rows[cid] = exact(float(cfg[cid[len("agnard.input.") :]]))
    ng = block.n_ground
    for cid, v in (
        ("control_5_n", c5.size),
        ("control_5_check_n", ng - c5.size),
        ("control_21_n", c21.size),
        ("control_21_check_n", ng - c21.size),
    ):
        rows[f"agnard.input.{cid}"] = exact(float(v), "control layouts control.few / control.many")
    pix = sc.pixel_um(cfg["scan.dpi"])
    rows["agnard.scanner.pixel_um"] = exact(
        pix, f"25.4 mm / {cfg['scan.dpi']:g} DPI = {pix:.2f} um"
    )
    return rows


def budget_rows(book: ClaimBook, cfg: dict) -> dict[str, Sim]:
    """The paper's precision budget recomputed from its own numbers, and what the
    simulation's pointing model gives."""
    pix_cm = 100 * pixel_ground_m(cfg)
    half = 0.5 * pix_cm
    fb = cfg["block.focal_mm"] / cfg["block.base_mm"]
    sxy, sz = model_sigmas(cfg)
    return {
        "agnard.budget.half_pixel_cm": exact(
            half,
            (
                f"half a pixel on the ground: 0.5 x {sc.pixel_um(cfg['scan.dpi']):.2f} um x "
                f"{cfg['block.scale']:g} = {half:.2f} cm"
            ),
        ),
        "agnard.budget.planimetry_cm": exact(
            half * np.sqrt(2),
            (
                f"radial planimetric error of {half:.2f} cm per coordinate: {half:.2f} x sqrt 2 = "
                f"{half * np.sqrt(2):.2f} cm"
            ),
        ),
        "agnard.budget.height_cm": exact(
            half * fb,
            (
                f"{half:.2f} cm x f / b = {half:.2f} x {cfg['block.focal_mm']:g} / "
                f"{cfg['block.base_mm']:g} = {half * fb:.2f} cm (the paper's own rounded 13 cm gives "
                f"{ref(book, 'agnard.budget.half_pixel_cm') * fb:.2f})"
            ),
        ),
        "agnard.budget.model_xy_cm": exact(
            100 * sxy,
            (
                f"the simulation's pointing model: a setting error of {cfg['measure.pointing_px']:g} "
                f"px per coordinate plus the mean of the two photos' x-parallax errors "
                f"({cfg['measure.parallax_px']:g} px / 2) gives {100 * sxy:.2f} cm per planimetric "
                f"model coordinate, against the half pixel alone ({half:.2f} cm) of the paper's "
                "budget, which counts the x-parallax error in height only"
            ),
        ),
        "agnard.budget.model_z_cm": exact(
            100 * sz,
            (
                f"x-parallax setting error {cfg['measure.parallax_px']:g} px x f / b = "
                f"{100 * sz:.2f} cm in height ({parallax_words(cfg)})"
            ),
        ),
    }


def table_note(cfg: dict, book: ClaimBook, cid: str, lay: str, ctrl, n_chk: int, x, alt=None):
    what = (
        "model-point residuals at control points (transformed model minus adjusted "
        "coordinates, as an independent-model program lists them)"
        if ".ctrl_" in cid
        else "check-point errors (adjusted minus true)"
    )
    p = ref(book, cid)
    tol = book.spec(cid)["tol"]
    note = (
        f"rms of the {what} of one block ({lay} layout, {len(ctrl)} control + {n_chk} check; "
        f"weights control {cfg['weights.control_xy']:g}/{cfg['weights.control_z']:g}, model "
        f"points {cfg['weights.pass']:g}), scanner-corrected measurements; median and 95 % of "
        f"{len(x)} blocks; {_where(p, x)}; tolerance {tol:g} cm "
        f"({100 * tol / p:.0f} % of the paper's value)"
        if p
        else ""
    )
    if alt is not None:
        note += (
            f". Read instead as adjusted minus given control coordinates: median "
            f"{100 * np.median(alt):.1f} cm"
        )
    return note


def quadrature_check(book: ClaimBook, cid: str) -> Sim:
    """The paper's XY as the quadrature of its own printed X and Y (a paper-check): the value
    from the printed numbers, the note with the range their rounding allows (the claim's tol
    is that range's half-width)."""
    x, y = (ref(book, cid.replace("_xy_", f"_{c}_")) for c in ("x", "y"))
    lo, hi = np.hypot(x - 0.5, y - 0.5), np.hypot(x + 0.5, y + 0.5)
    return exact(
        np.hypot(x, y),
        f"recomputed from the paper's own X and Y: sqrt({x:g}^2 + {y:g}^2) = "
        f"{np.hypot(x, y):.2f} cm, {lo:.2f}-{hi:.2f} cm over their printed rounding",
    )


def tables23_rows(book: ClaimBook, cfg: dict, block: Block, sim: dict, c5, c21) -> dict[str, Sim]:
    rows = {}
    for name, lay, ctrl in (
        ("control_5", cfg["control.few"], c5),
        ("control_21", cfg["control.many"], c21),
    ):
        n_chk = block.n_ground - ctrl.size
        for where in ("ctrl", "check"):
            for c in AXES:
                cid = f"agnard.{name}.{where}_{c}_cm"
                if c == "xy":  # the quadrature of X and Y: the paper's arithmetic
                    rows[cid] = quadrature_check(book, cid)
                    continue
                x = 100 * sim[f"layout_{lay}.{where}_{c}_m"]
                alt = sim[f"layout_{lay}.ctrl_given_{c}_m"] if where == "ctrl" else None
                rows[cid] = plates(x, table_note(cfg, book, cid, lay, ctrl, n_chk, x, alt))
                if cid in WITHOUT_CENTRES:  # at the configured inputs the same blocks
                    rows[WITHOUT_CENTRES[cid]] = rows[cid]
        for c in ("xy", "z"):
            rows[f"agnard.max_residual.{name}_{c}_cm"] = acceptance(
                book, cfg, name, lay, ctrl, c, sim
            )
    return rows


def family_rows(book: ClaimBook, rows: list[dict], n: int) -> list[dict]:
    """``rows`` with the joint X, Y rows of Tables 2-3 after their XY paper-checks (Holm over
    the two one-plate rows' Monte-Carlo p, each over the ``n`` main blocks, at the run's
    configured inputs; the 5-control one is then decided over the layout region)."""
    by = {r["claim"]: r for r in rows}
    fam = {j: family_row(book, j, [by[m] for m in MEMBERS[j]], n=n) for j in JOINT.values()}
    after = {j.replace("_holm", "_cm"): r for j, r in fam.items()}  # next to the XY check
    return [x for r in rows for x in ([r, after[r["claim"]]] if r["claim"] in after else [r])]


def acceptance(book: ClaimBook, cfg: dict, name: str, lay: str, ctrl, c: str, sim: dict) -> Sim:
    """The acceptance limit on the control residuals (21 cm planimetry, 16 cm height at
    1/6 200), applied to one block's control rms, radial XY or Z (the paper's own evidence
    that it met the limit is its tabulated control rms); the largest single residual is
    given in the note for information."""
    cid = f"agnard.max_residual.{name}_{c}_cm"
    lim = ref(book, cid)
    x = 100 * sim[f"layout_{lay}.ctrl_{c}_m"]
    mx = 100 * sim[f"layout_{lay}.ctrl_max_{c}_m"]
    return plates(
        x,
        (
            f"rms of the {'radial planimetric' if c == 'xy' else 'height'} model-point residuals "
            f"at the {ctrl.size} control points of one block ({lay} layout); median and 95 % of "
            f"{x.size} blocks; {100 * np.mean(x <= lim + 0.5):.0f} % of the blocks meet the "
            f"{lim:g} cm limit (the rule: holds iff the 95 % spread lies under it, fails iff "
            f"wholly above). For information, the largest single residual has median "
            f"{np.median(mx):.1f} cm ({100 * np.mean(mx <= lim + 0.5):.0f} % of blocks within "
            f"{lim:g} cm)"
        ),
    )


def first_pass_rows(book: ClaimBook, cfg: dict, block: Block, sim: dict) -> dict[str, Sim]:
    pix_cm = 100 * pixel_ground_m(cfg)
    n_pass = int(block.is_pass.sum())
    rows = {}
    for q, lab in (
        ("xy", "radial XY (the paper's 'planimetry': its Tables' XY column is the radial rms)"),
        ("z", "Z"),
    ):
        cid = f"agnard.first_pass.pass_{q}_cm"
        x = 100 * sim[f"first.pass_{q}_m"]
        extra = ""
        if q == "xy":
            extra = (
                f"; per coordinate X {100 * np.median(sim['first.pass_x_m']):.1f} cm, Y "
                f"{100 * np.median(sim['first.pass_y_m']):.1f} cm"
            )
        rows[cid] = plates(
            x,
            f"rms of the model-point residuals at the {n_pass} pass points, {lab}{extra}; "
            f"{cfg['control.many']} control at weight {cfg['weights.first_pass_control']:g} "
            f"against {cfg['weights.first_pass_pass']:g}; median and 95 % of {x.size} blocks; "
            f"{_where(ref(book, cid), x)}",
        )
    # the paper's own budget turns a ground pixel into planimetry (radial: x sqrt 2, its
    # "19 centimetres") and into height (x f / b, its "22 centimetres"); a pixel "in
    # planimetry" and "in altimetry" is read the same way (claims.toml says why)
    fb = cfg["block.focal_mm"] / cfg["block.base_mm"]
    for cid, src, k, how in (
        ("agnard.first_pass.quarter_pixel", "agnard.first_pass.pass_xy_cm", np.sqrt(2), "sqrt 2"),
        (
            "agnard.first_pass.third_pixel",
            "agnard.first_pass.pass_z_cm",
            fb,
            f"f / b = {cfg['block.focal_mm']:g} / {cfg['block.base_mm']:g}",
        ),
    ):
        cm = ref(book, src)
        rows[cid] = exact(
            cm / (pix_cm * k),
            f"recomputed from the paper's own numbers: {cm:g} cm / ({pix_cm:.2f} cm "
            f"ground pixel ({sc.pixel_um(cfg['scan.dpi']):.2f} um x {cfg['block.scale']:g})"
            f" x {how} = {pix_cm * k:.2f} cm) = {cm / (pix_cm * k):.3f} pixel; per "
            f"ground coordinate alone it would be {cm / pix_cm:.3f}",
        )
    return rows


def rejection_rows(
    book: ClaimBook, cfg: dict, block: Block, sim: dict, pug: dict
) -> dict[str, Sim]:
    n_pass = int(block.is_pass.sum())
    rej = sim["snoop_digital.rejected"].astype(float)
    sens = ", ".join(f"{r:g} px: {np.mean(s):.1f} %" for r, s in pug.items())
    sh = sim["snoop_mechanical.share_pct"]
    return {
        "agnard.pass_rejections.digital": plates(
            rej,
            (
                f"pass points (of {n_pass}) removed by iterative data snooping (Baarda w-test, "
                f"alpha {cfg['snoop.alpha']:g}, {cfg['snoop.test']}-test) under digital pugging; "
                f"{100 * np.mean(rej == 0):.0f} % of {rej.size} blocks lose none; median a-posteriori "
                f"sigma0 {np.median(sim['snoop_digital.sigma0']):.2f}. {PASS_82}; the simulated "
                f"block's regular pattern has {n_pass} "
                "(whole rows per strip at the inner nadirs and the sidelap ties: 62, 76, 90 "
                "with 3, 4, 5 rows on the paper's 2 x 8 block, so 82 is not buildable with "
                "it and the lost Figures 4-5 print no other; not_reproduced.parquet). The "
                "row decides the share of blocks that lose none, so the count enters only "
                "through it"
            ),
        ),
        "agnard.pass_rejections.mechanical_pct": plates(
            sh,
            (
                f"share of the {n_pass} pass points removed under mechanical pugging ("
                f"{'no gross errors' if not cfg['pugging.gross_rate'] else 'gross errors'} at "
                f"pugging.gross_rate {cfg['pugging.gross_rate']:g}; hole transfer "
                f"{cfg['pugging.transfer_um']:g} um, re-centring {cfg['pugging.recentre_px']:g} px "
                f"per photo: {recentre_words(cfg)}); {_where(ref(book, 'agnard.pass_rejections.mechanical_pct'), sh)}; "
                f"mean share against the re-centring error: {sens}"
            ),
        ),
    }


def anisotropy_samples(cfg: dict, sim: dict) -> np.ndarray:
    """Per block, the geometric mean of Y/X over the simulated counterparts of the paper's
    eight (X, Y) pairs (Table 1 without/with, control and check; Tables 2-3)."""
    keys = [f"without.{w}" for w in ("ctrl", "check")]
    keys += [f"layout_{cfg['control.table1']}.{w}" for w in ("ctrl", "check")]
    keys += [
        f"layout_{lay}.{w}"
        for lay in (cfg["control.few"], cfg["control.many"])
        for w in ("ctrl", "check")
    ]
    r = np.stack([np.log(sim[k + "_y_m"] / sim[k + "_x_m"]) for k in keys])
    return np.exp(r.mean(0))


def anisotropy_rows(book: ClaimBook, cfg: dict, sim: dict) -> dict[str, Sim]:
    g = anisotropy_samples(cfg, sim)
    yx21 = (
        sim[f"layout_{cfg['control.many']}.check_y_m"]
        / sim[f"layout_{cfg['control.many']}.check_x_m"]
    )
    return {
        "agnard.anisotropy.y_over_x": plates(
            g,
            (
                "a finding (the pairs are scored in their own rows); per block the geometric mean of Y/X over the eight simulated counterparts; "
                f"{_where(ref(book, 'agnard.anisotropy.y_over_x'), g)}; 21-control check points alone: "
                f"median Y/X {np.median(yx21):.2f}; the simulated pointing error is "
                f"{cfg['measure.pointing_px']:g} px in both x and y, the scanner deformation peaks at "
                f"{cfg['scan.max_y_um']:g} um in y and {cfg['scan.max_x_um']:g} um in x"
            ),
        ),
    }


def claim_rows(
    cfg: dict,
    block: Block,
    sim: dict,
    c5,
    c21,
    scan_t: dict,
    pug: dict,
    book: ClaimBook,
    scanner: Region,
    scanner_stats: list[dict],
) -> list[dict]:
    """Every claim of the book, scored once (Table 1 over the ``scanner`` region, with the
    per-vector statistics ``scanner_stats``)."""
    table = {
        **scanner_rows(scan_t, len(c21)),
        **input_rows(book, cfg, block, c5, c21),
        **budget_rows(book, cfg),
        **tables23_rows(book, cfg, block, sim, c5, c21),
        **first_pass_rows(book, cfg, block, sim),
        **rejection_rows(book, cfg, block, sim, pug),
        **anisotropy_rows(book, cfg, sim),
    }
    rows = table1_rows(book, scanner, scanner_stats) + table_rows(book, table)
    rows = family_rows(book, rows, cfg["trials"])
    for r in rows:  # an unbounded side of a bound's zone is "no number" (null), not infinity
        for k in ("zone_low", "zone_high"):
            if not np.isfinite(r[k]):
                r[k] = float("nan")
    return rows
