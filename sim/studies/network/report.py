"""The report section of a network study (seed 004 for ``network_brown``; declared networks
otherwise), from its Parquet files alone, on the shared skeleton :mod:`sim.report.section`.
Coordinates and sigmas in mm, directions in arcsec."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from sim.report.read import TableError
from sim.report.section import section, table
from sim.report.tables import fmt, md_code, md_table, md_text

__all__ = ["report"]


def _summary(s: dict, p: dict, o: dict) -> str:
    r = np.array(o["redundancy"], float)
    worst = int(np.argmax(p["ellipse95_a_mm"]))
    return (
        f"Network **{md_text(s['network'])}**: {s['points']} points, {s['observations']} observations, "
        f"{s['unknowns']} unknowns, datum `{s['datum']}` ({s['datum_constraints']} "
        f"constraints), {s['dof']} degrees of freedom. {s['converged']} of {s['trials']} "
        f"simulated adjustments converged. The sum of the redundancy numbers is "
        f"{fmt(s['redundancy_sum'], 6)}. Largest 95 % ellipse: point {md_code(p['point'][worst])}, "
        f"semi-axes {fmt(p['ellipse95_a_mm'][worst])} x {fmt(p['ellipse95_b_mm'][worst])} mm. "
        f"Redundancy numbers range from {fmt(float(r.min()))} to {fmt(float(r.max()))}; "
        f"{int(np.sum(~np.array(o['controlled'])))} observations are uncontrolled (r = 0). "
        f"gama-local XML: {md_text(s['gama_xml'])}."
        + (f" Read from {md_text(s['gama_input'])}." if s.get("gama_input") else "")
        + (
            f" Points held in part by the datum constraints (singular 2 x 2 covariance, not "
            f"listed): {md_text(s['held_by_datum'])}."
            if s["held_by_datum"]
            else ""
        )
    )


def _mc(t: dict, col: str, a: int) -> str:
    """``value [lo, hi]`` of a Monte-Carlo column and its 95 % interval columns."""
    stem, unit = (col[:-3], "_mm") if col.endswith("_mm") else (col, "")
    return f"{fmt(t[col][a])} [{fmt(t[stem + '_lo' + unit][a])}, {fmt(t[stem + '_hi' + unit][a])}]"


_POINT_HEADER = [
    "point",
    "sigma x (mm)",
    "sigma y (mm)",
    "MC sigma x [95 %]",
    "MC sigma y [95 %]",
    "95 % a (mm)",
    "95 % b (mm)",
    "coverage",
]


def _points(s: dict, p: dict) -> list[str]:
    """The point table (the 15 largest ellipses of a network over 30 points)."""
    rows = [
        [
            md_text(p["point"][a]),
            fmt(p["sigma_x_mm"][a]),
            fmt(p["sigma_y_mm"][a]),
            _mc(p, "mc_sigma_x_mm", a),
            _mc(p, "mc_sigma_y_mm", a),
            fmt(p["ellipse95_a_mm"][a]),
            fmt(p["ellipse95_b_mm"][a]),
            fmt(p["coverage95"][a]),
            fmt(p["dilution_pct"][a]),
        ]
        for a in range(len(p["point"]))
    ]
    lead = "Points:"
    if len(rows) > 30:
        rows = [rows[a] for a in sorted(np.argsort(p["ellipse95_a_mm"])[-15:])]
        lead = (
            f"Points (the 15 with the largest ellipses of {len(p['point'])}; all in "
            "`points.parquet`):"
        )
    dil = f"dilution vs {s['compare_fix']} known (%)" if s["compare_fix"] else "dilution (%)"
    return [lead, md_table([*_POINT_HEADER, dil], rows)]


def _finite(x) -> bool:
    return x is not None and bool(np.isfinite(x))


def _mdb(o: dict, a: int) -> str:
    """The observation's minimal detectable bias in its unit: ``observations.parquet`` holds
    NaN, not null, in the column of the other unit (an angle's ``mdb_mm``) and in both for
    an uncontrolled observation."""
    if _finite(o["mdb_mm"][a]):
        return f"{fmt(o['mdb_mm'][a])} mm"
    if _finite(o["mdb_arcsec"][a]):
        return f"{fmt(o['mdb_arcsec'][a])} arcsec"
    return "uncontrolled"


def _weakest(o: dict) -> list[str]:
    """The ten observations with the smallest redundancy numbers."""
    order = np.argsort(np.array(o["redundancy"], float))[:10]
    return [
        "Weakest observations (smallest redundancy numbers; all in `observations.parquet`):",
        md_table(
            ["kind", "at", "from", "to", "redundancy", "MDB", "external max (mm)"],
            [
                [
                    o["kind"][a],
                    md_text(o["at"][a] or ""),
                    md_text(o["from"][a] or ""),
                    md_text(o["to"][a] or ""),
                    fmt(o["redundancy"][a]),
                    _mdb(o, a),
                    fmt(o["external_max_mm"][a]),
                ]
                for a in order
            ],
        ),
    ]


def _parameters(out: Path) -> list[str]:
    """Estimated parameters other than the points (``parameters.parquet``, if any)."""
    if not (out / "parameters.parquet").is_file():
        return []
    g = table(out, "parameters.parquet")
    if not g["parameter"]:
        return []
    return [
        "Other estimated parameters (analytic and Monte-Carlo sigma; `parameters.parquet`):",
        md_table(
            ["parameter", "unit", "true", "sigma", "MC sigma [95 %]", "MC mean error [95 %]"],
            [
                [
                    md_text(g["parameter"][a]),
                    g["unit"][a],
                    fmt(g["true"][a]),
                    fmt(g["sigma"][a]),
                    _mc(g, "mc_sigma", a),
                    _mc(g, "mc_mean_error", a),
                ]
                for a in range(len(g["parameter"]))
            ],
        ),
    ]


def _datums(out: Path) -> list[str]:
    """The range of the point sigmas in each S-transformed datum (``datums.parquet``)."""
    d = table(out, "datums.parquet")
    lines = []
    for name in dict.fromkeys(d["datum"]):
        sx = [v for v, n in zip(d["sigma_x_mm"], d["datum"]) if n == name]
        sy = [v for v, n in zip(d["sigma_y_mm"], d["datum"]) if n == name]
        lines.append(
            f"In the datum *{md_text(name)}* (S-transformation) the point sigmas range "
            f"from {fmt(min(sx + sy))} to {fmt(max(sx + sy))} mm."
        )
    return ["\n".join(lines)] if lines else []


def report(out: Path) -> str:
    """The section of a network study: summary, claims, points, weakest observations,
    other parameters, datums, figures."""
    out = Path(out)
    s = table(out, "summary.parquet")
    rows = {len(v) for v in s.values()}
    if rows != {1}:  # emptied or doubled by hand: its row would be another's, or an IndexError
        raise TableError(out / "summary.parquet", f"has {min(rows, default=0)} rows, not one")
    s = {k: v[0] for k, v in s.items()}
    p, o = table(out, "points.parquet"), table(out, "observations.parquet")
    return section(
        out,
        intro=[_summary(s, p, o)],
        body=[*_points(s, p), *_weakest(o), *_parameters(out), *_datums(out)],
        figures=[("network", "network.png"), ("reliability", "reliability.png")],
    )
