"""Cross-key rules of ``wolf_polynomial`` (the schema's single-key ranges are
:mod:`.schema`): the area around the origin a, grids that contain a and b at every spacing
compared, the degree the grid supports, the trade-offs the claims read, the photograph inside
the calibrated area, the work per chunk, and the transcribed tables parsed at load time.
Coordinates in mm."""

from __future__ import annotations

import filecmp
import hashlib
from pathlib import Path

import numpy as np

from sim.mc.config import ConfigError
from sim.mc.schema_helpers import recorded_sha256, require
from sim.studies.wolf import tables
from sim.studies.wolf.grid import grid_nodes, mid_cells, node_index

__all__ = ["MAX_CHUNK_CELLS", "ROOT", "check", "table_digest", "table_path"]

#: the repository root: table files are given relative to it
ROOT = Path(__file__).resolve().parents[3]

#: the independent plate's random points lie this far inside plate.area_mm (mm)
CHECK_MARGIN_MM = 5.0

#: work limit of the shared draws: trials x points x readings per chunk (about 8 bytes each)
MAX_CHUNK_CELLS = 60_000_000


def _grid_ok(cfg, spacing, key):
    area = cfg["plate.area_mm"]
    ab = cfg["reduce.ab_mm"]
    n = [(area[1] - area[0]) / spacing + 1, (area[3] - area[2]) / spacing + 1]
    require(
        n[0] * n[1] <= 100_000,
        key,
        f"a grid at {spacing:g} mm has about {n[0] * n[1]:.3g} points in the "
        "area (more than 100000): the spacing is too fine",
    )
    g = grid_nodes(area, spacing)
    require(
        node_index(g, (0.0, 0.0)) >= 0 and node_index(g, (ab, 0.0)) >= 0,
        key,
        f"a grid at {spacing:g} mm in the area has no intersection at a = "
        f"(0, 0) or b = ({ab:g}, 0): the spacing must divide ab and b must lie "
        "in the area",
    )
    return g


def table_path(cfg: dict, key: str) -> Path:
    """The file ``cfg[key]`` names: a relative path is read from the project root, never from
    the working directory. A file of that relative path in the working directory (a study
    author's own copy, ``studies/data/wolf_table1.csv`` edited in a directory of theirs, or
    ``my_table.csv`` beside their study) was silently passed over for the project's (or named
    "no such file" under the root): a path whose file here differs from the root's (or that
    the root lacks) is refused, one line naming the key."""
    p = Path(cfg[key])
    if p.is_absolute():
        return p
    here = Path.cwd() / p
    try:  # a copy of the same bytes reads the same: only another file is refused
        other = here.is_file() and not (
            (ROOT / p).is_file() and filecmp.cmp(here, ROOT / p, shallow=False)
        )
    except OSError:  # unreadable here or under the root: the reader names the root's
        other = False
    require(
        not other,
        key,
        f"{p} is read from the project root {ROOT}, not from the working directory "
        f"{Path.cwd()}, which holds another file of that path: give its absolute path",
    )
    try:  # "no such file: ROOT/my.csv" of a file beside the study file said not why (L37)
        (ROOT / p).lstat()
    except FileNotFoundError:
        require(
            not str(p).isprintable(),  # a control character: the reader names it
            key,
            f"no such file: {ROOT / p} (a relative path is read from the project root, not "
            "from the study file's directory: give the path from the root, or an absolute one)",
        )
    except OSError:  # a name too long, a directory not searchable: the reader names it
        pass
    return ROOT / p


def _grids(cfg: dict) -> np.ndarray:
    """The area around a, the grid of the calibration (and the degree it supports), the
    grids of the degree trade-off; the calibration grid's nodes."""
    a = cfg["plate.area_mm"]
    require(
        len(a) == 4 and a[0] < 0 < a[1] and a[2] < 0 < a[3],
        "plate.area_mm",
        "must be [xmin, xmax, ymin, ymax] around the origin a",
    )
    ab = cfg["reduce.ab_mm"]
    require(ab <= a[1], "reduce.ab_mm", f"b = ({ab:g}, 0) lies outside the area")
    g = _grid_ok(cfg, cfg["plate.spacing_mm"], "plate.spacing_mm")
    d = cfg["calib.degree"]
    nx, ny = len(np.unique(g[:, 0])), len(np.unique(g[:, 1]))
    require(
        min(nx, ny) >= d + 1,
        "calib.degree",
        f"a degree-{d} polynomial needs at least {d + 1} grid "
        f"columns and rows (the grid has {nx} x {ny})",
    )
    for s in cfg["trade.spacings_mm"]:
        _grid_ok(cfg, s, "trade.spacings_mm")
    # named by the list that lacks the study's setting (calib.n_sets = 50 beside the default
    # trade.n_sets named trade.degrees, a key at its default: P44)
    why = (
        "the degree trade-off must compare the cubic (3) with another degree at "
        "plate.spacing_mm and calib.n_sets: the claim on the cubic reads it"
    )
    degs = cfg["trade.degrees"]
    require(3 in degs and len(set(degs)) >= 2, "trade.degrees", why)
    for key, lst in (("plate.spacing_mm", "trade.spacings_mm"), ("calib.n_sets", "trade.n_sets")):
        require(
            cfg[key] in cfg[lst],
            lst,
            f"{key} = {cfg[key]:g} is not one of {cfg[lst]}: {why}",
        )
    return g


