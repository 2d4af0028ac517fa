"""salsig_encoders' checks that read its data files: the keys' check with the control errors the
region (region.toml) explores (:attr:`sim.studies.Study.check`), and the data check
(:attr:`sim.studies.Study.data`): its claim book and region declaration over the validated
config. Imported when a study file's keys are known (it loads the claim machinery: SciPy,
Arrow), not when one of them is refused as unknown."""

from __future__ import annotations

from sim.studies import data_check
from sim.studies.salsig.claims import load_book, scored_ids
from sim.studies.salsig.region import _KEYS, DECLARATION, check_vertical, nominal
from sim.studies.salsig.schema import check as check_keys

__all__ = ["DATA", "check"]


def check(cfg: dict) -> None:
    """The schema's cross-key rules, then the control errors the region explores."""
    check_keys(cfg)
    check_vertical(cfg)


DATA = data_check(
    load_book,
    (DECLARATION, nominal, {**_KEYS, "control_1": "vertical.control"}),
    scored=scored_ids,
)
