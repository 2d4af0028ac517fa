"""Configuration of the study ``gridplate_two_plates`` (seed ``001_7e3a2951e7fed426.txt``).

Keys marked *input* carry a number the paper prints. Every other magnitude the paper does not
print (grid size and spacing, readings per point, the comparator's scale difference and
non-orthogonality, the true grid sigma) is explored jointly over its possible range (see
:mod:`sim.studies.gridplate.region`; ``region.*`` sizes the exploration). :func:`check` enforces what the model can compute.
"""

from __future__ import annotations

import numpy as np

from sim.mc.config import COMMON, ConfigError, Field

UM = 1e-3  # mm per um
#: bytes per trial of the simulated readings (P plates, N points, L readings, 2 coords, 8 B)
_MEM_LIMIT = 2e9

SCHEMA = {
    **COMMON,
    "trials": Field(
        4000, "int", "Monte-Carlo trials (simulated calibrations)", lo=2, hi=10_000_000
    ),
    "chunk": Field(250, "int", "trials per chunk", lo=1, hi=100_000),
    "plate.grid": Field(
        5,
        "int",
        "points per side of each grid plate (k x k); not printed, an example (region.toml)",
        lo=3,
        hi=15,
    ),
    "plate.spacing_mm": Field(
        40.0, "float", "grid spacing (mm); not printed", lo=1.0, hi=100.0, unit="mm"
    ),
    "plate.count": Field(2, "int", "grid plates measured (the PSK's two carriers)", lo=1, hi=4),
    "plate.kappa_deg": Field(
        1.0,
        "float",
        "largest |kappa| of a plate on its carrier (uniform)",
        lo=0.0,
        hi=45.0,
        unit="deg",
    ),
    "readings.count": Field(4, "int", "readings L per point; not printed", lo=2, hi=50),
    "readings.sigma_um": Field(
        1.5,
        "float",
        "sigma of one reading per coordinate (pointing)",
        lo=0.0,
        lo_open=True,
        hi=50.0,
        input=True,
        unit="um",
    ),
    "comparator.coord_sigma_um": Field(
        1.2,
        "float",
        "sigma of a mean comparator coordinate (pointing/sqrt(L) "
        "plus a per-point comparator error)",
        lo=0.0,
        lo_open=True,
        hi=50.0,
        input=True,
        unit="um",
    ),
    "comparator.scale_diff_ppm": Field(
        15.0,
        "float",
        "S' - S of the comparator (ppm); not printed, an example (region.toml explores it, eps in proportion)",
        lo=-1e4,
        hi=1e4,
        unit="ppm",
    ),
    "comparator.nonorth_arcsec": Field(
        3.8,
        "float",
        "non-orthogonality eps of the comparator axes; not printed",
        lo=-3600.0,
        hi=3600.0,
        unit="arcsec",
    ),
    "grid.sigma_true_um": Field(
        0.7,
        "float",
        "true sigma of the grid-plate coordinates; not "
        "printed (the paper gives the stated one), an example (region.toml)",
        lo=0.0,
        hi=50.0,
        unit="um",
    ),
    "grid.sigma_stated_um": Field(
        0.7,
        "float",
        "stated (certificate) grid sigma",
        lo=0.0,
        lo_open=True,
        hi=50.0,
        input=True,
        unit="um",
    ),
    "analysis.ratios": Field(
        [0.25, 0.5, 1.0, 2.0, 3.0, 4.0, 6.0, 10.0, 30.0],
        "list[float]",
        "weight ratios P_cx/P_x swept for coverage",
        lo=1e-6,
        hi=1e6,
        min_len=1,
    ),
    "analysis.stated_sigmas_um": Field(
        [0.2, 0.35, 0.5, 0.7, 0.9, 1.2, 1.6],
        "list[float]",
        "stated grid sigmas for the chi-square rejection curve",
        lo=0.0,
        lo_open=True,
        hi=50.0,
        min_len=1,
        unit="um",
    ),
    "analysis.alpha": Field(
        0.05, "float", "level of the two-sided chi-square test", lo=0.0, lo_open=True, hi=0.5
    ),
    "analysis.ratio_start": Field(
        2.0,
        "float",
        "P_cx:P_x of the first adjustment of the paper's "
        "re-weighting (its first printed weighting, 1:2)",
        lo=1e-3,
        hi=1e3,
    ),
    "analysis.iter_tol_um": Field(
        0.001,
        "float",
        "a Gauss-Newton iteration counts as converged "
        "when its largest correction (in coordinates) is below this "
        "(a tenth of the paper's last printed digit, 0.01 um)",
        lo=1e-9,
        hi=1.0,
        unit="um",
    ),
    "analysis.iter_sample": Field(
        32,
        "int",
        "adjustments per chunk whose Gauss-Newton iterations are counted",
        lo=1,
        hi=10_000,
    ),
    "region.points": Field(
        128, "int", "input vectors of the space-filling design (region.toml)", lo=4, hi=65536
    ),
    "region.rounds": Field(2, "int", "refinement rounds at the region's boundary", lo=0, hi=6),
    "region.draws": Field(
        1000,
        "int",
        "simulated calibrations per input vector (chi-square draws)",
        lo=50,
        hi=1_000_000,
    ),
}