def _inside(box, span, tol: float = 1e-6) -> bool:
    """Whether ``box`` [xmin, xmax, ymin, ymax] lies inside ``span`` (mm, within ``tol``)."""
    return (
        span[0] - tol <= box[0]
        and box[1] <= span[1] + tol
        and span[2] - tol <= box[2]
        and box[3] <= span[3] + tol
    )


def _photograph(cfg: dict, g: np.ndarray) -> None:
    """The photograph of Tables 1 and 2 and the independent plate's points inside the
    calibrated area, and that inside the calibration grid's nodes ``g``: an area whose edges
    are not on the grid at ``plate.spacing_mm`` (25 mm on the paper's -40 to 60 mm) left the
    grid short of it, and the photograph and the check points there were corrected by the
    polynomial extrapolated (P44)."""
    a = cfg["plate.area_mm"]
    for key in ("repeat.format_mm", "repeat.centre_mm"):
        require(len(cfg[key]) == 2, key, "must have two entries")
    (w, h), (cx, cy) = cfg["repeat.format_mm"], cfg["repeat.centre_mm"]
    photo = (cx - w / 2, cx + w / 2, cy - h / 2, cy + h / 2)
    require(
        _inside(photo, a, 0.0),
        "repeat.format_mm",
        "the photograph must lie inside the calibrated area "
        "(the polynomial is not meant to extrapolate)",
    )
    span = (g[:, 0].min(), g[:, 0].max(), g[:, 1].min(), g[:, 1].max())
    m5 = CHECK_MARGIN_MM  # the independent plate's points: the area less this margin
    checks = (a[0] + m5, a[1] - m5, a[2] + m5, a[3] - m5)
    for what, box in (
        ("the photograph (repeat.format_mm, repeat.centre_mm)", photo),
        ("the independent plate's points (plate.area_mm less 5 mm)", checks),
    ):
        require(
            _inside(box, span),
            "plate.spacing_mm",
            f"the calibration grid at {cfg['plate.spacing_mm']:g} mm has its nodes over x "
            f"{span[0]:g} to {span[1]:g} mm and y {span[2]:g} to {span[3]:g} mm, short of "
            f"plate.area_mm {_box(a)}: {what} over {_box(box)} would be corrected by the "
            "polynomial extrapolated; give an area whose edges lie on the grid (multiples "
            "of the spacing)",
        )


def _box(b) -> str:
    return f"[{', '.join(f'{v:g}' for v in b)}]"


def _chunk_work(cfg: dict, g: np.ndarray) -> None:
    """At most :data:`MAX_CHUNK_CELLS` readings in a chunk of any part."""
    mid = mid_cells(cfg["plate.area_mm"], cfg["plate.spacing_mm"])
    m = (len(g) + len(mid)) * cfg["calib.n_sets"] + cfg["check.n_points"]
    m += 2 * (cfg["repeat.n_points"] + 4)
    nmax = max([cfg["reading.n"], *cfg["trade.readings"]])
    for key in ("chunk", "trade.trials", "unprinted.trials"):
        per = min(cfg[key], cfg["chunk"]) * m * 2 * nmax
        require(
            per <= MAX_CHUNK_CELLS,
            key,
            f"a chunk would hold {per:.3g} readings (trials x points x "
            f"readings), more than {MAX_CHUNK_CELLS:g}: use a smaller chunk",
        )


def check(cfg: dict) -> None:
    """Cross-key rules of ``wolf_polynomial``, in this order: the grids, the field's spread,
    the photograph, the work per chunk; the transcribed tables are parsed here too, so a
    wrong file stops the run at load time with one line naming its key."""
    g = _grids(cfg)
    spread = cfg["field.spread"]
    require(
        len(spread) == 2 and spread[0] <= spread[1],
        "field.spread",
        "must be [lo, hi] with lo <= hi",
    )
    _photograph(cfg, g)
    _chunk_work(cfg, g)
    tables.load_table1(table_path(cfg, "table1.file"), "table1.file")
    tables.load_table3(table_path(cfg, "table3.file"), "table3.file")
    for t in ("table1", "table3"):
        cfg[f"{t}.sha256"] = table_digest(cfg, t)


def table_digest(cfg: dict, t: str) -> str:
    """The sha256 of the file ``cfg["<t>.file"]`` names, which must be ``cfg["<t>.sha256"]``
    when that is given (recorded at load): the config, and so the staleness of the results
    (``--stale-only``, ``make verify``, a resumed run, the API's handle), holds the table's
    contents, not only its path. An edited table was "up to date"."""
    key = f"{t}.sha256"
    path = table_path(cfg, f"{t}.file")
    try:
        sha = hashlib.sha256(path.read_bytes()).hexdigest()
    except OSError as e:
        raise ConfigError(f"{t}.file", f"{path}: {e.strerror or e}") from None
    have = recorded_sha256(key, cfg.get(key))
    require(
        not have or have == sha,
        key,
        f"{path} has changed since the study was loaded (sha256 {sha[:12]}..., recorded "
        f"{str(have)[:12]}...): load the study again",
    )
    return sha
