"""wolf_polynomial's data check (:attr:`sim.studies.Study.data`): its claim book and region
declaration read over the validated config. Imported when a valid config is checked (it
loads the claim machinery: SciPy, Arrow), not when a study file is refused."""

from __future__ import annotations

from sim.studies import data_check
from sim.studies.wolf.claims import load_book, scored_ids
from sim.studies.wolf.region import CELL, DECLARATION, nominal

__all__ = ["DATA"]

DATA = data_check(
    load_book,
    (DECLARATION, nominal, {k: v for k, v in CELL.items() if "." in v}),
    scored=scored_ids,
)
