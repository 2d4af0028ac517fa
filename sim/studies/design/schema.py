"""Configuration schema of study ``brown_design`` (seed ``004_f5bd9e86c308241f.txt``, Brown
1968); its cross-key checks are in :mod:`.checks`.

Keys marked ``input`` were set to match a number the paper prints. Keys the paper does not
print (station offset, beta, the pass time, the screw pitch, the layout of the Zeiss grid's
33 calibrated points) are explored jointly over their hardware ranges (:mod:`.region`); the
claims that depend on them are decided over the consistent region
(``consistent_region.parquet``).
"""

from __future__ import annotations

from sim.instruments.ranges import brown as B
from sim.mc.config import COMMON
from sim.mc.schema_helpers import (
    compared,
    count,
    counts,
    level,
    positive,
    printed,
    real,
    reals,
    region_seed,
)

__all__ = ["SEED", "SCHEMA", "MAX_CELLS", "MAX_POINTS", "BETA_MAX_MM"]

SEED = "004_f5bd9e86c308241f.txt"
MAX_CELLS = 200_000  # design cells (each a batched analytic covariance)
MAX_POINTS = 900  # points of one plate (covariances are (2n)^2 per cell)
#: beta, the pivot ball's offset across the scale, is at most half the scale's width: the
#: ball lies under the 29 mm wide scale (the instrument, :mod:`sim.instruments.ranges.brown`);
#: checked by :mod:`.checks` with that reason (the beta keys have no ``hi`` of their own)
BETA_MAX_MM = B.SCALE_WIDTH_MM / 2

