"""Report sections of the Brown studies (seed 004, Brown 1968), built from their Parquet files
alone (and the schema's key descriptions) on the shared skeleton :mod:`sim.report.section`.
Every number and verdict in the prose is read from a file; lengths in mm, sigmas in um."""

from __future__ import annotations

from pathlib import Path

from sim.report.section import config, region_lead, section, table
from sim.report.tables import fmt, md_table
from sim.studies.brown.schema import DILUTION, TABLE1

_BETA_NEAR_ZERO = (
    "**beta near zero.** beta enters the observation equation only squared, so its partial "
    "derivative vanishes at beta = 0 and the normal equations become singular. The solver "
    "estimates b = beta^2 instead (partial -1/(2q), never zero); the point covariances are "
    "the same as with beta whenever beta != 0, because it is a reparameterisation of one "
    "global."
)

_DATUM = (
    "**The datum of the dilution.** The dilution is stated in Brown's datum, which the "
    "station estimates define; the `brown_design` study gives it in datums that do not "
    "lean on the stations (its `brown.datum_*` rows)."
)

_UNPRINTED = (
    "**Unprinted inputs.** The paper prints neither the station offset ('a short "
    "distance from the midsides'), nor beta, nor the layout of its '25 well-distributed "
    "points'; the geometry above is a labelled example only, and the predictions are "
    "decided over the region (first paragraph)."
)

#: how the region's values at an input vector are obtained (closed-form covariances)
ANALYTIC = "every value analytic"


def _dilution_intro(out: Path) -> str:
    prov = config(out)
    cfg = prov["config"]
    n = len(set(table(out, "points.parquet")["point"]))
    scale = (
        f"every range on the {cfg['comparator.scale_length_mm']:g} mm scale plus "
        f"{cfg['comparator.micrometer_mm']:g} mm of micrometer"
        if cfg["comparator.scale_length_mm"] > 0
        else "scale length not enforced (idealised comparator)"
    )
    return (
        f"Design simulation of the paper's *Concept* section. Plate {cfg['plate.format_mm']:g} mm, "
        f"{cfg['plate.pattern']} pattern ({n} points), stations "
        f"{cfg['comparator.station_offset_mm']:g} mm outside the midsides (a labelled example), {scale}; "
        f"range sigma {prov['range_sigma_um']:.3f} um, {cfg['trials']} Monte-Carlo trials (seed "
        f"{cfg['seed']}). Three adjustments of the same simulated ranges: `known` (stations "
        "known), `stations` (Brown's datum x1 = x3 = 0, y4 = -y2), `pivot` (plus alpha and "
        "beta). The structure and bias rows use the analytic (rigorous) covariances of the example "
        "geometry; the Monte Carlo checks them (self-checks) and the bias invariance."
    )


def _dilution_vs_points(out: Path) -> list[str]:
    dvp = table(out, "dilution_vs_points.parquet")
    cols = ("n_points", "dil_min_pct", "dil_mean_pct", "dil_max_pct", "pivot_extra_max_pct")
    return [
        "**Dilution against the number of points** (analytic, k x k grid over the same extent, "
        "example geometry):",
        md_table(
            ["points", "min %", "mean %", "max %", "pivot extra, max %"],
            [[k, *(fmt(x) for x in rest)] for k, *rest in zip(*(dvp[c] for c in cols))],
        ),
    ]


def report_dilution(out: Path) -> str:
    """The section of ``brown_dilution``: the Concept's predictions over the region."""
    return section(
        out,
        lead=[region_lead(out, "The Concept's predictions", values=ANALYTIC)],
        intro=[_dilution_intro(out), _UNPRINTED],
        schema=DILUTION,
        body=[_BETA_NEAR_ZERO, _DATUM, *_dilution_vs_points(out)],
        figures=[
            ("consistent region", "consistent_region.png"),
            ("sigma maps", "sigma_maps.png"),
            ("dilution per point", "dilution_points.png"),
            ("dilution vs points", "dilution_vs_points.png"),
            ("MC vs analytic", "mc_vs_analytic.png"),
        ],
    )


def _plate(cfg: dict) -> str:
    """The run's plate (doors29f: the grid was printed as the paper's 5 x 5 whatever it was)."""
    if cfg["plate.pattern"] == "grid":
        g = cfg["plate.grid"]
        return f"a {g} x {g} array at {cfg['plate.spacing_mm']:g} mm"
    return f"a {cfg['plate.pattern']} pattern"


def _table1_intro(out: Path) -> str:
    prov = config(out)
    cfg = prov["config"]
    paper, run = "a 5 x 5 array at 45 mm", _plate(cfg)
    plate = run if run == paper else f"({paper}); this run: {run}"
    return (
        f"The paper's production test{':' if run == paper else ''} {plate}, "
        f"{cfg['errors.settings']} settings of {cfg['errors.setting_sigma_um']:g} um each and "
        f"{cfg['errors.comparator_sigma_um']:g} um from the comparator (range sigma "
        f"{prov['range_sigma_um']:.2f} um), reduced with the `pivot` model (2n + 7 unknowns). "
        "The printed standard deviations are sigma0 x sqrt(cofactor): sigma0 is the plate's "
        "printed closure (an input, 1.55–1.65 um at its rounding), the cofactor depends on "
        "the station offset and beta, which the paper does not print; so the rows above are "
        "decided over the region, never at one nominal geometry. The Monte Carlo below "
        f"(stations {cfg['comparator.station_offset_mm']:g} mm outside the midsides, a "
        "labelled example) checks the analytic covariance and the closure. The paper's "
        "listing of the residuals is lost; its summary line survives."
    )


def report_table1(out: Path) -> str:
    """The section of ``brown_table1``: Table 1's statements over the region."""
    what = (
        "Table 1's statements (80 % of the sigmas in 1.1–1.3 um, two points as large "
        "as 1.5 um, all below the closure of 1.6 um)"
    )
    return section(
        out,
        lead=[region_lead(out, what, values=ANALYTIC)],
        intro=[_table1_intro(out)],
        schema=TABLE1,
        figures=[("consistent region", "consistent_region.png"), ("table 1", "table1.png")],
    )
