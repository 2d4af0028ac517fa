"""Configuration schema of ``agnard_block`` (seed ``003_5ce730a990a7ebc5.txt``, Agnard,
Nolette & Gagnon): block geometry, scanner, measurement, pugging, weights, control layouts,
data snooping, trade-offs and the region of the unprinted five-point control layout; the
cross-key rules (:func:`check`) and the small derived quantities every part uses (:func:`block_of`,
:func:`model_sigmas`, the weights, the layouts of the region). Units: lengths in m on the
ground, mm and um on the photo, px of the scan."""

from __future__ import annotations

import numpy as np

from sim.instruments.block import scanner as sc
from sim.instruments.block.layout import (
    CONTROL_PATTERNS,
    Block,
    control_targets,
    make_block,
    select_control,
)
from sim.mc.config import COMMON, ConfigError, Field
from sim.mc.read_when import unless
from sim.mc.schema_helpers import (
    compared,
    count,
    counts,
    positive,
    printed,
    real,
    reals,
    region_seed,
)
from sim.studies.agnard.centre import check_centre_points
from sim.studies.agnard.datum import check_datum, region_insets
from sim.studies.agnard.strips import check_strip_overlap

SEED = "003_5ce730a990a7ebc5.txt"
NAME = "agnard_block"

SCHEMA = {
    **COMMON,
    "trials": count(500, "Monte-Carlo trials of the 2 x 8 block", 2, 100_000_000),
    "chunk": count(50, "trials per chunk (each chunk has its own spawned stream)", 1, 1_000_000),
    "block.strips": count(2, "strips (paper: two)", 1, 50, input=True),
    "block.models": count(8, "models per strip (paper: eight)", 1, 200, input=True),
    "block.scale": real(6200.0, "photo scale number (paper: 1/6 200)", 100.0, 1e6, input=True),
    "block.focal_mm": real(
        152.0, "camera constant (paper: 152 mm)", 10.0, 1000.0, unit="mm", input=True
    ),
    "block.base_mm": real(
        90.0, "base at photo scale (paper: 90 mm)", 10.0, 200.0, unit="mm", input=True
    ),
    "block.format_mm": real(230.0, "photo format side", 50.0, 500.0, unit="mm"),
    "block.usable": real(0.92, "share of the half format where points are measured", 0.3, 1.0),
    "block.sidelap": real(0.3, "sidelap between strips", 0.05, 0.8),
    "block.ground_points": count(
        178, "signalised test-field points (paper: 178)", 8, 100_000, input=True
    ),
    "block.pass_rows": count(4, "pass-point rows per strip", 2, 20),
    "block.relief_m": real(20.0, "terrain relief (peak to peak)", 0.0, 500.0, unit="m"),
    "block.layout_seed": count(7, "seed of the test-field layout (fixed, not a trial stream)", 0),
    "scan.dpi": real(
        600.0, "scan resolution (paper: 600 DPI, pixel 42 um)", 50.0, 10000.0, input=True
    ),
    "scan.max_x_um": real(
        20.0,
        "largest scanner deformation in x (paper: +-20 um)",
        0.0,
        1000.0,
        unit="um",
        input=True,
    ),
    "scan.max_y_um": real(
        40.0,
        "largest scanner deformation in y (paper: +-40 um)",
        0.0,
        1000.0,
        unit="um",
        input=True,
    ),
    "scan.stepper_share": real(
        0.3, "periodic stepper term of dy relative to its polynomial part", 0.0, 10.0
    ),
    "scan.wavelength_mm": real(60.0, "period of the stepper term", 1.0, 1000.0, unit="mm"),
    "scan.grid_mm": real(10.0, "spacing of the scanned calibration grid", 1.0, 230.0, unit="mm"),
    "scan.grid_sigma_px": real(
        0.1, "centring error of a grid node on the scan", 0.0, 10.0, unit="px"
    ),
    "scan.fiducial_mm": real(
        110.0,
        "corner fiducials at (+-d, +-d) (on the photo, at most half block.format_mm: checked on load)",
        10.0,
        250.0,
        unit="mm",
    ),
    "scan.fiducial_sigma_px": real(0.25, "centring error of a fiducial mark", 0.0, 10.0, unit="px"),
    "measure.pointing_px": positive(
        0.5,
        "planimetric setting error per coordinate (paper: half a pixel, '13 cm on the ground')",
        20.0,
        unit="px",
        input=True,
    ),
    # (tenth sweep) a parallax error or a pass weight of the smallest double (5e-324) passed
    # check and overflowed the snooping weights (1 / sigma^2, control / pass) at run time: at
    # least 1e-6 of the paper's value
    "measure.parallax_px": real(
        0.5,
        "x-parallax setting error (paper: 13 cm x f/B = 22 cm in height; at least 1e-6 of it)",
        lo=5e-7,
        hi=20.0,
        unit="px",
        input=True,
    ),
    "measure.control_sigma_m": real(
        0.02, "error of the surveyed control coordinates", 0.0, 10.0, unit="m"
    ),
    "pugging.transfer_um": real(
        10.0, "mechanical: error of a drilled hole (transfer to each photo)", 0.0, 1000.0, unit="um"
    ),
    "pugging.recentre_px": real(
        0.5, "mechanical: re-centring the mark in a hole, per measurement", 0.0, 20.0, unit="px"
    ),
    "pugging.gross_rate": real(
        0.0,
        "mechanical: chance per model point that a hole is missed on one photo (off by default)",
        0.0,
        1.0,
    ),
    "pugging.gross_px": unless(
        reals(
            [2.0, 6.0],
            "mechanical: range of a missed hole's error",
            0.0,
            1000.0,
            min_len=2,
            unit="px",
        ),
        "pugging.gross_rate",
        0.0,
    ),
    "weights.pass": real(
        0.1, "weight of model points (paper: 0.1; at least 1e-6 of it)", lo=1e-7, input=True
    ),
    "weights.control_xy": positive(3.0, "weight of control in planimetry (paper: 3)", input=True),
    "weights.control_z": positive(2.0, "weight of control in height (paper: 2)", input=True),
    "weights.first_pass_control": positive(
        0.1, "first pass: control weight (paper: 0.1)", input=True
    ),
    "weights.first_pass_pass": positive(
        1.0, "first pass: model-point weight (paper: 1.0)", input=True
    ),
    "control.table1": Field(
        "full", "str", "control layout of the Table 1 adjustments", choices=CONTROL_PATTERNS
    ),
    "control.few": Field(
        "five", "str", "layout of the 5-control pass (Table 3 rows)", choices=CONTROL_PATTERNS
    ),
    "control.many": Field(
        "full", "str", "layout of the 21-control pass (Table 2 rows)", choices=CONTROL_PATTERNS
    ),
    # read only when the snooping removes points: at snoop.max_reject = 0 no test decides
    # anything (the rejection rows are undecidable by construction: decide.without_snooping)
    "snoop.alpha": unless(
        real(0.001, "significance level of one w-test (two-sided)", 1e-09, 0.5),
        "snoop.max_reject",
        0,
    ),
    "snoop.test": unless(
        Field(
            "w",
            "str",
            "w: Baarda's w-test with the a-priori sigma0; tau: Pope's "
            "test with the block's a-posteriori sigma0",
            choices=("w", "tau"),
        ),
        "snoop.max_reject",
        0,
    ),
    "snoop.max_reject": count(25, "most pass points removed per block", 0, 1000),
    "tradeoff.dpis": compared(
        reals([300.0, 600.0, 1200.0], "scan resolutions compared", 50.0, 10000.0)
    ),
    "tradeoff.trials": count(
        150, "trials per scan resolution and per re-centring error", 2, 1_000_000
    ),
    "tradeoff.layouts": compared(
        Field(
            list(CONTROL_PATTERNS),
            "list[str]",
            "control layouts compared",
            choices=CONTROL_PATTERNS,
            min_len=1,
        )
    ),
    "tradeoff.block_strips": counts([1, 2, 2, 3, 4, 4], "strips of the blocks compared", 1, 50),
    "tradeoff.block_models": counts(
        [8, 4, 8, 12, 16, 24],
        "models per strip of the blocks compared (same length as block_strips)",
        1,
        200,
    ),
    "tradeoff.recentre_px": compared(
        reals(
            [0.25, 0.5, 0.75],
            "mechanical re-centring errors for the rejection sensitivity",
            0.0,
            20.0,
            unit="px",
        )
    ),
    "tradeoff.block_trials": count(30, "trials per block size", 2, 1_000_000),
    "tradeoff.block_control": Field(
        "perimeter", "str", "control layout of the block-size runs", choices=CONTROL_PATTERNS
    ),
    "tradeoff.centre_points": count(
        10,
        "check points nearest the block centre used for 'accuracy at the centre' (at most half "
        "the check points of each block compared: checked on load)",
        1,
        10_000,
    ),
    "region.trials": count(
        150, "simulated blocks per input vector of the region (region.toml)", 2, 1_000_000
    ),
    "region.points": count(8, "five-point layouts of the region's space-filling design", 2, 64),
    "region.seed": region_seed(1992),
    "table1.points": count(
        16, "scanner vectors of the Table 1 region's space-filling design (scanner.toml)", 2, 256
    ),
    "table1.trials": count(
        48,
        "simulated blocks per scanner vector of the Table 1 region, the same blocks for every "
        "vector and the configured scanner (the paired shift of the 21-control rows)",
        2,
        10_000,
    ),
    "table1.rounds": count(
        0, "boundary refinement rounds of the Table 1 region (none while it is empty)", 0, 5
    ),
}

