"""Desktop-scanner deformation of scanned aerial photographs, its calibration from a scanned
grid, and the interior orientation by fiducial marks.

Seed: ``003_5ce730a990a7ebc5.txt`` (Agnard, Nolette & Gagnon): photographs scanned at 600 DPI
on a Sharp JX-600; "maximum deformations found after calibration of the scanner were
+-20 um in the x direction and +-40 um in the y direction"; deformations negligible at
300 DPI for plotting must be corrected at 600 DPI for aerotriangulation.

Model. A flatbed scanner moves a CCD line (along x) with a stepper drive (along y). Its
deformation is a smooth field over the photo format, in micrometres,

    dx(u, v) = sum_k a_k P_k(u, v),
    dy(u, v) = sum_k b_k P_k(u, v) + c1 sin(2 pi y / lambda) + c2 cos(2 pi y / lambda),

with ``P_k`` the products of Legendre polynomials of total degree 2 and 3 in the normalised
coordinates ``u = x / h``, ``v = y / h`` (``h`` the half format) and a periodic term of the
stepper drive of wavelength ``lambda``. The affine part is left out on purpose: the fiducial
transformation of the interior orientation removes it anyway, and the paper's maxima are
what remains after it. Each Monte-Carlo trial draws a scanner (Gaussian coefficients)
scaled so that ``max |dx|`` and ``max |dy|`` over the format equal the stated maxima.

Calibration. A grid plate (spacing ``g``) is scanned and its nodes measured with a
centring error; the correction at any point is the bilinear interpolation of the measured
node displacements. What is left is interpolation error plus the (systematic, the same for
every photo) node-measurement noise.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.polynomial import legendre

from sim.lsq.linear import lstsq

__all__ = [
    "ScannerField",
    "random_field",
    "evaluate",
    "scan_grid",
    "interpolate",
    "fiducial_affine",
    "corner_fiducials",
    "image_errors",
    "pixel_um",
    "DEGREES",
]

#: (i, j) Legendre degrees in u and v of the non-affine polynomial terms
DEGREES = ((2, 0), (1, 1), (0, 2), (3, 0), (2, 1), (1, 2), (0, 3))


def pixel_um(dpi: float) -> float:
    """Pixel size in micrometres at ``dpi`` dots per inch (600 DPI -> 42.3 um)."""
    return 25_400.0 / dpi


def _legendre(t: np.ndarray, deg: int) -> np.ndarray:
    c = np.zeros(deg + 1)
    c[deg] = 1.0
    return legendre.legval(t, c)


def _basis(xy_mm: np.ndarray, half_mm: float, wavelength_mm: float):
    """Polynomial basis ``(n, 7)`` and stepper basis ``(n, 2)`` at ``xy_mm`` ``(n, 2)``."""
    u = xy_mm[:, 0] / half_mm
    v = xy_mm[:, 1] / half_mm
    poly = np.stack([_legendre(u, i) * _legendre(v, j) for i, j in DEGREES], -1)
    ph = 2.0 * np.pi * xy_mm[:, 1] / wavelength_mm
    return poly, np.stack([np.sin(ph), np.cos(ph)], -1)


@dataclass(frozen=True)
class ScannerField:
    """A batch of scanner deformation fields.

    a : (T, 7) coefficients of dx (um); b : (T, 7) and c : (T, 2) of dy (um);
    half_mm : half the format side; wavelength_mm : period of the stepper term.
    """

    a: np.ndarray
    b: np.ndarray
    c: np.ndarray
    half_mm: float
    wavelength_mm: float


def evaluate(field: ScannerField, xy_mm: np.ndarray) -> np.ndarray:
    """Deformation ``(T, n, 2)`` in um at image positions ``xy_mm`` ``(n, 2)``."""
    poly, step = _basis(np.asarray(xy_mm, float), field.half_mm, field.wavelength_mm)
    dx = field.a @ poly.T
    dy = field.b @ poly.T + field.c @ step.T
    return np.stack([dx, dy], -1)


def random_field(
    rng: np.random.Generator,
    trials: int,
    *,
    max_x_um: float,
    max_y_um: float,
    stepper_share: float = 0.3,
    wavelength_mm: float = 60.0,
    half_mm: float = 115.0,
    n_eval: int = 47,
) -> ScannerField:
    """Draw ``trials`` scanners whose fields peak at ``max_x_um`` in x and ``max_y_um`` in y.

    Coefficients are standard normal; the stepper term of dy is scaled to ``stepper_share``
    of the polynomial part's peak before the whole of dy is scaled to ``max_y_um``. The
    peaks are taken on an ``n_eval`` x ``n_eval`` grid over the format.
    """
    g = np.linspace(-half_mm, half_mm, n_eval)
    xy = np.stack(np.meshgrid(g, g), -1).reshape(-1, 2)
    poly, step = _basis(xy, half_mm, wavelength_mm)
    a = rng.standard_normal((trials, len(DEGREES)))
    b = rng.standard_normal((trials, len(DEGREES)))
    c = rng.standard_normal((trials, 2))
    a *= max_x_um / np.abs(a @ poly.T).max(axis=1, keepdims=True)
    b /= np.abs(b @ poly.T).max(axis=1, keepdims=True)
    c *= stepper_share / np.abs(c @ step.T).max(axis=1, keepdims=True)
    s = max_y_um / np.abs(b @ poly.T + c @ step.T).max(axis=1, keepdims=True)
    return ScannerField(a, b * s, c * s, half_mm, wavelength_mm)


def scan_grid(
    field: ScannerField, rng: np.random.Generator, spacing_mm: float, sigma_um: float
) -> tuple[np.ndarray, np.ndarray]:
    """Scan a grid plate: node positions ``(g,)`` (mm, the same in x and y) and the measured
    node displacements ``(T, g, g, 2)`` in um (true deformation + centring noise), indexed
    ``[trial, iy, ix, xy]``. The grid covers the format with nodes on its edges."""
    n = int(np.ceil(2 * field.half_mm / spacing_mm - 1e-9)) + 1
    nodes = np.linspace(-field.half_mm, field.half_mm, n)
    xx, yy = np.meshgrid(nodes, nodes)
    xy = np.column_stack([xx.ravel(), yy.ravel()])
    d = evaluate(field, xy)
    d = d + rng.normal(0.0, sigma_um, d.shape)
    return nodes, d.reshape(d.shape[0], n, n, 2)


def interpolate(nodes: np.ndarray, disp: np.ndarray, xy_mm: np.ndarray) -> np.ndarray:
    """Bilinear interpolation of node displacements ``(T, g, g, 2)`` at ``xy_mm`` ``(n, 2)``,
    returning ``(T, n, 2)`` (um). Points outside the grid use the border cells."""
    g = nodes.size
    h = nodes[1] - nodes[0]
    fx = np.clip((xy_mm[:, 0] - nodes[0]) / h, 0, g - 1 - 1e-9)
    fy = np.clip((xy_mm[:, 1] - nodes[0]) / h, 0, g - 1 - 1e-9)
    ix, iy = fx.astype(int), fy.astype(int)
    tx, ty = (fx - ix)[None, :, None], (fy - iy)[None, :, None]
    return (
        (1 - tx) * (1 - ty) * disp[:, iy, ix]
        + tx * (1 - ty) * disp[:, iy, ix + 1]
        + (1 - tx) * ty * disp[:, iy + 1, ix]
        + tx * ty * disp[:, iy + 1, ix + 1]
    )


def fiducial_affine(err_fid: np.ndarray, fid_mm: np.ndarray) -> np.ndarray:
    """Affine part of the fiducial errors removed by the interior orientation.

    The 6-parameter affine from the measured to the nominal fiducials absorbs the affine
    part of the fiducials' errors. To first order in the errors (um against mm) the error
    left at a point ``x`` is ``e(x) - [1, x, y] beta`` with ``beta`` the least-squares affine
    fit to the fiducial errors. err_fid : (..., F, 2) errors at the F fiducials (um);
    fid_mm : (F, 2). Returns ``beta`` (..., 3, 2) (um, um/mm): the library's one linear
    routine, the fiducial design factorised once for every trial and photo.
    """
    A = np.column_stack([np.ones(len(fid_mm)), fid_mm])  # (F, 3), shared
    e = np.asarray(err_fid, float)
    f = lstsq(A, e.reshape((-1,) + e.shape[-2:]))
    return f.x.reshape(e.shape[:-2] + (3, 2))


def corner_fiducials(offset_mm: float) -> np.ndarray:
    """Four corner fiducials at ``(+-offset, +-offset)`` mm, shape (4, 2)."""
    o = offset_mm
    return np.array([[-o, -o], [o, -o], [o, o], [-o, o]], float)


def image_errors(
    field: ScannerField,
    xy_mm: np.ndarray,
    photo: np.ndarray,
    fid_mm: np.ndarray,
    fid_noise_um: np.ndarray,
    grid: tuple[np.ndarray, np.ndarray] | None = None,
) -> np.ndarray:
    """Scanner error left in image coordinates after interior orientation, (T, K, 2) um.

    xy_mm : (K, 2) ideal image positions of the measurements; photo : (K,) which scan each
    lies on (all photos are scanned on the same scanner, so the deformation at a given
    image position is the same on every photo; only the fiducial measurements differ).
    fid_mm : (F, 2) nominal fiducials; fid_noise_um : (T, n_photos, F, 2) their centring
    errors. ``grid = (nodes, disp)`` from :func:`scan_grid` applies the calibration
    (bilinear correction) first.
    """
    d = evaluate(field, xy_mm)
    df = evaluate(field, fid_mm)  # (T, F, 2)
    if grid is not None:
        d = d - interpolate(grid[0], grid[1], xy_mm)
        df = df - interpolate(grid[0], grid[1], fid_mm)
    ef = df[:, None] + fid_noise_um
    beta = fiducial_affine(ef, fid_mm)[:, photo]  # (T, K, 3, 2)
    Ap = np.column_stack([np.ones(len(xy_mm)), xy_mm])  # (K, 3)
    return d - np.einsum("kj,tkjc->tkc", Ap, beta)