SCHEMA = {
    **COMMON,
    "trials": count(
        2000, "Monte-Carlo trials of the check of the paper's design", lo=2, hi=10_000_000
    ),
    "chunk": count(500, "trials per chunk", lo=1, hi=1_000_000),
    "plate.format_mm": real(
        245.0,
        "side of the square format (paper: 245 x 245 mm)",
        lo=1.0,
        hi=2000.0,
        unit="mm",
        input=True,
    ),
    "scale.graduated_mm": real(
        261.0,
        "graduated length of the scale (paper: 261 mm)",
        lo=1.0,
        hi=5000.0,
        unit="mm",
        input=True,
    ),
    "scale.micrometer_mm": real(
        1.0, "largest micrometer translation (paper: 1 mm)", lo=0.0, hi=100.0, unit="mm", input=True
    ),
    "comparator.alpha_mm": real(
        0.5,
        "radial pivot offset alpha (not printed; it drops out of the coordinates; every "
        "range must still read on the scale: checked on load)",
        lo=-50.0,
        hi=50.0,
        unit="mm",
    ),
    "comparator.sigma_um": real(
        1.1,
        "random comparator error per reading (paper, Table 1: about 1.1 um)",
        lo=0.0,
        hi=1000.0,
        unit="um",
        input=True,
    ),
    # design grid
    "design.positions": compared(counts([3, 4, 6, 8], "plate positions (stations)", lo=3, hi=24)),
    "design.offsets_mm": compared(
        reals(
            [5.0, 10.0, 17.0, 20.0, 30.0, 45.0, 60.0, 80.0],
            "station offsets outside the midsides",
            lo=0.0,
            hi=1000.0,
            lo_open=True,
            unit="mm",
        )
    ),
    "design.grids": compared(
        counts([3, 4, 5, 6, 7], "points per side of the square grid", lo=2, hi=30)
    ),
    "design.extents_mm": compared(
        reals(
            [70.0, 90.0, 110.0],
            "half extent of the grid",
            lo=0.0,
            hi=1000.0,
            lo_open=True,
            unit="mm",
        )
    ),
    "design.settings": compared(counts([1, 2, 3], "settings per point and position", lo=1, hi=20)),
    "design.setting_sigma_um": reals(
        [1.7, 0.5],
        "sigma of one setting (paper: 1.7 "
        "um by eye; better than 0.5 um expected from the semi-automatic "
        "setting device)",
        lo=0.0,
        hi=1000.0,
        lo_open=True,
        unit="um",
        input=True,
    ),
    "design.beta_mm": compared(
        reals(
            [1.0, 5.0],
            "tangential pivot offset beta (at most half the 29 mm scale's width: checked on load)",
            lo=0.0,
            unit="mm",
        )
    ),
    # measuring time
    "time.images": count(30, "images of the timed plate (paper: 30)", lo=1, hi=10_000, input=True),
    "time.single_min": positive(
        60.0,
        "time for 30 images, 4 positions, single settings (paper: within one hour)",
        hi=1e5,
        unit="min",
        input=True,
    ),
    "time.double_min": positive(
        90.0, "the same with double settings (paper: about 90 min)", hi=1e5, unit="min", input=True
    ),
    "time.pass_min": real(
        2.0,
        "fixed cost of one plate position (turn the holder, swing "
        "the arm; not printed: a labelled example)",
        lo=0.0,
        hi=1e4,
        unit="min",
    ),
    # the paper's design
    "paper.positions": count(
        4, "plate positions of the paper's comparator", lo=3, hi=24, input=True
    ),
    "paper.grid": count(5, "Table 1: 5 x 5 array", lo=2, hi=30, input=True),
    "paper.extent_mm": positive(
        90.0, "Table 1: 45 mm spacing -> +-90 mm", hi=1000.0, unit="mm", input=True
    ),
    "paper.settings": count(2, "Table 1: double settings", lo=1, hi=20, input=True),
    "paper.setting_sigma_um": positive(
        1.7, "Table 1: one setting 1.7 um", hi=1000.0, unit="um", input=True
    ),
    "paper.offset_mm": positive(
        17.0,
        "station offset of the paper's design (not printed: a labelled example, the "
        "claims that depend on it are decided over the region; must fit on the scale)",
        hi=1000.0,
        unit="mm",
    ),
    "paper.beta_mm": real(
        1.0,
        "beta of the paper's design (not printed: a labelled example; decided over the region; "
        "at most half the 29 mm scale's width)",
        lo=0.0,
        unit="mm",
    ),
    # datum (brown_dilution's example geometry; must be buildable on the scale)
    "datum.grid": count(5, "points per side (brown_dilution geometry)", lo=3, hi=30),
    "datum.spacing_mm": real(
        45.0, "grid spacing (brown_dilution geometry)", lo=0.01, hi=1000.0, unit="mm"
    ),
    "datum.offset_mm": positive(
        17.0, "station offset (brown_dilution geometry)", hi=1000.0, unit="mm"
    ),
    "datum.beta_mm": real(
        1.0, "beta (at most half the 29 mm scale's width: checked on load)", lo=0.0, unit="mm"
    ),
    # error budget
    "budget.graduation_um": real(
        0.54,
        "residual graduation error after calibration (paper: sqrt(0.5^2 + 0.2^2) = 0.54 um)",
        lo=0.0,
        hi=100.0,
        unit="um",
        input=True,
    ),
    "budget.scale_spec_um": real(
        1.0,
        "graduation error of an uncalibrated scale (paper's "
        "specification: cumulative nonlinearity at most 1 um)",
        lo=0.0,
        hi=100.0,
        unit="um",
        input=True,
    ),
    "budget.screw_um": real(
        0.3,
        "residual screw error after calibration (paper: 0.3 um)",
        lo=0.0,
        hi=100.0,
        unit="um",
        input=True,
    ),
    "budget.screw_harmonics": count(
        3, "Fourier terms of the residual screw error over 1 mm", lo=1, hi=50
    ),
    "budget.drum_periodic_um": real(
        0.5,
        "uncorrected periodic error of the drum (paper: up to 0.5 um)",
        lo=0.0,
        hi=100.0,
        unit="um",
        input=True,
    ),
    "budget.pitch_mm": real(
        0.5,
        "screw pitch (not printed: a labelled example; decided over the region)",
        lo=0.01,
        hi=1.0,
        unit="mm",
    ),
    "budget.wobble_um": real(
        2.0,
        "radial pivot wobble at 3 kg thrust (paper: up to 2 um)",
        lo=0.0,
        hi=100.0,
        unit="um",
        input=True,
    ),
    "budget.wobble_harmonic": count(
        2, "harmonic of the wobble over the arm's direction", lo=1, hi=20
    ),
    "budget.sphericity_um": real(
        0.25,
        "sphericity of the pivot ball (paper: 0.25 um), modelled as a second-harmonic radial error",
        lo=0.0,
        hi=100.0,
        unit="um",
        input=True,
    ),
    "budget.target_se_um": real(
        0.005,
        "adaptive: standard error target of each rms coordinate error",
        lo=1e-4,
        hi=100.0,
        unit="um",
    ),
    "budget.max_trials": count(20000, "adaptive: trial limit per source", lo=10, hi=10_000_000),
    # the paper's external comparisons
    "zeiss.points": count(
        33,
        "calibrated intersections of the Zeiss grid (paper: 33)",
        lo=3,
        hi=MAX_POINTS,
        input=True,
    ),
    "zeiss.grid_sigma_um": real(
        0.8,
        "stated accuracy of the Zeiss grid (paper: 0.8 um rms)",
        lo=0.0,
        hi=100.0,
        unit="um",
        input=True,
    ),
    "zeiss.half_extent_mm": real(
        90.0,
        "half extent of the 33-point sample (layout not "
        "printed: a labelled example; decided over the region)",
        lo=1.0,
        hi=1000.0,
        unit="mm",
    ),
    "zeiss.layout_seed": count(
        1967,
        "seed of the stand-in layout's intersections, apart from seed: --seed, replicates and "
        "a sweep's cells draw new plates on one layout (sweep this key to compare layouts; "
        "1967 is the study file's seed, which drew it before)",
        lo=0,
        hi=2**63 - 1,
    ),
    "operation.lateral_offset_um": real(
        100.0,
        "lateral offset of the image in the reticle (paper: as much as 100 um)",
        lo=0.0,
        hi=1e4,
        unit="um",
        input=True,
    ),
    "operation.gap_um": real(
        100.0,
        "gap between plate and scale (paper: 75 to 100 um; the larger is the worst case)",
        lo=0.1,
        hi=1e4,
        unit="um",
        input=True,
    ),
    "calibration.accuracy_um": real(
        1.0,
        "accuracy the tolerances are stated for (paper: one micron)",
        lo=0.001,
        hi=100.0,
        unit="um",
        input=True,
    ),
    "calibration.drum_dividing_arcsec": real(
        15.0,
        "dividing accuracy of the drum (paper: 15 seconds of arc)",
        lo=0.0,
        hi=3600.0,
        input=True,
    ),
    # the joint exploration of the unprinted inputs (sim.claims.inference; .region)
    "region.points": count(
        1024,
        "Sobol design size of the analytic tolerance region (offset x beta x sigma0 x screw pitch)",
        lo=256,
        hi=16384,
    ),
    "region.rounds": count(3, "refinement rounds of the tolerance region", lo=0, hi=8),
    "region.seed": region_seed(1967),
    "region.plate_points": count(
        1024,
        "Sobol design size of the plate region (offset x beta x sigma0 x Zeiss layout x "
        "two-screw error; each point Table 1 leaves in the region draws unprinted.plates plates). "
        "Table 1's statements leave about 3 % of the box, so at least 256 (about 6 points in "
        "the region; fewer points leave the plates rows with none)",
        lo=256,
        hi=1024,
    ),
    "unprinted.plates": count(
        4000, "Gaussian plates drawn per input vector (linearised)", lo=100, hi=1_000_000
    ),
    # coverage
    "coverage.trials": count(10000, "trials of the nominal coverage runs", lo=10, hi=10_000_000),
    "coverage.sweep_trials": count(
        2000, "trials per point of the coverage sweeps", lo=10, hi=10_000_000
    ),
    "coverage.sigma_um": real(
        1.0,
        "range sigma of the nominal case (at most 1 % of the datum plate's spacing and "
        "shortest range: checked on load)",
        lo=1e-6,
        hi=1e5,
        unit="um",
    ),
    "coverage.noise_um": compared(
        reals(
            [1.0, 300.0, 1000.0, 3000.0, 10000.0],
            "range sigmas of the noise sweep",
            lo=1e-6,
            hi=1e5,
            unit="um",
        )
    ),
    "coverage.grids": compared(counts([2, 3, 4, 5], "grids of the point-count sweep", lo=2, hi=20)),
    "coverage.betas_mm": compared(
        reals(
            [0.0, 0.003, 0.01, 0.03, 0.1, 1.0],
            "betas of the beta sweep (at most half the 29 mm scale's width)",
            lo=0.0,
            unit="mm",
        )
    ),
    "coverage.alpha": level(0.05, "level of the global chi-square test"),
    # bayes
    "bayes.walkers": count(32, "emcee walkers", lo=16, hi=1000),
    "bayes.steps": count(
        8000,
        "emcee steps per walker and chain (8,000: about 70 autocorrelation times kept, "
        "emcee's rule asks 50 for a verdict)",
        lo=100,
        hi=1_000_000,
    ),
    "bayes.chains": count(
        4, "independent emcee ensembles (run in parallel, one per chunk)", lo=2, hi=64
    ),
    "bayes.grid_prior_log_sd": real(
        0.1,
        "sd of log sigma_g in the certificate prior of the two-plate ratio (10 %: assumed)",
        lo=0.001,
        hi=10.0,
    ),
}