#: the keys whose default is a number the paper prints for its own setup and that no exact
#: input row (agnard.input.*) already holds (seed 003: the x-parallax setting error, half a
#: pixel, "22 centimetres in height"): a run with another value is off the paper's setup,
#: its predictions findings (sim.claims.rules.printed_differs). The block (strips, models,
#: ground points, scale, focal length, base), the scan, the pointing and the weights are
#: exact input rows of the claim book; the format, the overlaps and the pass rows are not
#: printed, nor are the inputs the regions explore (region.toml, scanner.toml)
PRINTED = ("measure.parallax_px",)
SCHEMA.update({k: printed(SCHEMA[k]) for k in PRINTED})


def check(cfg: dict) -> None:
    """Cross-key rules, and the bounds that follow from what the model can compute."""
    gp = cfg["pugging.gross_px"]
    if len(gp) != 2 or gp[0] > gp[1]:
        raise ConfigError("pugging.gross_px", "must be [min, max] with min <= max")
    if len(cfg["tradeoff.block_strips"]) != len(cfg["tradeoff.block_models"]):
        raise ConfigError("tradeoff.block_models", "needs as many entries as tradeoff.block_strips")
    if cfg["block.base_mm"] >= 0.5 * cfg["block.format_mm"] * cfg["block.usable"]:
        raise ConfigError(
            "block.base_mm",
            "the base must be shorter than half the usable "
            "format (endlap over 50 %), or consecutive models share no points "
            "and the strip falls apart",
        )
    if cfg["scan.fiducial_mm"] > 0.5 * cfg["block.format_mm"]:
        raise ConfigError(
            "scan.fiducial_mm",
            f"the corner fiducials at +-{cfg['scan.fiducial_mm']:g} mm lie off the "
            f"{cfg['block.format_mm']:g} mm photo (block.format_mm): at most half the format",
        )
    if cfg["block.strips"] * cfg["block.models"] < 2:
        raise ConfigError("block.models", "a block needs at least two models")
    check_strip_overlap(cfg)
    # the block's visibility table (points x models) grows with the square of the models
    for key, strips, models in [
        ("block.models", [cfg["block.strips"]], [cfg["block.models"]]),
        ("tradeoff.block_models", cfg["tradeoff.block_strips"], cfg["tradeoff.block_models"]),
    ]:
        for s_, m_ in zip(strips, models):
            if s_ * m_ > MAX_MODELS:
                raise ConfigError(
                    key,
                    f"a block of {s_} x {m_} = {s_ * m_} models is more than the simulated block "
                    f"builds ({MAX_MODELS}: its table of which point each model sees grows with "
                    "the square of the models)",
                )
    # memory of the largest adjustment: trials x observation pairs x 7 x 7 doubles per chunk
    try:
        block = block_of(cfg)
    except ValueError as e:
        raise _relief_error(cfg, e) from None
    for key in ("control.table1", "control.few", "control.many"):
        n = control_targets(block, cfg[key]).shape[0]
        if n > block.n_ground:
            raise ConfigError(
                "block.ground_points",
                f"{cfg[key]!r} control ({key}) needs {n} points but the block has {block.n_ground}",
            )
    if not block.is_pass.any():
        raise ConfigError(
            "block.pass_rows",
            "the block has no pass points (no point seen by two "
            "models): raise block.pass_rows or the overlaps",
        )
    # before the datum's check, which adjusts the whole block for each layout (a block of
    # 34,447 points refused here took 47 s of CPU there first, minutes on a loaded machine)
    pairs = int((np.bincount(block.obs_point).astype(np.int64) ** 2).sum())
    if cfg["chunk"] * pairs * 49 * 8 > 2e9:
        raise ConfigError(
            "chunk",
            f"a chunk of {cfg['chunk']} blocks needs "
            f"{cfg['chunk'] * pairs * 49 * 8 / 1e9:.1f} GB for its normal "
            "equations; lower chunk",
        )
    check_centre_points(cfg, block)
    names = [cfg["control.table1"], cfg["control.few"], cfg["control.many"]]
    layouts = {n: select_control(block, n) for n in dict.fromkeys(names + cfg["tradeoff.layouts"])}
    for u in region_insets():  # the region's five-point layouts (region.toml)
        layouts[f"the region's five-point layout, inset {u:g}"] = five_control(block, u)
    paper = {k: SCHEMA[k].default for k in SCHEMA if k.startswith("weights.")}
    check_datum(cfg, block, paper, layouts)


