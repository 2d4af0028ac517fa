"""The frames of a GNU Gama ``gama-local`` file: ``axes-xy`` (ne, its turns es, sw, wn and the
right-handed en, nw, se, ws) and the sense of its angles (``angles``: left- or right-handed).
This suite's bearings run from +x towards +y: the file's convention when its frame and its
angles have the same handedness (:func:`consistent`); otherwise each direction and angle of the
file is the suite's with its sign changed, which leaves every covariance unchanged
(tests/test_gama27.py compares all 16 combinations with ``gama-local``). Read by
:mod:`sim.studies.network.gama_read`, written by :mod:`sim.studies.network.gama`."""

from __future__ import annotations

__all__ = ["FRAMES", "LEFT_HANDED", "NE", "consistent", "frame_note"]

#: gama-local's frames (``axes-xy``): the left-handed ones (x to y clockwise) are ne and its
#: turns by 90, 180 and 270 degrees, the right-handed ones their mirror images
FRAMES = {
    "ne": "x north, y east",
    "es": "x east, y south: ne turned 90 degrees",
    "sw": "x south, y west: ne turned 180 degrees",
    "wn": "x west, y north: ne turned 270 degrees",
    "en": "x east, y north: right-handed",
    "nw": "x north, y west: right-handed",
    "se": "x south, y east: right-handed",
    "ws": "x west, y south: right-handed",
}
LEFT_HANDED = ("ne", "es", "sw", "wn")
#: gama-local's default frame, the suite's own: (axes-xy, angles), x north, y east, clockwise
NE = ("ne", "left-handed")


def consistent(axes: str, angles: str) -> bool:
    """The frame and the angles have the same handedness: a direction is a bearing from +x
    towards +y (minus its orientation), as this suite's; otherwise from +x towards -y."""
    return (axes in LEFT_HANDED) == (angles == "left-handed")


def frame_note(axes: str, angles: str) -> str:
    """What the report says of a file's frame (``""`` for gama-local's default, ne with
    left-handed angles)."""
    if (axes, angles) == NE:
        return ""
    note = (
        f"; axes-xy = {axes!r} ({FRAMES[axes]}), {angles} angles: coordinates and covariances "
        "are in the file's frame, ellipse bearings from +x towards +y"
    )
    if consistent(axes, angles):
        return note + " (the sense of its angles)"
    return note + (
        " (against its angles, which run from +x towards -y: each direction and angle only "
        "changes sign, which leaves every covariance unchanged)"
    )
