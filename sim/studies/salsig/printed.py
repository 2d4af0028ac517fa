"""What Salsig (seed ``002_fb81c7b0481438c4.txt``) prints in FIG. 2 and FIG. 3, as data.

Paper values are references only: the paper-check rows recompute the printed decompositions
and unit-weight errors from these numbers. Residual magnitudes are used because the OCR
loses most signs (a sum of squares does not need them); FIG. 3 lists 24 of its 25 points
(825 is missing in the OCR). FIG. 2's coordinates of the marks 801-825 in the grid system;
the sign of 813's x (printed "250") is read as negative.
"""

from __future__ import annotations

#: FIG. 2 and FIG. 3 parameters A-F as printed (D negative: see sim.instruments.transforms2d)
FIG2 = (0.999929623, 0.011191034, -117.846539270, -0.011258985, 0.999916040, -116.507525374)
FIG3 = (12.700044103, 0.027714040, -2625.077266139, -0.031355021, 12.701997895, -5081.092972783)
#: printed decompositions (SX, SY, E arcsec)
FIG2_PRINTED = (0.999993007, 0.999978669, -14.0)
FIG3_PRINTED = (12.700082809, 12.702028129, -59.2)

#: |VX2|, |VY2| of FIG. 2 (grid intersections 1-25), units of the printed table (mm)
FIG2_RES = (
    (1, 1),
    (3, 1),
    (7, 1),
    (0, 3),
    (7, 3),
    (5, 3),
    (1, 3),
    (7, 2),
    (1, 3),
    (1, 5),
    (1, 2),
    (1, 5),
    (4, 1),
    (0, 0),
    (0, 0),
    (0, 3),
    (6, 5),
    (2, 1),
    (1, 2),
    (0, 1),
    (0, 0),
    (2, 2),
    (2, 3),
    (1, 0),
    (3, 1),
)
#: |VX2|, |VY2| of FIG. 3 (marks 801-824; 825 not legible), in B8 digits
FIG3_RES = (
    (3, 0),
    (3, 3),
    (3, 2),
    (1, 2),
    (3, 2),
    (0, 1),
    (1, 1),
    (3, 0),
    (1, 1),
    (2, 2),
    (4, 2),
    (1, 2),
    (2, 1),
    (1, 1),
    (1, 2),
    (3, 0),
    (2, 0),
    (1, 1),
    (1, 0),
    (3, 1),
    (1, 0),
    (3, 1),
    (2, 0),
    (1, 1),
)
RES_UNIT = 1e-3  # the residual tables print three decimals
N_POINTS = 25  # points of each affine (both figures)

#: FIG. 2 grid-system coordinates of the steel-point marks 801-825 (mm), rows of the 5 x 5
MARKS_XY = (
    (-97.679, -98.689),
    (-49.656, -99.749),
    (0.953, -101.269),
    (49.596, -102.766),
    (97.910, -104.087),
    (-99.450, -51.019),
    (-48.017, -50.400),
    (1.068, -51.803),
    (51.977, -53.056),
    (100.124, -51.954),
    (-99.651, -1.602),
    (-50.137, -2.438),
    (-0.250, -1.693),
    (49.289, -2.836),
    (100.069, -4.282),
    (-94.639, 45.715),
    (-49.453, 47.338),
    (2.117, 46.876),
    (52.198, 46.852),
    (102.277, 46.284),
    (-98.965, 96.314),
    (-49.205, 97.292),
    (1.114, 97.268),
    (51.369, 95.813),
    (100.823, 96.592),
)
INCH_MM = 25.4