def _relief_error(cfg: dict, e: ValueError) -> ConfigError:
    """The main block's builder's refusal, with the flying height the relief stands against:
    ``block.scale = 100`` (15.2 m above the ground) was refused as ``block.relief_m`` at its
    default 20 m, "lower the relief", naming no key the user set (P44)."""
    relief, h = cfg["block.relief_m"], cfg["block.focal_mm"] * cfg["block.scale"] / 1000.0
    key = "block.relief_m"
    if relief == SCHEMA[key].default:  # the relief as it was: the flying height changed
        key = "block.scale" if cfg["block.scale"] != SCHEMA["block.scale"].default else key
    return ConfigError(
        key,
        f"{e} ({relief:g} m of relief, block.relief_m, under a flying height of {h:g} m, "
        "block.focal_mm x block.scale); or raise block.scale",
    )


#: the most models (strips x models per strip) of a simulated block: 1000 models see about
#: 8,000 points, a visibility table of 128 MB (10,000 models asked for 12 GB in `sim check`)
MAX_MODELS = 1000


def block_of(
    cfg: dict, strips: int | None = None, models: int | None = None, density: float | None = None
) -> Block:
    """The simulated test field and block (fixed for a run: ``block.layout_seed``)."""
    return make_block(
        strips or cfg["block.strips"],
        models or cfg["block.models"],
        scale=cfg["block.scale"],
        focal_mm=cfg["block.focal_mm"],
        base_mm=cfg["block.base_mm"],
        format_mm=cfg["block.format_mm"],
        sidelap=cfg["block.sidelap"],
        usable=cfg["block.usable"],
        n_ground=cfg["block.ground_points"],
        ground_density=density,
        pass_rows=cfg["block.pass_rows"],
        relief_m=cfg["block.relief_m"],
        layout_seed=cfg["block.layout_seed"],
    )


