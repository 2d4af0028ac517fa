"""The README's table of a study's inputs set to match the paper (the schema's fields marked
``input``): every digit as the study file sets it, and a value the run set to another than
the paper's marked as this run's (it was listed as "set to match the paper")."""

from __future__ import annotations

import math

from sim.mc.numtext import shows_differently
from sim.report.tables import fmt, md_table

__all__ = ["as_set", "inputs_markdown"]


def as_set(v) -> str:
    """An input as the study file sets it (every digit: 12.702028129 was shown as 12.7)."""
    if isinstance(v, float) and math.isfinite(v):
        return repr(v)
    return fmt(v)


def inputs_markdown(cfg: dict, schema) -> str:
    """List the config values marked as paper-matched inputs; one this run set to another
    value than the paper's is marked so (it was listed as "set to match the paper")."""
    rows, changed = [], 0
    for k, f in schema.items():
        if not f.input:
            continue
        v = cfg.get(k)
        text = as_set(v)
        if shows_differently(v, f.default):  # 12 digits: a swept 1.1 + 0.6 is 1.7
            changed += 1
            text += f" (this run; the paper's: {as_set(f.default)})"
        rows.append([f"`{k}`", text, f.doc])
    if not rows:
        return ""
    but = (
        f"; {changed} of them this run sets to another value, marked: there agreement is no "
        "longer by construction"
        if changed
        else ""
    )
    return (
        "Inputs set to match the paper (agreement with these is by construction, not a "
        f"prediction{but}):\n\n" + md_table(["key", "value", "meaning"], rows)
    )
