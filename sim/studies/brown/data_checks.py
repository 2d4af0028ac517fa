"""brown_dilution's and brown_table1's data checks (:attr:`sim.studies.Study.data`): the
claim book read over the validated config, with the ids each run scores. Imported when a
valid config is checked (it loads the claim machinery: SciPy, Arrow), not when a study file
is refused."""

from __future__ import annotations

from sim.studies import data_check
from sim.studies.brown.claim_ids import T1_JOINT, T1_PREDICTIONS
from sim.studies.brown.claims import load_book, scored_by
from sim.studies.brown.schema import MODEL_NAMES

__all__ = ["DILUTION_DATA", "TABLE1_DATA"]


def _dilution_ids(cfg: dict, book) -> list[str]:
    """The ids brown_dilution builds (:func:`.claims.score_dilution`)."""
    return [f"brown.mc_agreement.{m}.mean_ratio" for m in MODEL_NAMES]


def _table1_ids(cfg: dict, book) -> list[str]:
    """The ids brown_table1 builds: Table 1's statements over the region (:mod:`.region`)."""
    return [*T1_PREDICTIONS, T1_JOINT]


DILUTION_DATA = data_check(
    lambda: load_book("brown_dilution"),
    scores=scored_by("brown_dilution"),
    scored=_dilution_ids,
)
TABLE1_DATA = data_check(
    lambda: load_book("brown_table1"), scores=scored_by("brown_table1"), scored=_table1_ids
)