def pixel_ground_m(cfg: dict, dpi: float | None = None) -> float:
    """One scan pixel on the ground (m)."""
    return sc.pixel_um(dpi or cfg["scan.dpi"]) * 1e-6 * cfg["block.scale"]


def model_sigmas(cfg: dict, dpi: float | None = None) -> tuple[float, float]:
    """A-priori sigma (m) of a model coordinate in planimetry and height of a re-pointed
    point: ``m_b p sqrt(s_p^2 + s_x^2 / 4)`` (the setting error plus the mean of the two
    photos' parallax errors) and ``(f / b) m_b p s_x``, with ``p`` the pixel, ``s_p`` the
    planimetric setting and ``s_x`` the x-parallax setting error (px)."""
    pix = pixel_ground_m(cfg, dpi)
    sp, sx = cfg["measure.pointing_px"], cfg["measure.parallax_px"]
    return (
        float(np.hypot(sp, sx / 2) * pix),
        float(cfg["block.focal_mm"] / cfg["block.base_mm"] * sx * pix),
    )


def paper_weights(cfg: dict, first_pass: bool = False):
    """(model-point weights (3,), control weights (3,)) as the paper sets them."""
    if first_pass:
        wp, wc = cfg["weights.first_pass_pass"], cfg["weights.first_pass_control"]
        return np.full(3, wp), np.full(3, wc)
    return (
        np.full(3, cfg["weights.pass"]),
        np.array([cfg["weights.control_xy"]] * 2 + [cfg["weights.control_z"]]),
    )


