"""Configuration schema of ``agnard_block`` (seed ``003_5ce730a990a7ebc5.txt``, Agnard,
Nolette & Gagnon): block geometry, scanner, measurement, pugging, weights, control layouts,
data snooping, trade-offs and the sweep of the unprinted five-point control layout; the
cross-key rules (:func:`check`) and the small derived quantities every part uses
(:func:`block_of`, :func:`model_sigmas`, the weights, the swept layouts).
Units: lengths in m on the ground, mm and um on the photo, px of the scan.
"""

from __future__ import annotations

import numpy as np

from sim.instruments.block import scanner as sc
from sim.instruments.block.layout import CONTROL_PATTERNS, Block, control_targets, make_block
from sim.mc.config import COMMON, ConfigError, Field

SEED = "003_5ce730a990a7ebc5.txt"
NAME = "agnard_block"

SCHEMA = {
    **COMMON,
    "trials": Field(500, "int", "Monte-Carlo trials of the 2 x 8 block", lo=2, hi=100_000_000),
    "chunk": Field(
        50, "int", "trials per chunk (each chunk has its own spawned stream)", lo=1, hi=1_000_000
    ),
    "block.strips": Field(2, "int", "strips (paper: two)", lo=1, hi=50, input=True),
    "block.models": Field(8, "int", "models per strip (paper: eight)", lo=1, hi=200, input=True),
    "block.scale": Field(
        6200.0, "float", "photo scale number (paper: 1/6 200)", lo=100.0, hi=1e6, input=True
    ),
    "block.focal_mm": Field(
        152.0, "float", "camera constant (paper: 152 mm)", lo=10.0, hi=1000.0, input=True, unit="mm"
    ),
    "block.base_mm": Field(
        90.0,
        "float",
        "base at photo scale (paper: 90 mm)",
        lo=10.0,
        hi=200.0,
        input=True,
        unit="mm",
    ),
    "block.format_mm": Field(230.0, "float", "photo format side", lo=50.0, hi=500.0, unit="mm"),
    "block.usable": Field(
        0.92, "float", "share of the half format where points are measured", lo=0.3, hi=1.0
    ),
    "block.sidelap": Field(0.3, "float", "sidelap between strips", lo=0.05, hi=0.8),
    "block.ground_points": Field(
        178, "int", "signalised test-field points (paper: 178)", lo=8, hi=100_000, input=True
    ),
    "block.pass_rows": Field(4, "int", "pass-point rows per strip", lo=2, hi=20),
    "block.relief_m": Field(
        20.0, "float", "terrain relief (peak to peak)", lo=0.0, hi=500.0, unit="m"
    ),
    "block.layout_seed": Field(
        7, "int", "seed of the test-field layout (fixed, not a trial stream)", lo=0
    ),
    "scan.dpi": Field(
        600.0,
        "float",
        "scan resolution (paper: 600 DPI, pixel 42 um)",
        lo=50.0,
        hi=10000.0,
        input=True,
    ),
    "scan.max_x_um": Field(
        20.0,
        "float",
        "largest scanner deformation in x (paper: +-20 um)",
        lo=0.0,
        hi=1000.0,
        input=True,
        unit="um",
    ),
    "scan.max_y_um": Field(
        40.0,
        "float",
        "largest scanner deformation in y (paper: +-40 um)",
        lo=0.0,
        hi=1000.0,
        input=True,
        unit="um",
    ),
    "scan.stepper_share": Field(
        0.3, "float", "periodic stepper term of dy relative to its polynomial part", lo=0.0, hi=10.0
    ),
    "scan.wavelength_mm": Field(
        60.0, "float", "period of the stepper term", lo=1.0, hi=1000.0, unit="mm"
    ),
    "scan.grid_mm": Field(
        10.0, "float", "spacing of the scanned calibration grid", lo=1.0, hi=230.0, unit="mm"
    ),
    "scan.grid_sigma_px": Field(
        0.1, "float", "centring error of a grid node on the scan", lo=0.0, hi=10.0, unit="px"
    ),
    "scan.fiducial_mm": Field(
        110.0, "float", "corner fiducials at (+-d, +-d)", lo=10.0, hi=250.0, unit="mm"
    ),
    "scan.fiducial_sigma_px": Field(
        0.25, "float", "centring error of a fiducial mark", lo=0.0, hi=10.0, unit="px"
    ),
    "measure.pointing_px": Field(
        0.5,
        "float",
        "planimetric setting error per coordinate (paper: half a pixel, '13 cm on the ground')",
        lo=0.0,
        lo_open=True,
        hi=20.0,
        input=True,
        unit="px",
    ),
    "measure.parallax_px": Field(
        0.5,
        "float",
        "x-parallax setting error (paper: 13 cm x f/B = 22 cm in height)",
        lo=0.0,
        lo_open=True,
        hi=20.0,
        input=True,
        unit="px",
    ),
    "measure.control_sigma_m": Field(
        0.02, "float", "error of the surveyed control coordinates", lo=0.0, hi=10.0, unit="m"
    ),
    "pugging.transfer_um": Field(
        10.0,
        "float",
        "mechanical: error of a drilled hole (transfer to each photo)",
        lo=0.0,
        hi=1000.0,
        unit="um",
    ),
    "pugging.recentre_px": Field(
        0.5,
        "float",
        "mechanical: re-centring the mark in a hole, per measurement",
        lo=0.0,
        hi=20.0,
        unit="px",
    ),
    "pugging.gross_rate": Field(
        0.0,
        "float",
        "mechanical: chance per model point that a hole is missed on one photo (off by default)",
        lo=0.0,
        hi=1.0,
    ),
    "pugging.gross_px": Field(
        [2.0, 6.0],
        "list[float]",
        "mechanical: range of a missed hole's error",
        lo=0.0,
        hi=1000.0,
        min_len=2,
        unit="px",
    ),
    "weights.pass": Field(
        0.1, "float", "weight of model points (paper: 0.1)", lo=0.0, lo_open=True, input=True
    ),
    "weights.control_xy": Field(
        3.0, "float", "weight of control in planimetry (paper: 3)", lo=0.0, lo_open=True, input=True
    ),
    "weights.control_z": Field(
        2.0, "float", "weight of control in height (paper: 2)", lo=0.0, lo_open=True, input=True
    ),
    "weights.first_pass_control": Field(
        0.1, "float", "first pass: control weight (paper: 0.1)", lo=0.0, lo_open=True, input=True
    ),
    "weights.first_pass_pass": Field(
        1.0,
        "float",
        "first pass: model-point weight (paper: 1.0)",
        lo=0.0,
        lo_open=True,
        input=True,
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
    "snoop.alpha": Field(
        0.001, "float", "significance level of one w-test (two-sided)", lo=1e-9, hi=0.5
    ),
    "snoop.test": Field(
        "w",
        "str",
        "w: Baarda's w-test with the a-priori sigma0; tau: Pope's "
        "test with the block's a-posteriori sigma0",
        choices=("w", "tau"),
    ),
    "snoop.max_reject": Field(25, "int", "most pass points removed per block", lo=0, hi=1000),
    "tradeoff.dpis": Field(
        [300.0, 600.0, 1200.0],
        "list[float]",
        "scan resolutions compared",
        lo=50.0,
        hi=10000.0,
        min_len=1,
    ),
    "tradeoff.trials": Field(
        150, "int", "trials per scan resolution and per re-centring error", lo=2, hi=1_000_000
    ),
    "tradeoff.layouts": Field(
        list(CONTROL_PATTERNS),
        "list[str]",
        "control layouts compared",
        choices=CONTROL_PATTERNS,
        min_len=1,
    ),
    "tradeoff.block_strips": Field(
        [1, 2, 2, 3, 4, 4], "list[int]", "strips of the blocks compared", lo=1, hi=50, min_len=1
    ),
    "tradeoff.block_models": Field(
        [8, 4, 8, 12, 16, 24],
        "list[int]",
        "models per strip of the blocks compared (same length as block_strips)",
        lo=1,
        hi=200,
        min_len=1,
    ),
    "tradeoff.recentre_px": Field(
        [0.25, 0.5, 0.75],
        "list[float]",
        "mechanical re-centring errors for the rejection sensitivity",
        lo=0.0,
        hi=20.0,
        min_len=1,
        unit="px",
    ),
    "tradeoff.block_trials": Field(30, "int", "trials per block size", lo=2, hi=1_000_000),
    "tradeoff.block_control": Field(
        "perimeter", "str", "control layout of the block-size runs", choices=CONTROL_PATTERNS
    ),
    "tradeoff.centre_points": Field(
        10,
        "int",
        "check points nearest the block centre used for 'accuracy at the centre'",
        lo=1,
        hi=10_000,
    ),
    "sweep.trials": Field(
        150, "int", "trials per value of the swept five-point control layout", lo=2, hi=1_000_000
    ),
    "sweep.five_inset": Field(
        [0.0, 0.08, 0.17, 0.25, 0.33],
        "list[float]",
        "unprinted input "
        "(Figure 5 lost): the four outer control points of the five-point "
        "layout moved inwards along the strips by this share of the block "
        "length (0: block corners; 1/6, 1/3: the second and third column "
        "of a 3 x 7 layout of 21), the fifth at the centre",
        lo=0.0,
        hi=0.45,
        min_len=2,
    ),
}


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
    if cfg["block.strips"] * cfg["block.models"] < 2:
        raise ConfigError("block.models", "a block needs at least two models")
    if len(set(cfg["sweep.five_inset"])) != len(cfg["sweep.five_inset"]):
        raise ConfigError("sweep.five_inset", "values must be distinct")
    # memory of the largest adjustment: trials x observation pairs x 7 x 7 doubles per chunk
    try:
        block = block_of(cfg)
    except ValueError as e:
        raise ConfigError("block.relief_m", str(e)) from None
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
    pairs = int((np.bincount(block.obs_point).astype(np.int64) ** 2).sum())
    if cfg["chunk"] * pairs * 49 * 8 > 2e9:
        raise ConfigError(
            "chunk",
            f"a chunk of {cfg['chunk']} blocks needs "
            f"{cfg['chunk'] * pairs * 49 * 8 / 1e9:.1f} GB for its normal "
            "equations; lower chunk",
        )


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
    """The swept five-point layout (5, 2): the corners of the ``five`` pattern moved inwards
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
