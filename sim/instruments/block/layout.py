"""Geometry of an aerial block of independent stereomodels: strips x models, ground points,
pass points and the choice of control and check points.

Seed: ``003_5ce730a990a7ebc5.txt`` (Agnard, Nolette & Gagnon, *PC-based integrated digital
pugging and measurements for block adjustments*): two strips of eight models, photo scale
1:6 200, focal length 152 mm, base about 90 mm at photo scale, 178 signalised ground points
of which a subset is control, pass points between models and strips.

Conventions. Ground coordinates in metres, X along the flight lines, Y across, Z up.
Photography is the normal case: vertical photos at flying height ``H = f * scale`` above the
datum, photo ``i`` of strip ``s`` at ``(i * B, s * D, H)`` with ground base ``B`` and strip
spacing ``D = W (1 - sidelap)`` where ``W`` is the ground width of the format. Model ``m`` of
strip ``s`` is formed by photos ``m`` (left) and ``m + 1`` (right). A point belongs to a model
when it images inside ``usable`` times the half format on both photos. Everything here is
fixed for a run (one test field); the Monte-Carlo trials vary only the measurements.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Block", "make_block", "control_targets", "select_control", "CONTROL_PATTERNS"]

CONTROL_PATTERNS = ("corners", "five", "perimeter", "full")


@dataclass(frozen=True)
class Block:
    """A block of independent models (all lengths in metres unless stated).

    photos : (S, M + 1, 3) projection centres; points : (P, 3) ground points, the first
    ``n_ground`` signalised test-field points, then the pass points; obs_model, obs_point :
    (K,) which model observes which point (sorted by model); obs_left, obs_right : (K,) flat
    index (``s * (M + 1) + i``) of the left and right photo of the observing model;
    focal_mm, scale : camera constant and photo-scale number; base_m, strip_spacing_m, H_m.
    """

    strips: int
    models: int
    photos: np.ndarray
    points: np.ndarray
    n_ground: int
    obs_model: np.ndarray
    obs_point: np.ndarray
    obs_left: np.ndarray
    obs_right: np.ndarray
    focal_mm: float
    scale: float
    base_m: float
    strip_spacing_m: float
    H_m: float
    half_format_mm: float

    @property
    def n_models(self) -> int:
        return self.strips * self.models

    @property
    def n_points(self) -> int:
        return self.points.shape[0]

    @property
    def is_pass(self) -> np.ndarray:
        """(P,) True for the (artificial) pass points."""
        return np.arange(self.n_points) >= self.n_ground

    def extent(self) -> tuple[float, float, float, float]:
        """``(x0, x1, y0, y1)`` of the union of the model areas."""
        w = self.half_format_mm * 1e-3 * self.scale
        return (
            self.base_m - w,
            (self.models - 1) * self.base_m + w,
            -w,
            (self.strips - 1) * self.strip_spacing_m + w,
        )

    def image_coords(self, photo: np.ndarray, point: np.ndarray) -> np.ndarray:
        """Ideal image coordinates (mm) of ``point`` (K,) on flat ``photo`` index (K,), (K, 2)."""
        c = self.photos.reshape(-1, 3)[photo]
        p = self.points[point]
        return self.focal_mm * (p[:, :2] - c[:, :2]) / (c[:, 2:3] - p[:, 2:3])


def _visible(photos_xyz: np.ndarray, pts: np.ndarray, f_mm: float, half_mm: float) -> np.ndarray:
    """(n_photos, n_pts) True where the point images inside ``half_mm`` of the centre."""
    d = pts[None, :, :2] - photos_xyz[:, None, :2]
    xy = f_mm * d / (photos_xyz[:, None, 2:3] - pts[None, :, 2:3])
    return np.all(np.abs(xy) <= half_mm, axis=-1)


def _terrain(xy: np.ndarray, relief_m: float, extent) -> np.ndarray:
    """A smooth rolling terrain of peak-to-peak about ``relief_m``."""
    x0, x1, y0, y1 = extent
    u = (xy[:, 0] - x0) / (x1 - x0)
    v = (xy[:, 1] - y0) / (y1 - y0)
    z = np.sin(2.1 * np.pi * u + 0.4) * np.cos(1.3 * np.pi * v) + 0.5 * np.sin(4.3 * np.pi * u * v)
    return 0.5 * relief_m * z / 1.5


def make_block(
    strips: int = 2,
    models: int = 8,
    *,
    scale: float = 6200.0,
    focal_mm: float = 152.0,
    base_mm: float = 90.0,
    format_mm: float = 230.0,
    sidelap: float = 0.3,
    usable: float = 0.92,
    n_ground: int = 178,
    ground_density: float | None = None,
    pass_rows: int = 4,
    relief_m: float = 20.0,
    layout_seed: int = 7,
) -> Block:
    """Build the block.

    Ground points: ``n_ground`` signalised points spread over the block, one in each of
    ``n_ground`` randomly chosen cells of a square grid (a stratified random layout, like a
    surveyed test field), or, when
    ``ground_density`` (points per km^2) is given, as many as that density asks for (block-size
    studies). Pass points: columns at every photo nadir and model centre, ``pass_rows`` rows
    per strip spread over the usable width; a candidate is kept when at least two models
    see it (so the ones at model centres survive only in the sidelap, as tie points between
    strips). ``layout_seed`` fixes the test field (it is not a Monte-Carlo stream).
    """
    if strips < 1 or models < 1:
        raise ValueError("a block needs at least one strip and one model")
    H = focal_mm * 1e-3 * scale
    B = base_mm * 1e-3 * scale
    half = 0.5 * format_mm * usable
    W = format_mm * 1e-3 * scale
    D = W * (1.0 - sidelap)
    ii, ss = np.meshgrid(np.arange(models + 1), np.arange(strips))
    photos = np.stack([ii * B, ss * D, np.full(ii.shape, H)], -1).astype(float)
    flat = photos.reshape(-1, 3)
    w = half * 1e-3 * scale
    ext = (B - w, (models - 1) * B + w, -w, (strips - 1) * D + w)
    rng = np.random.default_rng(layout_seed)

    def in_models(xyz):
        vis = _visible(flat, xyz, focal_mm, half).reshape(strips, models + 1, -1)
        return vis[:, :-1] & vis[:, 1:]  # (S, M, n)

    # signalised test-field points: one per randomly chosen cell of a grid (stratified)
    area = (ext[1] - ext[0]) * (ext[3] - ext[2])
    if ground_density is not None:
        n_ground = max(8, int(round(ground_density * area * 1e-6)))
    side = np.sqrt(area / n_ground)
    while True:
        nx = int((ext[1] - ext[0]) // side)
        ny = int((ext[3] - ext[2]) // side)
        if nx * ny >= n_ground:
            break
        side *= 0.97
    x_off = ext[0] + 0.5 * ((ext[1] - ext[0]) - nx * side)
    y_off = ext[2] + 0.5 * ((ext[3] - ext[2]) - ny * side)
    cells = rng.choice(nx * ny, n_ground, replace=False)
    # jitter inside the cell, kept off the block edge by the relief's shrinking of the footprint
    lo = min(0.45, (relief_m / H * w + 1.0) / side)
    xy = (
        np.column_stack([cells % nx, cells // nx]) + rng.uniform(lo, 1 - lo, (n_ground, 2))
    ) * side + [x_off, y_off]
    ground = np.column_stack([xy, _terrain(xy, relief_m, ext)])

    # pass points
    cols = np.union1d(np.arange(models + 1) * B, (np.arange(models) + 0.5) * B)
    rows = np.concatenate(
        [s * D + np.linspace(-0.85 * w, 0.85 * w, pass_rows) for s in range(strips)]
    )
    cx, cy = np.meshgrid(cols, rows)
    pas = np.column_stack([cx.ravel(), cy.ravel()])
    pas = np.column_stack([pas, _terrain(pas, relief_m, ext)])
    pas = pas[in_models(pas).sum(axis=(0, 1)) >= 2]
    points = np.vstack([ground, pas])

    inc = in_models(points)  # (S, M, P)
    if not inc.any(axis=(0, 1)).all():
        raise ValueError("a ground point lies outside every model; lower the relief")
    s_idx, m_idx, p_idx = np.nonzero(inc)
    model = s_idx * models + m_idx
    order = np.lexsort((p_idx, model))
    model, p_idx, s_idx, m_idx = model[order], p_idx[order], s_idx[order], m_idx[order]
    left = s_idx * (models + 1) + m_idx
    return Block(
        strips,
        models,
        photos,
        points,
        ground.shape[0],
        model,
        p_idx,
        left,
        left + 1,
        focal_mm,
        scale,
        B,
        D,
        H,
        half,
    )


def control_targets(block: Block, pattern: str) -> np.ndarray:
    """Nominal control positions ``(n, 2)`` (m) of a named layout.

    ``corners``: the four block corners; ``five``: corners and centre; ``perimeter``: points
    every ~4/3 model bases along the first and last strip edges plus both block ends at
    every strip overlap; ``full``: the perimeter rows and one row in every strip overlap
    (3 x 7 = 21 for 2 x 8 models). The paper's figures 4 and 5 are lost from the seed; 5 and
    21 points in these layouts are our reading of its counts.
    """
    x0, x1, y0, y1 = block.extent()
    ix = 0.04 * (x1 - x0)
    iy = 0.04 * (y1 - y0)
    x0, x1, y0, y1 = x0 + ix, x1 - ix, y0 + iy, y1 - iy
    ncol = int(round(0.75 * block.models)) + 1
    xs = np.linspace(x0, x1, max(ncol, 2))
    mids = (np.arange(1, block.strips) - 0.5) * block.strip_spacing_m
    corners = np.array([[x0, y0], [x1, y0], [x0, y1], [x1, y1]])
    if pattern == "corners":
        return corners
    if pattern == "five":
        return np.vstack([corners, [[0.5 * (x0 + x1), 0.5 * (y0 + y1)]]])
    edge = np.vstack(
        [np.column_stack([xs, np.full_like(xs, y0)]), np.column_stack([xs, np.full_like(xs, y1)])]
    )
    if pattern == "perimeter":
        ends = np.array([[x, y] for y in mids for x in (x0, x1)]).reshape(-1, 2)
        return np.vstack([edge, ends])
    if pattern == "full":
        inner = np.array([[x, y] for y in mids for x in xs]).reshape(-1, 2)
        return np.vstack([edge, inner])
    raise ValueError(f"unknown control pattern {pattern!r}; known: {', '.join(CONTROL_PATTERNS)}")


def select_control(block: Block, pattern: str) -> np.ndarray:
    """Indices (into ``block.points``) of the signalised points nearest the pattern's targets."""
    t = control_targets(block, pattern)
    g = block.points[: block.n_ground, :2]
    chosen: list[int] = []
    for p in t:  # a handful of targets
        d = np.hypot(*(g - p).T)
        d[chosen] = np.inf
        chosen.append(int(np.argmin(d)))
    return np.array(sorted(chosen))