def check(cfg: dict) -> None:
    """Bounds that follow from what the model can compute; one line naming the key."""
    sp, L, sc = cfg["readings.sigma_um"], cfg["readings.count"], cfg["comparator.coord_sigma_um"]
    if sc**2 < sp**2 / L:
        raise ConfigError(
            "comparator.coord_sigma_um",
            f"must be >= readings.sigma_um/sqrt(readings.count) = "
            f"{sp / np.sqrt(L):.3f} um (the mean of L readings cannot be better)",
        )
    total = np.hypot(sc, cfg["grid.sigma_true_um"])
    st = cfg["grid.sigma_stated_um"]
    # the re-weighting's fixed point P_cx = s_w^2 / sg^2 - 1 must be positive and finite for a
    # typical plate: sg below the total misclosure sigma, and not so small that P_cx overflows
    # the conditioning of the combined normals (P_cx up to ~1e8 keeps them well above eps)
    if st >= total:
        raise ConfigError(
            "grid.sigma_stated_um",
            f"{st:g} um is not below the total misclosure sigma "
            f"sqrt(coord_sigma^2 + grid.sigma_true^2) = {total:.3f} um: no "
            "re-weighting ratio passes (no positive fixed point)",
        )
    if st < total * 1e-4:
        raise ConfigError(
            "grid.sigma_stated_um",
            f"{st:g} um is so small against the misclosure sigma {total:.3f} um "
            "that the re-weighting ratio exceeds 1e8 (the combined normals lose "
            "all precision); state at least 1e-4 of it",
        )
    extent = cfg["plate.spacing_mm"] * (cfg["plate.grid"] - 1)
    # the systematic displacement at the edge must stay small against the grid (linearised
    # decomposition) and the coordinates finite
    sysrel = (
        abs(cfg["comparator.scale_diff_ppm"]) * 1e-6
        + abs(cfg["comparator.nonorth_arcsec"]) / 206265
    )
    if sysrel > 0.01:
        raise ConfigError(
            "comparator.scale_diff_ppm",
            "scale difference and non-orthogonality "
            "together exceed 1 % (the decomposition is linearised about a "
            "near-identity comparator)",
        )
    if sc * UM > 0.01 * extent:
        raise ConfigError(
            "comparator.coord_sigma_um",
            f"larger than 1 % of the grid extent "
            f"{extent:g} mm: the adjustment's geometry is meaningless",
        )
    n = cfg["plate.count"] * cfg["plate.grid"] ** 2 * cfg["readings.count"] * 2 * 8
    if n * min(cfg["chunk"], cfg["trials"]) * 6 > _MEM_LIMIT:
        raise ConfigError(
            "chunk",
            f"a chunk of {min(cfg['chunk'], cfg['trials'])} trials needs "
            f"about {n * min(cfg['chunk'], cfg['trials']) * 6 / 1e9:.1f} GB; "
            "use a smaller chunk",
        )
