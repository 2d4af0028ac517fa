"""brown_design's data check (:attr:`sim.studies.Study.data`): its claim book read over the
validated config. Imported when a valid config is checked (it loads the claim machinery:
SciPy, Arrow), not when a study file is refused."""

from __future__ import annotations

from sim.studies import data_check
from sim.studies.design.claims import load_book, scored_ids

__all__ = ["DATA"]

DATA = data_check(load_book, scored=scored_ids)
