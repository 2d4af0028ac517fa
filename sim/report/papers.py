"""The five seed papers by authors and year (the OCR files in ``../shared/seeds/`` are named
by number and hash; readers see these names instead)."""

from __future__ import annotations

__all__ = ["PAPERS", "paper_name"]

#: seed file number -> (short name, full reference)
PAPERS = {
    "000": (
        "Wolf & Pearsall 1976",
        "Wolf & Pearsall, The Kern PG-2 as a Monocomparator, PE&RS 42(10), 1976",
    ),
    "001": (
        "Ohio State two-plate calibration (early 1970s)",
        "Calibration of a Comparator (two grid plates, Zeiss PSK stereocomparator, Ohio State "
        "University), Photogrammetric Engineering, early 1970s",
    ),
    "002": (
        "Salsig 1985",
        "Salsig, Calibrating Stereo Plotter Encoders, PE&RS 51(10), 1985",
    ),
    "003": (
        "Agnard, Nolette & Gagnon (early 1990s)",
        "Agnard, Nolette & Gagnon, PC-based integrated digital pugging and measurements for "
        "block adjustments, early 1990s",
    ),
    "004": (
        "Brown 1968",
        "Brown, Computational Tradeoffs in the Design of a Comparator, Photogrammetric "
        "Engineering, 1968",
    ),
}


def paper_name(seed_file: str | None, full: bool = False) -> str:
    """``"Brown 1968"`` for ``"004_f5bd9e86c308241f.txt"`` (the full reference with
    ``full``); a seed file not listed is returned as it is, no seed file as ``""``."""
    if not seed_file:
        return ""
    hit = PAPERS.get(str(seed_file)[:3])
    return hit[1 if full else 0] if hit else str(seed_file)
