"""The line on a run off the paper's setup (its printed inputs not the paper's): what
README.md says at its top, ``sim check`` before the run, and ``sim show`` and the end of
``sim run`` below their counts, in the same words."""

from __future__ import annotations

from pathlib import Path
from typing import Callable

from sim.claims.rules import printed_differs
from sim.mc.config import ConfigError
from sim.mc.storage import read_provenance
from sim.mc.sweep import expand

__all__ = ["off_setup", "off_note", "sweep_off_note"]


def off_setup(study, cfg: dict, before: bool = False) -> str:
    """``off the paper's setup (key = value (paper: default), ...): its predictions are
    findings ...`` for a config whose printed inputs are not the paper's (``sim check`` says
    it before the run, ``before``: "will be"; a run's README.md at its top: it said so only
    in its claims' notes), else ``""``. The predictions decided on the paper's setup were
    named in a clause without its verb ("findings, but the 5 it decides on the paper's own
    setup, which stay the paper's verdicts")."""
    off = printed_differs(study.schema, cfg, study.as_printed)
    if not off:
        return ""
    kept = len(study.paper_design)
    but = (
        f", except the {kept} it decides on the paper's own setup whatever the run's: those "
        "stay the paper's verdicts"
        if kept
        else ""
    )
    verb = "will be" if before else "are"
    return f"off the paper's setup ({', '.join(off)}): its predictions {verb} findings{but}"


def off_note(out: Path, get_study: Callable | None) -> str:
    """README.md's line on a run off the paper's setup (:func:`off_setup`), for the doors that
    print the same directory in a terminal (``sim show``, the end of ``sim run``: they said
    nothing of it), or ``""`` (no ``get_study``, or on the paper's setup)."""
    if get_study is None:
        return ""
    prov = read_provenance(Path(out) / "claims.parquet")
    off = off_setup(get_study(prov["study"]), prov.get("config") or {})
    return off[:1].upper() + off[1:]


def sweep_off_note(out: Path, get_study: Callable | None) -> str:
    """The line on a sweep's cells off the paper's setup (each cell's README-less results are
    decided as :func:`off_setup` says), for its README.md, ``sim show`` and the end of ``sim
    run``, or ``""``: a sweep of a printed key (``errors.settings = [1, 2]``) said nothing of
    it, where ``sim show`` of its cell ``errors.settings = 1`` says its predictions are
    findings. Its cells are the run's, in the order of its keys (``sweep_keys``): the record's
    table, its keys sorted, named ``cell0001`` with another cell's values."""
    if get_study is None:
        return ""
    prov = read_provenance(Path(out) / "sweep.parquet")
    cfg = prov.get("config") if isinstance(prov.get("config"), dict) else {}
    table, order = prov.get("sweep") or {}, prov.get("sweep_keys")
    try:
        if isinstance(table, dict) and isinstance(order, list):  # the record's keys sorted:
            table = {**{k: table[k] for k in order if k in table}, **table}  # the run's order
        study = get_study(prov.get("study"))
        cells = expand(table)[1]
    except (ConfigError, TypeError, AttributeError):  # a provenance edited by hand: no line
        return ""
    off = [
        (i, w)
        for i, c in enumerate(cells)
        if (w := printed_differs(study.schema, {**cfg, **c}, study.as_printed))
    ]
    if not off:
        return ""
    (i, words), more = off[0], " ..." if len(off) > 1 else ""
    return (
        f"Off the paper's setup in {len(off)} of {len(cells)} cells (cell{i:04d}: "
        f"{', '.join(words)}{more}): their predictions are findings (sim show of a cell says which)"
    )
