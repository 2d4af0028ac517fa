"""The configuration keys of the ``network`` study kind (a user's network as data): their
types, defaults, bounds and meaning, and which are read only under a condition (the network
given in the study file, not by ``network.gama_xml``; the datum's points and constraints by
``datum.kind``). The cross-key rules are :func:`sim.studies.network.schema.check`.

Coordinates and distance sigmas in mm, angular sigmas in arcsec.
"""

from __future__ import annotations

from sim.mc.config import COMMON, Field
from sim.mc.read_when import unless, when
from sim.mc.runner import MIN_CHUNKS

__all__ = ["SCHEMA"]


def _own(f: Field) -> Field:
    """A key of a network given in the study file: not read with ``network.gama_xml``."""
    return when(
        f, "network.gama_xml", "", says="without network.gama_xml (the file gives the network)"
    )


SCHEMA = {
    **COMMON,
    "network.name": Field("network", "str", "name of the network (report title)"),
    "network.gama_xml": Field(
        "",
        "str",
        "read the points and observations from this "
        "gama-local XML file instead (a path relative to the working "
        "directory, or absolute)",
        sweep="each file is a network with its own sha256 (network.gama_sha256): "
        "write one study file per network",
    ),
    "network.gama_sha256": unless(
        Field(
            "",
            "str",
            "sha256 of the network.gama_xml file's contents, filled in on load so that an "
            "edited file makes the results stale (if given, the file must still have it)",
            sweep="it is the sha256 of the one network.gama_xml file",
        ),
        "network.gama_xml",
        "",
        says="with network.gama_xml",
    ),
    "network.points": _own(
        Field([], "records", "points {name, x_mm | x_m, y_mm | y_m, role, sigma_mm}")
    ),
    "network.grids": _own(
        Field(
            [],
            "records",
            "grids {prefix, nx, ny, spacing_mm | spacing_m, origin_mm | origin_m, role, sigma_mm}",
        )
    ),
    "network.random": _own(
        Field(
            [],
            "records",
            "random points {prefix, n, half_extent_mm | half_extent_m, center_mm | center_m, "
            "role, sigma_mm}, drawn once from network.layout_seed",
        )
    ),
    "network.layout_seed": unless(
        Field(
            1,
            "int",
            "seed of the random points' layout, apart from seed: --seed, replicates and a "
            "sweep's cells draw new noise on one network (sweep this key to compare layouts)",
            lo=0,
            hi=2**63 - 1,
        ),
        "network.random",
        [],
        says="with random points (network.random)",
    ),
    "network.observations": _own(
        Field(
            [],
            "records",
            "single observations {kind, from, to, at, "
            "sigma_mm | sigma_arcsec, settings, bias_mm | bias_arcsec, set}",
        )
    ),
    "network.generate": _own(
        Field(
            [],
            "records",
            "generated observations {kind, from, to, nearest, "
            "sigma_*, settings, bias_*}: every 'from' point to every 'to' point",
        )
    ),
    "network.constant_mm": Field(
        0.0,
        "float",
        "true additive constant of every distance (Brown's alpha)",
        lo=-1e6,
        hi=1e6,
        unit="mm",
    ),
    "network.estimate_constant": Field(False, "bool", "estimate the additive constant"),
    "network.offset_mm": Field(
        0.0,
        "float",
        "known perpendicular offset of every distance (Brown's beta): reads sqrt(d^2 - beta^2)",
        lo=0.0,
        hi=1e6,
        unit="mm",
    ),
    "network.scale_ppm": Field(
        0.0,
        "float",
        "true scale error of every distance: reads (1 + s) times the distance",
        lo=-1e5,
        hi=1e5,
        unit="ppm",
    ),
    "network.estimate_scale": Field(False, "bool", "estimate the scale error of the distances"),
    "datum.kind": Field(
        "fixed",
        "str",
        "fixed points, inner constraints over datum.points, or explicit minimal constraints",
        choices=("fixed", "inner", "constraints"),
    ),
    "datum.points": when(
        Field([], "list[str]", "name patterns of the inner-constraint points (default: all)"),
        "datum.kind",
        "inner",
    ),
    "datum.constraints": when(
        Field(
            [],
            "records",
            'minimal constraints, each {"P.x" = coef, ...}: sum of coef x correction = 0',
        ),
        "datum.kind",
        "constraints",
    ),
    "output.inner_over": Field(
        [],
        "list[str]",
        "also state the point precision in the inner "
        "datum over these name patterns (S-transformation)",
    ),
    "compare.fix": Field(
        [],
        "list[str]",
        "a second parameterisation with these points known: "
        "the dilution of every other point between the two",
    ),
    "reliability.alpha0": Field(
        0.001, "float", "significance level of Baarda's w-test", lo=1e-12, hi=0.5
    ),
    "reliability.power": Field(0.80, "float", "power of the w-test (MDB)", lo=0.05, hi=0.9999),
    "test.alpha": Field(
        0.05, "float", "significance level of the global (chi-square) test", lo=1e-6, hi=0.5
    ),
    "solver.tol_mm": Field(
        1e-9, "float", "convergence on the corrections", lo=1e-15, hi=1.0, lo_open=True, unit="mm"
    ),
    "solver.max_iter": Field(20, "int", "Gauss-Newton iteration limit", lo=1, hi=200),
}
SCHEMA["trials"] = Field(2000, "int", "Monte-Carlo trials", lo=2, hi=10_000_000)
SCHEMA["chunk"] = Field(
    100,
    "int",
    f"trials per chunk (the jackknife intervals are over chunks: >= {MIN_CHUNKS} chunks)",
    lo=1,
    hi=100_000,
)
