"""agnard_block's data check (:attr:`sim.studies.Study.data`): its claim book and region
declarations read over the validated config. Imported when a valid config is checked (it
loads the claim machinery: SciPy, Arrow), not when a study file is refused."""

from __future__ import annotations

from sim.studies import data_check
from sim.studies.agnard.claims import load_book, scored_ids
from sim.studies.agnard.region import CENTRES, DECLARATION, INSET, SCANNER, SCANNER_KEYS

__all__ = ["DATA"]

DATA = data_check(
    load_book,
    (DECLARATION, lambda cfg: (CENTRES, "five_inset_1"), {"five_inset_1": INSET}),
    (SCANNER, lambda cfg: SCANNER_KEYS, SCANNER_KEYS),
    scored=scored_ids,
)
