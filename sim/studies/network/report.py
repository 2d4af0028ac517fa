"""The report section of a network study, from its Parquet files alone."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from sim.mc.storage import read_table
from sim.report.markdown import claims_markdown, fmt, md_table

__all__ = ["report"]


def report(out: Path) -> str:
    out = Path(out)
    s = read_table(out / "summary.parquet").to_pylist()[0]
    p = read_table(out / "points.parquet").to_pydict()
    o = read_table(out / "observations.parquet").to_pydict()
    r = np.array(o["redundancy"], float)
    worst = int(np.argmax(p["ellipse95_a_mm"]))
    parts = [
        f"Network **{s['network']}**: {s['points']} points, {s['observations']} observations, "
        f"{s['unknowns']} unknowns, datum `{s['datum']}` ({s['datum_constraints']} "
        f"constraints), {s['dof']} degrees of freedom. {s['converged']} of {s['trials']} "
        f"simulated adjustments converged. The sum of the redundancy numbers is "
        f"{fmt(s['redundancy_sum'], 6)}. Largest 95 % ellipse: point `{p['point'][worst]}`, "
        f"semi-axes {fmt(p['ellipse95_a_mm'][worst])} x {fmt(p['ellipse95_b_mm'][worst])} mm. "
        f"Redundancy numbers range from {fmt(float(r.min()))} to {fmt(float(r.max()))}; "
        f"{int(np.sum(~np.array(o['controlled'])))} observations are uncontrolled (r = 0). "
        f"gama-local XML: {s['gama_xml']}."
        + (f" Read from {s['gama_input']}." if s.get("gama_input") else "")
        + (
            f" Points held in part by the datum constraints (singular 2 x 2 covariance, not "
            f"listed): {s['held_by_datum']}."
            if s["held_by_datum"]
            else ""
        ),
        "",
        claims_markdown(out / "claims.parquet"),
        "",
    ]
    rows = [
        [
            p["point"][a],
            fmt(p["sigma_x_mm"][a]),
            fmt(p["sigma_y_mm"][a]),
            f"{fmt(p['mc_sigma_x_mm'][a])} [{fmt(p['mc_sigma_x_lo_mm'][a])}, "
            f"{fmt(p['mc_sigma_x_hi_mm'][a])}]",
            f"{fmt(p['mc_sigma_y_mm'][a])} [{fmt(p['mc_sigma_y_lo_mm'][a])}, "
            f"{fmt(p['mc_sigma_y_hi_mm'][a])}]",
            fmt(p["ellipse95_a_mm"][a]),
            fmt(p["ellipse95_b_mm"][a]),
            fmt(p["coverage95"][a]),
            fmt(p["dilution_pct"][a]),
        ]
        for a in range(len(p["point"]))
    ]
    if len(rows) > 30:
        keep = sorted(np.argsort(p["ellipse95_a_mm"])[-15:])
        rows = [rows[a] for a in keep]
        parts.append(
            f"Points (the 15 with the largest ellipses of {len(p['point'])}; all in "
            "`points.parquet`):"
        )
    else:
        parts.append("Points:")
    dil = f"dilution vs {s['compare_fix']} known (%)" if s["compare_fix"] else "dilution (%)"
    parts += [
        "",
        md_table(
            [
                "point",
                "sigma x (mm)",
                "sigma y (mm)",
                "MC sigma x [95 %]",
                "MC sigma y [95 %]",
                "95 % a (mm)",
                "95 % b (mm)",
                "coverage",
                dil,
            ],
            rows,
        ),
        "",
    ]
    order = np.argsort(r)[:10]
    unit = lambda a: (
        f"{fmt(o['mdb_mm'][a])} mm"
        if o["mdb_mm"][a] is not None  # noqa: E731
        else (
            f"{fmt(o['mdb_arcsec'][a])} arcsec"
            if o["mdb_arcsec"][a] is not None
            else "uncontrolled"
        )
    )
    parts += [
        "Weakest observations (smallest redundancy numbers; all in `observations.parquet`):",
        "",
        md_table(
            ["kind", "at", "from", "to", "redundancy", "MDB", "external max (mm)"],
            [
                [
                    o["kind"][a],
                    o["at"][a],
                    o["from"][a],
                    o["to"][a],
                    fmt(o["redundancy"][a]),
                    unit(a),
                    fmt(o["external_max_mm"][a]),
                ]
                for a in order
            ],
        ),
        "",
    ]
    g = (
        read_table(out / "parameters.parquet").to_pydict()
        if (out / "parameters.parquet").is_file()
        else {"parameter": []}
    )
    if g["parameter"]:
        parts += [
            "Other estimated parameters (analytic and Monte-Carlo sigma; `parameters.parquet`):",
            "",
            md_table(
                ["parameter", "unit", "true", "sigma", "MC sigma [95 %]", "MC mean error [95 %]"],
                [
                    [
                        g["parameter"][a],
                        g["unit"][a],
                        fmt(g["true"][a]),
                        fmt(g["sigma"][a]),
                        f"{fmt(g['mc_sigma'][a])} [{fmt(g['mc_sigma_lo'][a])}, "
                        f"{fmt(g['mc_sigma_hi'][a])}]",
                        f"{fmt(g['mc_mean_error'][a])} [{fmt(g['mc_mean_error_lo'][a])}, "
                        f"{fmt(g['mc_mean_error_hi'][a])}]",
                    ]
                    for a in range(len(g["parameter"]))
                ],
            ),
            "",
        ]
    d = read_table(out / "datums.parquet").to_pydict()
    if d["datum"]:
        for name in dict.fromkeys(d["datum"]):
            sx = [v for v, n in zip(d["sigma_x_mm"], d["datum"]) if n == name]
            sy = [v for v, n in zip(d["sigma_y_mm"], d["datum"]) if n == name]
            parts.append(
                f"In the datum *{name}* (S-transformation) the point sigmas range "
                f"from {fmt(min(sx + sy))} to {fmt(max(sx + sy))} mm."
            )
        parts.append("")
    parts += [
        "![network](" + out.name + "/network.png)",
        "![reliability](" + out.name + "/reliability.png)",
    ]
    return "\n".join(parts)