def snoop_weights(cfg: dict):
    """Weights 1/sigma^2 for data snooping: model points from the pointing precision
    (:func:`model_sigmas`), control with the paper's control/pass weight ratios."""
    sxy, sz = model_sigmas(cfg)
    w = np.array([1 / sxy**2, 1 / sxy**2, 1 / sz**2])
    r = np.array([cfg["weights.control_xy"]] * 2 + [cfg["weights.control_z"]]) / cfg["weights.pass"]
    return w, w * r


def five_targets(block: Block, inset: float) -> np.ndarray:
    """A five-point layout of the region (5, 2): the corners of the ``five`` pattern moved inwards
    along the strips by ``inset`` times the block length, and the centre."""
    t = control_targets(block, "five")
    x0, x1 = t[:4, 0].min(), t[:4, 0].max()
    d = inset * (x1 - x0)
    out = t.copy()
    out[:4, 0] = np.where(t[:4, 0] < 0.5 * (x0 + x1), t[:4, 0] + d, t[:4, 0] - d)
    return out


def nearest_points(block: Block, targets: np.ndarray) -> np.ndarray:
    """Indices of distinct signalised points nearest the targets (greedy, in order)."""
    g = block.points[: block.n_ground, :2]
    chosen: list[int] = []
    for p in targets:  # a handful of targets
        d = np.hypot(*(g - p).T)
        d[chosen] = np.inf
        chosen.append(int(np.argmin(d)))
    return np.array(sorted(chosen))


def five_control(block: Block, inset: float) -> np.ndarray:
    return nearest_points(block, five_targets(block, inset))


def recentre_words(cfg: dict) -> str:
    """Why ``pugging.recentre_px`` (unprinted) has its value: the default is set so the share
    of pass points mechanical pugging removes matches the paper's; a run with another value
    says so rather than claim the match."""
    key = "pugging.recentre_px"
    if cfg[key] == SCHEMA[key].default:
        return "unprinted, set so the share matches the paper: an input"
    return (
        f"unprinted: this run's {cfg[key]:g} px, the default {SCHEMA[key].default:g} px is set "
        "so the share matches the paper"
    )


def parallax_words(cfg: dict) -> str:
    """Where ``measure.parallax_px`` comes from: the default is set from the paper's 22 cm in
    height; a run with another value says so rather than claim it."""
    key = "measure.parallax_px"
    if cfg[key] == SCHEMA[key].default:
        return f"{key} set from the paper's 22 cm"
    return f"this run's {key} {cfg[key]:g} px; the default {SCHEMA[key].default:g} px is set from the paper's 22 cm"
