"""A study file ported from another study: a key the study has not, that another study has,
is named with the study that reads it.

A study author who copies ``brown_dilution.toml`` and changes ``study`` to
``gridplate_two_plates`` (or keeps a network file's ``[network]`` under ``brown_table1``, or
a ``[sweep]`` of Brown's keys under a network) was told ``plate.format_mm: unknown key``,
with a guess from the new study's own keys (``did you mean block.format_mm?``: agnard's own
key, not Brown's plate): nothing said the key was Brown's, nor that a dozen more of
the file's keys were. :func:`foreign_key` says both in the one line of the refusal.

It is applied where a study file is loaded for a command (``sim check``/``run``, the batch's
checks, :func:`sim.load`), not inside :func:`sim.studies.load_study`, and no study imports it:
the refusal's wording is no part of any study's code hash (results stay current).
"""

from __future__ import annotations

import os
from typing import Mapping

from sim.mc.config import ConfigError, flatten, read_toml
from sim.mc.registry import MODULES
from sim.mc.sweep import read_sweep
from sim.studies import get_study
from sim.studies.retired import retired_note

__all__ = ["foreign_key"]

#: how many of the file's foreign keys the line shows before "and N more"
SHOWN = 3
#: the sweep's own keys (not config keys)
REPEAT = ("replicates", "seed_mode")


def _schemas(name: str) -> dict[str, Mapping]:
    """Every other study's schema (a study whose module does not load is left out)."""
    out = {}
    for other in MODULES:
        if other == name:
            continue
        try:
            out[other] = get_study(other).schema
        except (ConfigError, ImportError):
            continue
    return out


def foreign_key(e: ConfigError, path: str | os.PathLike) -> ConfigError:
    """``e``, or, when it refuses as an unknown key of the study file ``path``'s study a key
    that other studies have (a ``sweep.`` key too), one line naming those studies and, when
    the key is the file's own (not an override's), how many of the file's keys (and swept
    keys) are the likeliest one's, the first few by name."""
    if e.key == "study" and "missing" in str(e):
        return _missing_study(e, path)
    if not isinstance(e.key, str) or not e.detail.startswith("unknown key"):
        return e
    try:
        doc = read_toml(path)
        name = doc.get("study")
        value = doc.get(e.key)
        if isinstance(value, str) and value in MODULES:  # kind = "network"
            fix = f"leave {e.key} out"  # beside study = "network": "did you mean datum.kind?"
            if value != name:
                fix = f'for {value}, write study = "{value}" and {fix}'
            return ConfigError(
                e.key,
                'unknown key: a study file names its study by study = "..." alone '
                f"(this file's is {name}; {fix})",
            )
        schema = get_study(name).schema
        keys = list(flatten({k: v for k, v in doc.items() if k not in ("study", "sweep")}))
        try:
            keys += list(read_sweep(path)) if "sweep" in doc else []
        except ConfigError:
            pass
    except (ConfigError, OSError):  # the file as the load read it: nothing else to say
        return e
    if note := retired_note(name, e.key):  # a file kept from an older version of the suite
        old = [k for k in dict.fromkeys(keys) if retired_note(name, k)]
        more = f" and {len(old) - SHOWN} more" if len(old) > SHOWN else ""
        if len(old) > 1:
            note += f" (the file holds {len(old)} such keys: {', '.join(old[:SHOWN])}{more})"
        return ConfigError(e.key, note)
    swept = e.key.removeprefix("sweep.")
    if e.key == "sweep" or (swept != e.key and (swept in schema or swept in REPEAT)):
        return ConfigError(  # --set sweep.plate.grid=[4,5]: "a key of brown_dilution" (sic);
            e.key,  # --set 'sweep={plate.grid=[4,5]}', the same in TOML: "sweep: unknown key"
            f"unknown key: a sweep is not set by an override; write "
            f"{'its keys' if swept == 'sweep' else swept} in the study file's [sweep] table",
        )
    key = e.key.removeprefix("sweep.")
    schemas = _schemas(name)
    owners = [s for s, sch in schemas.items() if key in sch]
    if not owners:
        return e
    foreign = [k for k in dict.fromkeys(keys) if k not in schema]
    best = max(owners, key=lambda s: sum(k in schemas[s] for k in foreign))  # first on ties
    owners = [best, *(s for s in owners if s != best)]
    text = f"unknown key of the study {name}: a key of {', '.join(owners)}"
    if key in foreign:
        theirs = [k for k in foreign if k in schemas[best]]
        more = f" and {len(theirs) - SHOWN} more" if len(theirs) > SHOWN else ""
        text += (
            f" (the file holds {len(theirs)} key{'s' * (len(theirs) > 1)} of {best} that "
            f"{name} has not: {', '.join(theirs[:SHOWN])}{more}; a file copied from another "
            "study keeps that study's keys: leave them out)"
        )
    return ConfigError(e.key, text)


def _missing_study(e: ConfigError, path: str | os.PathLike) -> ConfigError:
    """``e`` (a file without ``study``), with the studies whose keys hold every key of the
    file (the line was deleted, or ``kind = ...`` written for it), when there are any."""
    try:
        doc = read_toml(path)
    except (ConfigError, OSError):
        return e
    named = [(k, v) for k, v in doc.items() if isinstance(v, str) and v in MODULES]
    if named:  # kind = "network" for study = "network": it fitted no study (kind is no key)
        key, value = named[0]
        return ConfigError(
            "study",
            f'missing: a study file names its study by study = "..." alone ({key} = '
            f'"{value}": write study = "{value}" in its place)',
        )
    common = ("trials", "seed", "chunk")  # every study's: they tell none apart
    keys = [k for k in flatten({k: v for k, v in doc.items() if k != "sweep"}) if k not in common]
    fits = [s for s, sch in _schemas("").items() if keys and all(k in sch for k in keys)]
    if not fits or len(fits) > SHOWN:
        return e
    return ConfigError(
        "study",
        f"{str(e).removeprefix('study: ')}; every key of the file is a key of {', '.join(fits)}",
    )
