"""Keys of the shipped study files that an older version of the suite read and this one
does not: a study file kept from before an upgrade is told so, and what replaced the key.

Every study's sweep of its unprinted inputs (``[consistency]`` in Brown's, the grid plates'
and Salsig's files, ``[unprinted]`` lists in brown_design's and Wolf's, the ``sweep.*`` keys
of agnard_block, Brown's earlier ``dilution.offsets_mm``) was replaced on 2026-11-26 by the
joint exploration ``[region]`` over the ranges the study declares. Such a
file was refused as ``unknown key`` with a guess from the new keys that is not the
replacement (``consistency.grid`` -> ``did you mean plate.grid?``, a key the file already
sets; ``unprinted.offsets_mm`` -> ``design.offsets_mm``), or, for agnard's ``sweep.trials``,
as "a key of" seven other studies. The table below lists the keys of every shipped file
since the first commit (``git log -- studies/``) that no study reads now.

Applied by :func:`sim.studies.ported.foreign_key` where a study file is loaded for a
command; no study imports it (the wording is no part of any study's code hash).
"""

from __future__ import annotations

__all__ = ["RETIRED", "retired_note"]

_SWEEP = "its sweep of the unprinted inputs"

#: study -> {retired key: (the version that dropped it, what it was)}
RETIRED: dict[str, dict[str, tuple[str, str]]] = {
    "brown_dilution": {
        **{
            f"consistency.{k}": ("2026-11-26", "[consistency], " + _SWEEP)
            for k in ("offset_min_mm", "offset_max_mm", "offset_step_mm", "extents_mm")
        },
        "dilution.offsets_mm": ("2026-11-23", "the swept station offsets"),
        "dilution.extents_mm": ("2026-11-23", "the swept plate extents"),
    },
    "brown_table1": {
        f"consistency.{k}": ("2026-11-26", "[consistency], " + _SWEEP)
        for k in ("offset_min_mm", "offset_max_mm", "offset_step_mm")
    },
    "gridplate_two_plates": {
        f"consistency.{k}": ("2026-11-26", "[consistency], " + _SWEEP)
        for k in ("grid", "spacing_mm", "readings", "scale_diff_ppm", "grid_sigma_true_um", "draws")
    },
    "salsig_encoders": {
        **{
            f"consistency.{k}": ("2026-11-26", "[consistency], " + _SWEEP)
            for k in (
                "relief_mm",
                "sigma_z_um",
                "control",
                "b8_sigma_um",
                "comparator_sigma_um",
                "trials",
            )
        },
        "vertical.relief_sweep_mm": ("2026-11-23", "the swept relief"),
    },
    "brown_design": {
        f"unprinted.{k}": ("2026-11-26", _SWEEP)
        for k in ("offsets_mm", "betas_mm", "pass_min", "pitches_mm", "zeiss_extents_mm")
    },
    "wolf_polynomial": {
        f"unprinted.{k}": ("2026-11-26", _SWEEP)
        for k in (
            "pointing_sigmas_um",
            "field_scales",
            "mono_sigmas_um",
            "drift_fractions",
            "restitutions_um",
        )
    },
    "agnard_block": {
        f"sweep.{k}": ("2026-11-26", "its sweep of the unprinted five-point layout")
        for k in ("trials", "five_inset")
    },
}


def retired_note(study: object, key: str) -> str | None:
    """The refusal's text for ``key`` in a file of ``study`` when an older version of the
    suite read it, else None."""
    hit = RETIRED.get(study, {}).get(key) if isinstance(study, str) else None
    if hit is None:
        return None
    when, what = hit
    return (
        f"a key of an older version of the suite ({what}), gone since {when}: [region] now "
        "explores the unprinted inputs jointly over their declared ranges (sim check lists "
        "the keys read now): leave it out"
    )
