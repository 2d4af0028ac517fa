"""gridplate_two_plates' checks that read its data files: the keys' check with the comparator
the region (region.toml) explores (:attr:`sim.studies.Study.check`), and the data check
(:attr:`sim.studies.Study.data`): its claim book and region declaration over the validated
config. Imported when a study file's keys are known (it loads the claim machinery: SciPy,
Arrow), not when one of them is refused as unknown."""

from __future__ import annotations

from sim.studies import data_check
from sim.studies.gridplate.beyond import scored_ids
from sim.studies.gridplate.claims import load_book
from sim.studies.gridplate.region import DECLARATION, SCALE_DIFF_KEYS, check_comparator, nominal
from sim.studies.gridplate.schema import check as check_keys

__all__ = ["DATA", "check"]


def check(cfg: dict) -> None:
    """The schema's cross-key rules, then the comparator the region explores."""
    check_keys(cfg)
    check_comparator(cfg)


DATA = data_check(
    load_book,
    (
        DECLARATION,
        nominal,
        {
            "grid_points_1": "plate.grid",
            "spacing_mm": "plate.spacing_mm",
            "grid_sigma_true_um": "grid.sigma_true_um",
            "scale_diff_at_100mm_um": SCALE_DIFF_KEYS,
        },
    ),
    scored=scored_ids,
)