#: the keys whose default is a number the paper prints for its own comparator and Table 1
#: (seed 004: the format, the scale and micrometer, the comparator's 1.1 um, the timed plate,
#: Table 1's plate and settings, the error budget's printed sources, the Zeiss grid, the
#: operation's offsets, the calibration's tolerances): a run with another value is off the
#: paper's setup, its predictions findings (sim.claims.rules.printed_differs). Not marked:
#: the design space explored (design.*, coverage.*), the labelled examples of unprinted
#: inputs (offsets, beta, pitch, the Zeiss layout, time.pass_min), brown_dilution's example
#: geometry (datum.*)
PRINTED = (
    "plate.format_mm",
    "scale.graduated_mm",
    "scale.micrometer_mm",
    "comparator.sigma_um",
    "time.images",
    "time.single_min",
    "time.double_min",
    "paper.positions",
    "paper.grid",
    "paper.extent_mm",
    "paper.settings",
    "paper.setting_sigma_um",
    "budget.graduation_um",
    "budget.scale_spec_um",
    "budget.screw_um",
    "budget.drum_periodic_um",
    "budget.wobble_um",
    "budget.sphericity_um",
    "zeiss.points",
    "zeiss.grid_sigma_um",
    "operation.lateral_offset_um",
    "operation.gap_um",
    "calibration.accuracy_um",
    "calibration.drum_dividing_arcsec",
)
SCHEMA.update({k: printed(SCHEMA[k]) for k in PRINTED})


def datum_geometry(cfg: dict) -> str:
    """Whose geometry the dilution's datum rows use: "brown_dilution's" where every
    ``datum.*`` key is its default (brown_dilution's example), else "the run's datum.*"."""
    keys = [k for k in SCHEMA if k.startswith("datum.")]
    same = all(cfg[k] == SCHEMA[k].default for k in keys)
    return "brown_dilution's" if same else "the run's datum.*"
